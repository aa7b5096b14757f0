"""``hinge_stiffness_hardening``: a hinge spring that stiffens with the angle (cubic term).

.. math:: \\tau = -k\\,\\theta - k_3\\,\\theta^3

(the linear part is the case's spring); the oscillation frequency rises with the amplitude.
"""
from __future__ import annotations

from numba import njit

from riskassess.diagnosis.dynamics import LAW_SIGNATURE, L_TH, X_TH
from riskassess.diagnosis.effects.base import Effect, Parameter, reference_angle, torque_scale
from riskassess.diagnosis.plant import Plant


@njit(cache=True)
def hardening_torque(angle, cubic_stiffness):
    """Cubic spring torque (N m) at hinge ``angle`` (rad), ``cubic_stiffness`` (N m/rad^3)."""
    return -cubic_stiffness * angle ** 3


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load):
    load[L_TH] += hardening_torque(x[X_TH], p[0])


class HingeStiffnessHardening(Effect):
    id = "hinge_stiffness_hardening"
    title = "hinge spring stiffening with the angle (cubic term)"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def parameter_specs(self, case, channels=None):
        plant = Plant.from_case(case)
        typical = torque_scale(plant) / reference_angle(plant) ** 3
        return [Parameter("cubic_stiffness", "N m/rad^3", "cubic hardening coefficient k3", typical, 0.0,
                          50.0 * typical)]

    def add_to_exudyn(self, builder, values, names):
        builder.add_hinge_torque(lambda t, angle, rate: hardening_torque(angle, values[0]))


EFFECT = HingeStiffnessHardening()
