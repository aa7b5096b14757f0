"""Rotations shared by every package: scalar-first unit quaternions and rotation matrices.

One implementation each, compiled (numba) so kernels and Python code call the same function.
Convention: ``q = [q0, q1, q2, q3]`` with the scalar first and ``q0 >= 0``; the matrix of ``q``
maps body components to the reference frame's (body -> inertial, body -> LVLH, ...), as in
Boonrath, Singh & Botta 2024, eq. (6). Imports nothing of the project.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def quaternion_from_matrix(body_to_inertial):
    """Scalar-first unit quaternion of a body->inertial rotation matrix (Shepperd's method).

    Inverse of paper eq. (6); the sign is chosen with a non-negative scalar part.

    Parameters
    ----------
    body_to_inertial : (3, 3) float array
        Rotation matrix whose columns are the body axes in inertial (or LVLH) components.

    Returns
    -------
    (4,) float array
        Unit quaternion [q0, q1, q2, q3], scalar first, q0 >= 0.
    """
    out = np.empty(4)
    out[0], out[1], out[2], out[3] = quaternion_from_matrix_tuple(body_to_inertial)
    return out


@njit(cache=True, inline="always")
def quaternion_from_matrix_tuple(a):
    """:func:`quaternion_from_matrix` as a tuple (no allocation: the attitude controller runs every step).

    Parameters
    ----------
    a : (3, 3) float array
        Rotation matrix body->inertial (or body->LVLH): columns are the body axes.

    Returns
    -------
    tuple of 4 float
        Unit quaternion (q0, q1, q2, q3), scalar first, q0 >= 0.
    """
    trace = a[0, 0] + a[1, 1] + a[2, 2]
    if trace > max(a[0, 0], a[1, 1], a[2, 2]):
        s = 2.0 * math.sqrt(1.0 + trace)
        q = 0.25 * s, (a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s
    elif a[0, 0] >= a[1, 1] and a[0, 0] >= a[2, 2]:
        s = 2.0 * math.sqrt(1.0 + a[0, 0] - a[1, 1] - a[2, 2])
        q = (a[2, 1] - a[1, 2]) / s, 0.25 * s, (a[0, 1] + a[1, 0]) / s, (a[0, 2] + a[2, 0]) / s
    elif a[1, 1] >= a[2, 2]:
        s = 2.0 * math.sqrt(1.0 + a[1, 1] - a[0, 0] - a[2, 2])
        q = (a[0, 2] - a[2, 0]) / s, (a[0, 1] + a[1, 0]) / s, 0.25 * s, (a[1, 2] + a[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 + a[2, 2] - a[0, 0] - a[1, 1])
        q = (a[1, 0] - a[0, 1]) / s, (a[0, 2] + a[2, 0]) / s, (a[1, 2] + a[2, 1]) / s, 0.25 * s
    if q[0] < 0.0:
        q = -q[0], -q[1], -q[2], -q[3]
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm


@njit(cache=True)
def quaternion_to_matrix(q):
    """Body->inertial rotation matrix of a scalar-first quaternion, paper eq. (6).

    Parameters
    ----------
    q : (4,) float array
        Quaternion [q0, q1, q2, q3], scalar first; normalised here (an integrator's drift off the
        unit sphere does not skew the matrix).

    Returns
    -------
    (3, 3) float array
        Orthonormal matrix mapping body components to inertial (or LVLH) components.
    """
    q = q / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    q1, q2, q3, q4 = q[0], q[1], q[2], q[3]
    return np.array([
        [q1 * q1 + q2 * q2 - q3 * q3 - q4 * q4, 2.0 * (q2 * q3 - q1 * q4), 2.0 * (q2 * q4 + q1 * q3)],
        [2.0 * (q2 * q3 + q1 * q4), q1 * q1 - q2 * q2 + q3 * q3 - q4 * q4, 2.0 * (q4 * q3 - q1 * q2)],
        [2.0 * (q2 * q4 - q3 * q1), 2.0 * (q3 * q4 + q1 * q2), q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4]])
