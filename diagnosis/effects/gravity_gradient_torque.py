"""``gravity_gradient_torque``: the tidal torque of Earth's gravity on each extended body.

.. math:: \\boldsymbol\\tau = 3 n^2\\, \\hat r \\times (\\mathbf J \\hat r)

(Hughes, *Spacecraft Attitude Dynamics*, eq. 8.1.13) with r the radial direction (LVLH x) in
the body's frame and J its inertia about its CoM; applied to the main body and the appendage.
The nominal model already moves every body's CoM in the orbit's tidal field (Clohessy-Wiltshire);
this adds the bodies' own inertia. Parameter: the mean motion n, expected at the case orbit's.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from diagnosis.dynamics import LAW_SIGNATURE, E_HINGED, E_JM, E_N, L_TA, L_TM, X_Q, X_TH, appendage_state, cross, quaternion_matrix, \
    radial_inertial
from diagnosis.effects.base import Effect, Parameter
from diagnosis.plant import Plant


@njit(cache=True)
def gravity_gradient(radial_body, inertia, mean_motion):
    """Gravity-gradient torque (N m) in the frame of ``radial_body`` (unit, -) and ``inertia`` (kg m^2)."""
    return 3.0 * mean_motion ** 2 * cross(radial_body, inertia @ radial_body)


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load):
    rot = quaternion_matrix(x[X_Q:X_Q + 4])
    r_b = rot.T @ radial_inertial(env[E_N], t)
    load[L_TM:L_TM + 3] += gravity_gradient(r_b, env[E_JM:E_JM + 9].reshape(3, 3), p[0])
    if env[E_HINGED] != 0.0:
        _, _, ja = appendage_state(env, x[X_TH])
        load[L_TA:L_TA + 3] += gravity_gradient(r_b, ja, p[0])


class GravityGradientTorque(Effect):
    id = "gravity_gradient_torque"
    title = "gravity-gradient torque on the bodies' inertia"
    channels = ("omega_x", "omega_y", "omega_z", "q_w", "hinge_angle", "hinge_rate")
    law = staticmethod(law)

    def not_applicable(self, case, channels):
        if case.orbit.kind != "circular":
            return "the case has no orbit ([orbit] kind = 'circular' with its altitude)"
        return super().not_applicable(case, channels)

    def parameter_specs(self, case, channels=None):
        n = Plant.from_case(case).mean_motion
        return [Parameter("mean_motion", "rad/s", "orbit mean motion seen by the torque (the case orbit's: "
                          f"{n:.4g})", n, 0.0, 10.0 * n)]

    def starts(self, specs):
        return [np.array([specs[0].typical])]

    def add_to_exudyn(self, builder, values, names):
        n_orbit = builder.plant.mean_motion
        builder.add_body_torque(lambda t, body, rot, omega: gravity_gradient(
            rot.T @ radial_inertial(n_orbit, t), builder.inertia_body(body), values[0]))


EFFECT = GravityGradientTorque()
