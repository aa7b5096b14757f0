"""``hinge_coulomb_friction``: dry friction in the hinge, a constant torque against the hinge rate.

.. math:: \\tau = -T_c \\tanh(\\dot\\theta / \\dot\\theta_s)

The tanh regularises the sign function (Coulomb's law) over ``REGULARIZATION_RATE``; below it
the hinge creeps instead of sticking. Stops of the appendage are where the law shows most.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.dynamics import LAW_SIGNATURE, L_TH, X_THD
from riskassess.diagnosis.effects.base import Effect, Parameter, torque_scale
from riskassess.diagnosis.plant import Plant

#: Hinge rate over which the friction torque builds up (rad/s): a hundredth of typical panel
#: rates (0.1-1 rad/s), wide enough for the fit's RK4 step (stiffness T_c / (rate I) stays < 1/step).
REGULARIZATION_RATE = 0.01


@njit(cache=True)
def friction_torque(rate, friction):
    """Hinge friction torque (N m) at ``rate`` (rad/s) for a Coulomb torque ``friction`` (N m)."""
    return -friction * np.tanh(rate / REGULARIZATION_RATE)


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load):
    load[L_TH] += friction_torque(x[X_THD], p[0])


class HingeCoulombFriction(Effect):
    id = "hinge_coulomb_friction"
    title = "Coulomb (dry) friction torque in the hinge"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def parameter_specs(self, case, channels=None):
        scale = torque_scale(Plant.from_case(case))
        return [Parameter("friction_torque", "N m", "Coulomb friction torque magnitude", 0.1 * scale, 0.0, 2.0 * scale)]

    def stiffness_rate(self, plant, specs):
        return specs[0].upper / (REGULARIZATION_RATE * plant.hinge_inertia())

    def add_to_exudyn(self, builder, values, names):
        builder.add_hinge_torque(lambda t, angle, rate: friction_torque(rate, values[0]))


EFFECT = HingeCoulombFriction()
