"""``hinge_coulomb_friction``: dry friction in the hinge that slides AND sticks (issue 24 item 4).

Coulomb's law with stiction: while the hinge slides the friction torque is :math:`-T_c\\,
\\mathrm{sign}(\\dot\\theta)`; once the hinge stops it stays stuck as long as the torque that
holds it there is within the break-away limit :math:`T_c` (static = kinetic limit here), and
breaks away when that torque exceeds it. The switch is written as one continuous law, a
saturated "stick" controller:

.. math:: \\tau_f = \\mathrm{clip}\\big(k\\,\\theta - c_s\\,\\dot\\theta,\\; -T_c,\\; T_c\\big)

* sliding (:math:`|k\\theta - c_s\\dot\\theta| > T_c`): :math:`\\tau_f = \\mp T_c`, Coulomb's law;
* sticking: :math:`\\tau_f` cancels the hinge spring :math:`-k\\theta` exactly (the torque that
  holds the panel, within the limit) and adds a stiff damping :math:`-c_s\\dot\\theta` that
  brings the rate to zero in :math:`1/\\lambda_s` and keeps it there. The stuck hinge does not
  creep under its spring, unlike a tanh regularisation (the former law, tanh(rate / 0.01 rad/s),
  crept at rates comparable to a slowly moving panel's and could not stick).

The stick rate :math:`\\lambda_s = c_s / J_{eff}` is ``STICK_RATE_PER_MOTION_RATE`` times the
plant's fastest motion rate, so the transition from sliding to sticking lasts a few hundredths
of a period; the fit's RK4 step is shortened by :meth:`stiffness_rate` so that the stiff term is
integrated stably (the Exudyn reference's explicit RK4 step, 4 ms, is far below it).
Torques on the hinge other than the spring (coupling to the main body's rotation) are held by
the stiff damping up to the break-away limit. Checked against the analytic stick-slip
ring-down in tests/riskassess/diagnosis/test_stiction.py.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.dynamics import LAW_SIGNATURE, E_K, L_TH, X_TH, X_THD
from riskassess.diagnosis.effects.base import Effect, Parameter, torque_scale
from riskassess.diagnosis.plant import Plant

#: Stick rate lambda_s (1/s) per fastest motion rate (rad/s) of the plant: 10 makes the stick
#: transient 1/(10 omega), a 60th of a period, and keeps the fit's RK4 step (1.5 / lambda_s =
#: 0.15 / omega) above its accuracy step (0.1 / omega, riskassess.diagnosis.model), so sticking
#: costs no extra steps.
STICK_RATE_PER_MOTION_RATE = 30.0


@njit(cache=True)
def friction_torque(angle, rate, friction, stiffness, stick_damping):
    """Hinge friction torque (N m) at hinge ``angle`` (rad) and ``rate`` (rad/s) for a Coulomb
    (break-away) torque ``friction`` (N m), the hinge spring ``stiffness`` (N m/rad) it holds
    while stuck and the ``stick_damping`` (N m s/rad) that stops the hinge."""
    hold = stiffness * angle - stick_damping * rate
    return min(max(hold, -friction), friction)


def stick_damping(plant: Plant) -> float:
    """c_s (N m s/rad): the stick rate times the hinge mode's inertia with the main body free."""
    return STICK_RATE_PER_MOTION_RATE * plant.rate_scale() * plant.effective_hinge_inertia()


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load):
    load[L_TH] += friction_torque(x[X_TH], x[X_THD], p[0], env[E_K], p[1])


class HingeCoulombFriction(Effect):
    id = "hinge_coulomb_friction"
    title = "Coulomb (dry) friction in the hinge, sliding and sticking"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def parameter_specs(self, case, channels=None):
        scale = torque_scale(Plant.from_case(case))
        return [Parameter("friction_torque", "N m", "Coulomb friction torque magnitude (sliding and break-away)",
                          0.1 * scale, 0.0, 2.0 * scale)]

    def law_parameters(self, plant, values):
        return np.array([float(values[0]), stick_damping(plant)])

    def stiffness_rate(self, plant, specs):
        return (stick_damping(plant) + plant.damping) / plant.effective_hinge_inertia()

    def add_to_exudyn(self, builder, values, names):
        k, c_s = builder.plant.stiffness, stick_damping(builder.plant)
        builder.add_hinge_torque(lambda t, angle, rate: friction_torque(angle, rate, values[0], k, c_s))


EFFECT = HingeCoulombFriction()
