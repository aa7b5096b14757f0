"""Sliding-mode attitude control of the towing chaser (Boonrath, Singh & Botta 2024, eqs. 7-10,
after Crassidis, Vadali & Markley 2000).

Quaternions are scalar-first, :math:`q = [q_1, q_2, q_3, q_4]`, and describe the body->inertial
rotation (paper eq. 6: :math:`{}^{\\mathcal O}A^C`); angular velocities are in the body frame.
Every function is compiled (numba) and pure: arrays in, arrays out.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from multibody.maths.linalg3 import cross3, dot3, matvec3
from multibody.maths.rotations import quaternion_from_matrix_tuple


@njit(cache=True)
def kinematics_matrix(q):
    """Quaternion kinematics matrix :math:`Q(q)` (4, 3), paper eq. (8) (Schaub & Junkins' B):
    :math:`\\dot q = \\tfrac12 Q(q)\\,\\omega_{body}`.

    Parameters
    ----------
    q : (4,) float
        Scalar-first unit quaternion of the body->inertial rotation.

    Returns
    -------
    (4, 3) float
        Q(q); half of it times the body-frame angular velocity (rad/s) is the quaternion rate (1/s).
    """
    return np.array([[-q[1], -q[2], -q[3]],
                     [q[0], -q[3], q[2]],
                     [q[3], q[0], -q[1]],
                     [-q[2], q[1], q[0]]])


@njit(cache=True, inline="always")
def _kinematics_times(q, w):
    """:math:`Q(q)\\,w` (4-tuple) without forming Q."""
    return (-q[1] * w[0] - q[2] * w[1] - q[3] * w[2], q[0] * w[0] - q[3] * w[1] + q[2] * w[2],
            q[3] * w[0] + q[0] * w[1] - q[1] * w[2], -q[2] * w[0] + q[1] * w[1] + q[0] * w[2])


@njit(cache=True, inline="always")
def _kinematics_transpose_times(q, x):
    """:math:`Q(q)^T x` (3-tuple) for a 4-vector x without forming Q."""
    return (-q[1] * x[0] + q[0] * x[1] + q[3] * x[2] - q[2] * x[3],
            -q[2] * x[0] - q[3] * x[1] + q[0] * x[2] + q[1] * x[3],
            -q[3] * x[0] + q[2] * x[1] - q[1] * x[2] + q[0] * x[3])


@njit(cache=True)
def desired_attitude(u_main_tether_inertial, r_chaser_inertial):
    """Desired chaser attitude (body->inertial matrix): body z along :math:`-\\hat u_{MT}`,
    body x along :math:`-\\hat u_{MT}\\times\\hat r_{C/O}`, body y completing the triad
    (paper, text after eq. 8).

    Parameters
    ----------
    u_main_tether_inertial : (3,) float
        Unit vector from the main-tether attachment point on the chaser to the connection point, inertial.
    r_chaser_inertial : (3,) float
        Chaser CoM from the Earth's centre (m), inertial.
    """
    u_inertial, r_inertial = u_main_tether_inertial, r_chaser_inertial
    u_norm, r_norm = math.sqrt(dot3(u_inertial, u_inertial)), math.sqrt(dot3(r_inertial, r_inertial))
    # tuples: this runs every step of a tow
    ez_inertial = -u_inertial[0] / u_norm, -u_inertial[1] / u_norm, -u_inertial[2] / u_norm
    radial_inertial = r_inertial[0] / r_norm, r_inertial[1] / r_norm, r_inertial[2] / r_norm
    ex_inertial = _cross(ez_inertial, radial_inertial)
    ex_norm = math.sqrt(dot3(ex_inertial, ex_inertial))
    ex_inertial = ex_inertial[0] / ex_norm, ex_inertial[1] / ex_norm, ex_inertial[2] / ex_norm
    ey_inertial = _cross(ez_inertial, ex_inertial)
    out = np.empty((3, 3))
    for i in range(3):
        out[i, 0], out[i, 1], out[i, 2] = ex_inertial[i], ey_inertial[i], ez_inertial[i]
    return out


@njit(cache=True, inline="always")
def _cross(a, b):
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def sampled_boundary_layer(width, gain, step):
    """Boundary-layer width (3,) that keeps a controller sampled every ``step`` (s) stable.

    Inside the boundary layer the closed loop of eq. (10) is :math:`\\dot S = -(G/\\epsilon) S`;
    with the paper's :math:`\\epsilon = 10^{-3}`, :math:`G = 1` that is a 1 ms time constant. Held
    over a step :math:`h`, the loop gain :math:`G/\\epsilon` is replaced by its exact discrete
    equivalent :math:`(1 - e^{-hG/\\epsilon})/h`, i.e. the width by
    :math:`\\epsilon_h = G h / (1 - e^{-hG/\\epsilon})`, so that :math:`S` decays by
    :math:`e^{-hG/\\epsilon}` per step for any step. :math:`\\epsilon_h \\to \\epsilon` as
    :math:`h \\to 0` (e.g. +0.05 % at h = 1 us, +16 % at h = 0.3 ms).

    Parameters
    ----------
    width : float      :math:`\\epsilon` (rad/s).
    gain : (3,) float  Diagonal of :math:`G` (rad/s^2).
    step : float       Sampling step (s); 0 gives back ``width``.
    """
    out = np.empty(3)
    for i in range(3):
        x = step * gain[i] / width
        out[i] = width if x < 1e-9 else gain[i] * step / (1.0 - math.exp(-x))
    return out


@njit(cache=True)
def sliding_mode_torque(body_to_inertial, omega_body, desired_to_inertial, inertia_body, k_gain, gain, width):
    """Control torque (N m, body frame) of the sliding-mode attitude controller, eqs. (7)-(10),
    with :math:`\\omega_d = 0`; also returns the sliding variable S (3,) (rad/s).

    .. math::
        q_e = [q_d^T q,\\; Q(q_d)^T q],\\qquad
        S = \\omega + K\\,\\mathrm{sgn}(q_{e,1})\\,Q(q_d)^T q

        \\tau_S = \\omega\\times J\\omega + J\\big(-\\tfrac12 K\\,\\mathrm{sgn}(q_{e,1})\\,
        Q(q_d)^T Q(q)\\,\\omega - G\\,\\mathrm{sat}(S, \\epsilon)\\big)

    so that, with the Euler equation (3), :math:`\\dot S = J^{-1}\\tau_{ext} - G\\,\\mathrm{sat}(S,\\epsilon)`
    (the desired attitude is treated as constant, as in the paper).

    Parameters
    ----------
    body_to_inertial, desired_to_inertial : (3, 3) float
        Actual and desired chaser attitude.
    omega_body : (3,) float
        Chaser angular velocity (rad/s), body frame.
    inertia_body : (3, 3) float
        :math:`J_C` (kg m^2), body frame.
    k_gain : float
        :math:`K` (1/s).
    gain : (3,) float
        Diagonal of :math:`G` (rad/s^2).
    width : (3,) float
        Boundary-layer width per axis (rad/s), see :func:`sampled_boundary_layer`.
    """
    q = quaternion_from_matrix_tuple(body_to_inertial)
    qd = quaternion_from_matrix_tuple(desired_to_inertial)
    sign = 1.0 if qd[0] * q[0] + qd[1] * q[1] + qd[2] * q[2] + qd[3] * q[3] >= 0.0 else -1.0
    error = _kinematics_transpose_times(qd, q)
    feedforward = _kinematics_transpose_times(qd, _kinematics_times(q, omega_body))
    j_omega_body = matvec3(inertia_body, omega_body)
    s, demand = np.empty(3), np.empty(3)
    for i in range(3):
        s[i] = omega_body[i] + k_gain * sign * error[i]
        demand[i] = -0.5 * k_gain * sign * feedforward[i] - gain[i] * min(1.0, max(-1.0, s[i] / width[i]))
    torque_body = cross3(omega_body, j_omega_body) + matvec3(inertia_body, demand)
    return torque_body, s
