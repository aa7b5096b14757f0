"""``tether_viscoelasticity``: the main tether relaxes: a standard linear solid instead of a Kelvin-Voigt tether.

The nominal main tether is a tension-only Kelvin-Voigt element (k e + c e', Boonrath, Singh & Botta
2024 eq. 5). A viscoelastic tether (polymer braid) adds a Maxwell branch in parallel, a spring k_m
in series with a dashpot k_m tau_m, whose tension T_m (N) is a state:

.. math::
    T = \\begin{cases} \\max(0,\\ k\\,e + c\\,\\dot e + T_m) & e > 0 \\\\ 0 & e \\le 0 \\end{cases},\\qquad
    \\dot T_m = k_m\\,\\dot e - T_m / \\tau_m

(the standard linear solid, e.g. Lakes, *Viscoelastic Materials*, 2009, Sec. 2.6; e = l - l0 the
elongation (m)). Fast loading (t << tau_m) sees the stiffness k + k_m, slow loading k; at
tau_m -> 0 the branch is a dashpot k_m tau_m. The branch's tension acts along the main tether on
the chaser's attachment point and on the connection point P (inside P's implicit step), so the
debris feels it through the sub-tethers. Parameters: k_m and tau_m. Towing scenario only.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from diagnosis.effects.base import Effect, Parameter
from diagnosis.towing_dynamics import (TOWING_LAW_SIGNATURE, W_TETHER, XE_MAXWELL, last_diagnostics,
                                       main_tether_direction)
from multibody.towing_kernel import C_MT, CHASER, K_MT, MT_ELONGATION, MT_ELONGATION_RATE, W_ATTACH_CHASER


@njit(cache=True)
def branch_tension(elongation, elongation_rate, maxwell_tension, stiffness, damping):
    """Tension (N) the Maxwell branch adds to the tension-only Kelvin-Voigt tether (the difference of
    the two laws above) at elongation (m), its rate (m/s) and the branch's state (N)."""
    if elongation <= 0.0:
        return 0.0
    elastic = stiffness * elongation + damping * elongation_rate
    return max(0.0, elastic + maxwell_tension) - max(0.0, elastic)


@njit(cache=True)
def relaxed(maxwell_tension, elongation_rate, maxwell_stiffness, relaxation_time, h):
    """T_m after ``h`` (s) at a constant elongation rate (m/s): the exact solution of the linear ODE."""
    decay = math.exp(-h / relaxation_time)
    return maxwell_tension * decay + maxwell_stiffness * relaxation_time * (1.0 - decay) * elongation_rate


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    diag = last_diagnostics(work)
    e, e_rate = diag[MT_ELONGATION], diag[MT_ELONGATION_RATE]
    extra = branch_tension(e, e_rate, xe[XE_MAXWELL], work[W_TETHER + K_MT], work[W_TETHER + C_MT])
    if extra != 0.0:
        u, rot_c = main_tether_direction(work, q)       # A -> P, inertial
        force_body = rot_c.T @ (extra * u)
        attach = work[W_ATTACH_CHASER:W_ATTACH_CHASER + 3]
        for i in range(3):
            load[i] -= extra * u[i]                      # on P
            load[CHASER + i] += extra * u[i]             # on the chaser, at A
        load[CHASER + 3] += attach[1] * force_body[2] - attach[2] * force_body[1]
        load[CHASER + 4] += attach[2] * force_body[0] - attach[0] * force_body[2]
        load[CHASER + 5] += attach[0] * force_body[1] - attach[1] * force_body[0]
    if h > 0.0:
        xe[XE_MAXWELL] = relaxed(xe[XE_MAXWELL], e_rate, p[0], p[1], h)


class TetherViscoelasticity(Effect):
    id = "tether_viscoelasticity"
    title = "viscoelastic main tether (standard linear solid: a relaxing Maxwell branch)"
    scenarios = ("towing",)
    channels = ("tether_tension", "rel_x", "rel_y", "rel_z", "omega_x", "omega_y", "omega_z", "q_w")
    towing_law = staticmethod(towing_law)

    def parameter_specs(self, case, channels=None):
        k = case.towing_case.main_tether.stiffness
        return [Parameter("maxwell_stiffness", "N/m", "stiffness of the relaxing branch k_m", 0.3 * k, 0.0, 10.0 * k),
                Parameter("relaxation_time", "s", "relaxation time of the branch tau_m", 5.0, 0.05, 1000.0)]

    def starts(self, specs):
        return [np.array([specs[0].typical / 3.0, 2.0]), np.array([specs[0].typical / 3.0, 30.0])]


EFFECT = TetherViscoelasticity()
