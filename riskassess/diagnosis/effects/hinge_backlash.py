"""``hinge_backlash``: free play in the hinge; the torsional spring acts only outside a gap.

.. math:: \\tau_{spring} = -k\\,(\\theta - \\mathrm{clip}(\\theta, -b, b))

i.e. the effect adds :math:`k\\,\\mathrm{clip}(\\theta, -b, b)` to the nominal :math:`-k\\theta`.
Inside the gap (half width b) the appendage swings freely; the period grows as the amplitude
decays towards b.
"""
from __future__ import annotations

from numba import njit

from riskassess.diagnosis.dynamics import LAW_SIGNATURE, E_K, L_TH, X_TH
from riskassess.diagnosis.effects.base import Effect, Parameter, reference_angle
from riskassess.diagnosis.plant import Plant


@njit(cache=True)
def backlash_torque(angle, stiffness, half_gap):
    """Torque (N m) that cancels the spring ``stiffness`` (N m/rad) inside the gap +-``half_gap`` (rad)."""
    return stiffness * min(max(angle, -half_gap), half_gap)


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load):
    load[L_TH] += backlash_torque(x[X_TH], env[E_K], p[0])


class HingeBacklash(Effect):
    id = "hinge_backlash"
    title = "free play (dead band) of the hinge spring"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def not_applicable(self, case, channels):
        if case.kind == "hinged_appendage" and case.hinge.torsional_stiffness == 0:
            return "the hinge has no torsional spring: free play changes nothing"
        return super().not_applicable(case, channels)

    def parameter_specs(self, case, channels=None):
        angle = reference_angle(Plant.from_case(case))
        return [Parameter("half_gap", "rad", "half width of the free-play band", 0.2 * angle, 0.0, 1.5 * angle)]

    def add_to_exudyn(self, builder, values, names):
        k = builder.plant.stiffness
        builder.add_hinge_torque(lambda t, angle, rate: backlash_torque(angle, k, values[0]))


EFFECT = HingeBacklash()
