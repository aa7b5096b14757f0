"""``tether_viscoelasticity``: the towing tether's tension relaxes and damps (standard linear solid).

.. math::
    T = \\max\\big(0,\\ k\\,e + c\\,\\dot e + T_m\\big),\\qquad
    \\dot T_m = k_m\\,\\dot e - T_m / \\tau_m

with e = L - L0 the elongation (m): the nominal elastic tether k e plus a Kelvin-Voigt damper c
and a Maxwell branch (stiffness k_m, relaxation time tau_m) whose state T_m (N) is carried by
the towing model; a slack tether carries nothing. Applies to the towing scenario (the lower-order
tethered model, ``multibody/towing.py``), which this stage cannot simulate yet: the effect is
registered and reported "not applicable" until then.
"""
from __future__ import annotations

from numba import njit

from diagnosis.effects.base import Effect, Parameter


@njit(cache=True)
def tension(elongation, elongation_rate, maxwell_tension, stiffness, damping):
    """Tether tension (N) from elongation (m), its rate (m/s) and the Maxwell branch's tension (N)."""
    return max(0.0, stiffness * elongation + damping * elongation_rate + maxwell_tension)


@njit(cache=True)
def maxwell_rate(elongation_rate, maxwell_tension, maxwell_stiffness, relaxation_time):
    """d T_m / dt (N/s) of the Maxwell branch."""
    return maxwell_stiffness * elongation_rate - maxwell_tension / relaxation_time


class TetherViscoelasticity(Effect):
    id = "tether_viscoelasticity"
    title = "viscoelastic tether (Kelvin-Voigt damping + Maxwell relaxation)"
    scenarios = ("towing",)
    channels = ("tether_tension", "rel_x", "rel_y", "rel_z")

    def parameter_specs(self, case, channels=None):
        return [Parameter("damping", "N s/m", "Kelvin-Voigt damping of the tether", 10.0, 0.0, 1e5),
                Parameter("maxwell_stiffness", "N/m", "stiffness of the relaxing branch", 100.0, 0.0, 1e7),
                Parameter("relaxation_time", "s", "relaxation time of the Maxwell branch", 5.0, 0.01, 1e4)]


EFFECT = TetherViscoelasticity()
