"""``thrust_misalignment``: the tug's engine is mounted tilted, so its thrust pushes sideways.

The nominal thrust acts along the law's direction e (against the chaser's velocity for the ramp,
along its body z for the MRAC laws; ``multibody.towing_kernel.towing_forces``). A misaligned engine
turns that direction by a fixed rotation in the chaser's body frame C:

.. math::
    \\mathbf F = F\\,\\mathbf R_C\\,\\mathbf R_y(\\beta)\\mathbf R_x(\\alpha)\\,\\mathbf R_C^T\\,\\hat{\\mathbf e},\\qquad
    \\boldsymbol\\tau_C = \\mathbf r_n \\times \\mathbf R_C^T\\mathbf F

with the tilts alpha (about the chaser's x axis) and beta (about y) and the thrust magnitude F of
the law (N). The thrust line is taken through the chaser's CoM (r_n = 0): the towing case gives no
nozzle position, and the chaser's attitude controller takes out such a torque. The side force
swings the tethered pair, so the debris' position relative to the chaser, the tether direction and
tension and, through the sub-tethers, the debris' rotation change. Towing scenario only.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from multibody.maths.linalg3 import cross3
from riskassess.diagnosis.plants.dynamics import axis_rotation
from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE, last_diagnostics
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.towing_kernel import CHASER, THRUST, W_ALONG_Z


@njit(cache=True)
def misaligned_thrust(thrust, direction_body, nozzle_body, tilt_x, tilt_y):
    """Thrust force (N) and torque about the CoM (N m), tug body frame, for tilts (rad) about x and y.

    Parameters
    ----------
    thrust : float
        Thrust magnitude F (N).
    direction_body : (3,) float
        Nominal unit thrust direction, chaser body frame C (-).
    nozzle_body : (3,) float
        Thrust line's point r_n relative to the chaser CoM, C (m).
    tilt_x, tilt_y : float
        Tilts alpha about C x and beta about C y (rad).

    Returns
    -------
    force_body : (3,) float
        F R_y(beta) R_x(alpha) e, C (N).
    torque_body : (3,) float
        r_n x force, C (N m).
    """
    tilt = axis_rotation(np.array([0.0, 1.0, 0.0]), tilt_y) @ axis_rotation(np.array([1.0, 0.0, 0.0]), tilt_x)
    force = thrust * (tilt @ direction_body)
    return force, cross3(nozzle_body, force)


@njit(cache=True)
def thrust_direction_eci(q, v, work):
    """Unit direction (ECI) of the thrust law's force (multibody.towing_kernel.towing_forces): the
    chaser's body z for the MRAC laws, against its velocity for the ramp.

    Parameters
    ----------
    q, v : (15,) float
        State, kernel layout (:mod:`multibody.towing_kernel`).
    work : (w,) float
        Packed towing model (its thrust-law flag ``W_ALONG_Z``).

    Returns
    -------
    direction_eci : (3,) float
        Unit vector, ECI (-).
    """
    if work[W_ALONG_Z] > 0.0:
        return rotation_matrix_from_rotation_vector(q[CHASER + 3:CHASER + 6])[:, 2].copy()
    speed = math.sqrt(v[CHASER] ** 2 + v[CHASER + 1] ** 2 + v[CHASER + 2] ** 2)
    return -v[CHASER:CHASER + 3] / speed


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """The misaligned thrust's change of force and its torque on the chaser.

    Parameters
    ----------
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        Evaluation state, kernel layout (:mod:`multibody.towing_kernel`): P, chaser and debris
        displacements from their reference positions (m, ECI; P's are stale, see
        :func:`~riskassess.diagnosis.plants.towing_dynamics.point_position`) and rotation vectors body -> ECI
        (rad); velocities (m/s, ECI) and angular velocities (rad/s, body frames).
    p : (2,) float
        [tilt_x, tilt_y] (rad), about the chaser's body x and y.
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (0,) float
        The law's own states: none (the effect declares no ``towing_extra_states``).
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: the force change on the chaser (N, ECI)
        and the torque (N m, chaser body frame; 0 with the thrust line through the CoM).
    """
    thrust = last_diagnostics(work)[THRUST]
    if thrust == 0.0:
        return
    rot_c = rotation_matrix_from_rotation_vector(q[CHASER + 3:CHASER + 6])
    direction = thrust_direction_eci(q, v, work)
    force_body, torque_body = misaligned_thrust(thrust, rot_c.T @ direction, np.zeros(3), p[0], p[1])
    change = rot_c @ force_body - thrust * direction
    for i in range(3):
        load[CHASER + i] += change[i]
        load[CHASER + 3 + i] += torque_body[i]


class ThrustMisalignment(Effect):
    id = "thrust_misalignment"
    title = "tilted tug thrust (side force)"
    scenarios = ("towing",)
    channels = ("tether_tension", "rel_x", "rel_y", "rel_z", "omega_x", "omega_y", "omega_z", "q_w")
    towing_law = staticmethod(towing_law)

    def parameter_specs(self, case, channels=None):
        """The tilts about the tug's body x and y (rad), within +-0.3 rad.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; not read.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        return [Parameter("tilt_x", "rad", "thrust tilt about the tug's body x axis", 0.02, -0.3, 0.3),
                Parameter("tilt_y", "rad", "thrust tilt about the tug's body y axis", 0.02, -0.3, 0.3)]

    def starts(self, specs):
        """A 3 x 3 grid of tilts (0, +-2 x typical): a towing candidate's fit starts from the best of them
        on the training span (one run each, riskassess.diagnosis.fit); from zero tilt alone the fit stopped at
        chi^2 1.8e6 for a record whose truth has 2.3e4 (0.013 / -0.032 rad; docs/diagnosis.md).

        Parameters
        ----------
        specs : list of Parameter
            [tilt_x, tilt_y].

        Returns
        -------
        starts : list of (m,) float
            Nine [tilt_x, tilt_y] (rad).
        """
        return [np.array([a * specs[0].typical, b * specs[1].typical]) for a in (-2.0, 0.0, 2.0)
                for b in (-2.0, 0.0, 2.0)]


EFFECT = ThrustMisalignment()
