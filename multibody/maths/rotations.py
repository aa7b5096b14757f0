"""Rotations shared by every package: scalar-first unit quaternions, rotation matrices and rotation
vectors (Exudyn's rotation-vector nodes; the log map of a rotation matrix).

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


@njit(cache=True, inline="always")
def quaternion_from_rotation_vector_tuple(rotation_vector):
    """Scalar-first unit quaternion (tuple) of a rotation vector (rad): angle |r| about r / |r|.

    Parameters
    ----------
    rotation_vector : (3,) float
        Axis times angle (rad), of the rotation body->reference (in either frame's components: they
        agree on the axis).

    Returns
    -------
    tuple of 4 float
        (q0, q1, q2, q3), scalar first.
    """
    return quaternion_from_rotation_vector_xyz(rotation_vector[0], rotation_vector[1], rotation_vector[2])


@njit(cache=True, inline="always")
def quaternion_from_rotation_vector_xyz(x, y, z):
    """:func:`quaternion_from_rotation_vector_tuple` of the rotation vector (x, y, z) (rad).

    Parameters
    ----------
    x, y, z : float
        Axis times angle (rad).

    Returns
    -------
    tuple of 4 float
        (q0, q1, q2, q3), scalar first.
    """
    angle = math.sqrt(x * x + y * y + z * z)
    if angle < 1e-8:
        return 1.0 - angle * angle / 8.0, 0.5 * x, 0.5 * y, 0.5 * z
    s = math.sin(0.5 * angle) / angle
    return math.cos(0.5 * angle), s * x, s * y, s * z


@njit(cache=True)
def rotation_matrix_from_rotation_vector(rotation_vector):
    """Rotation matrix (3, 3) of a rotation vector (rad), e.g. body -> LVLH of an Exudyn rotation-vector
    node; Rodrigues' formula :math:`I + \\frac{\\sin\\theta}{\\theta}K + \\frac{1-\\cos\\theta}{\\theta^2}K^2`,
    written out in scalars (numba sends 3x3 products to BLAS, ~1 us a call).

    Parameters
    ----------
    rotation_vector : (3,) float
        Axis times angle (rad) of the rotation body->reference.

    Returns
    -------
    (3, 3) float
        body->reference matrix (columns: body axes in reference components, e.g. LVLH).
    """
    out = np.empty((1, 3, 3))
    rotation_matrix_from_rotation_vector_into(rotation_vector[0], rotation_vector[1], rotation_vector[2], out, 0)
    return out[0]


@njit(cache=True, inline="always")
def rotation_matrix_from_rotation_vector_into(x, y, z, out, k):
    """:func:`rotation_matrix_from_rotation_vector` of the rotation vector (x, y, z) (rad) into ``out[k]`` (no
    allocation, no row view: the compiled kernels call it for every body every step).

    Parameters
    ----------
    x, y, z : float
        Axis times angle (rad) of the rotation body->reference.
    out : (K, 3, 3) float
        Output: ``out[k]`` is set to the body->reference matrix.
    k : int
    """
    angle2 = x * x + y * y + z * z
    if angle2 < 1e-16:
        a, b = 1.0, 0.5
    else:
        angle = math.sqrt(angle2)
        a, b = math.sin(angle) / angle, (1.0 - math.cos(angle)) / angle2
    # K^2 = r r^T - |r|^2 I
    out[k, 0, 0] = 1.0 + b * (x * x - angle2)
    out[k, 1, 1] = 1.0 + b * (y * y - angle2)
    out[k, 2, 2] = 1.0 + b * (z * z - angle2)
    out[k, 0, 1] = -a * z + b * x * y
    out[k, 1, 0] = a * z + b * x * y
    out[k, 0, 2] = a * y + b * x * z
    out[k, 2, 0] = -a * y + b * x * z
    out[k, 1, 2] = -a * x + b * y * z
    out[k, 2, 1] = a * x + b * y * z


@njit(cache=True, inline="always")
def rotation_vector_from_quaternion_into(w, x, y, z, out):
    """Rotation vector (rad, angle at most pi) of the unit quaternion (w, x, y, z) into ``out`` (3,).

    Parameters
    ----------
    w, x, y, z : float
        Unit quaternion, scalar first, of the rotation body->reference.
    out : (3,) float
        Output: axis times angle (rad).
    """
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    sine = math.sqrt(x * x + y * y + z * z)
    if sine < 1e-12:  # angle below 2e-12 rad: 2 atan2(s, w) / s = 2 to round-off
        out[0], out[1], out[2] = 2.0 * x, 2.0 * y, 2.0 * z
        return
    angle = 2.0 * math.atan2(sine, w)
    out[0], out[1], out[2] = angle * x / sine, angle * y / sine, angle * z / sine


@njit(cache=True)
def rotation_vector_from_matrix_into(rotation, out):
    """Rotation vector (rad) of a rotation matrix (the log map) into ``out`` (3,), through Shepperd's
    quaternion (:func:`quaternion_from_matrix_tuple`): accurate at every angle up to pi.

    Parameters
    ----------
    rotation : (3, 3) float
        Rotation matrix body->reference (columns: body axes in reference components).
    out : (3,) float
        Output: axis times angle (rad).
    """
    w, x, y, z = quaternion_from_matrix_tuple(rotation)
    rotation_vector_from_quaternion_into(w, x, y, z, out)


@njit(cache=True)
def half_rotation_matrix_into(rotation, out, k):
    """The rotation halfway to ``rotation``, :math:`\\exp(\\log(R) / 2)` (the same axis, half the angle, angle at
    most pi), into ``out[k]``: through the half-angle quaternion :math:`(1 + w, x, y, z) / |\\cdot|` of Shepperd's
    quaternion (:func:`quaternion_from_matrix_tuple`, w >= 0), so with no trigonometric call (the log map and the
    exponential, :func:`rotation_vector_from_matrix_into` then :func:`rotation_matrix_from_rotation_vector_into`,
    cost three and most of a joint's damper power, which the recorder books every step).

    Parameters
    ----------
    rotation : (3, 3) float
        Rotation matrix body->reference.
    out : (K, 3, 3) float
        Output: ``out[k]`` is set to the half rotation, body->reference.
    k : int
    """
    w, x, y, z = quaternion_from_matrix_tuple(rotation)
    w = 1.0 + w   # >= 1: the half angle's quaternion, not yet normalized
    scale = 1.0 / (w * w + x * x + y * y + z * z)
    # the unit quaternion's matrix, written with the squared norm so that no square root is needed
    out[k, 0, 0] = 1.0 - 2.0 * scale * (y * y + z * z)
    out[k, 1, 1] = 1.0 - 2.0 * scale * (x * x + z * z)
    out[k, 2, 2] = 1.0 - 2.0 * scale * (x * x + y * y)
    out[k, 0, 1] = 2.0 * scale * (x * y - w * z)
    out[k, 1, 0] = 2.0 * scale * (x * y + w * z)
    out[k, 0, 2] = 2.0 * scale * (x * z + w * y)
    out[k, 2, 0] = 2.0 * scale * (x * z - w * y)
    out[k, 1, 2] = 2.0 * scale * (y * z - w * x)
    out[k, 2, 1] = 2.0 * scale * (y * z + w * x)


@njit(cache=True)
def rotation_vector_from_matrix(rotation):
    """Rotation vector (3,) (rad) of a rotation matrix: :func:`rotation_vector_from_matrix_into`.

    Parameters
    ----------
    rotation : (3, 3) float
        Rotation matrix body->reference (columns: body axes in reference components).

    Returns
    -------
    (3,) float
        Axis times angle (rad), angle at most pi.
    """
    out = np.empty(3)
    rotation_vector_from_matrix_into(rotation, out)
    return out


@njit(cache=True)
def compose_rotation_vectors(rotation_vector, increment_body):
    """Rotation vector (3,) of R(rotation_vector) R(increment_body): a rotation by ``increment_body``
    (rad, body frame) after ``rotation_vector``; the Lie-group update Exudyn applies to rotation-vector
    nodes. The result's angle is at most pi.

    Parameters
    ----------
    rotation_vector : (3,) float
        Current rotation body->reference (rad).
    increment_body : (3,) float
        Rotation increment (rad), body frame.

    Returns
    -------
    (3,) float
        The composed rotation body->reference (rad).
    """
    out = np.empty(3)
    compose_rotation_vectors_into(rotation_vector[0], rotation_vector[1], rotation_vector[2], increment_body[0],
                                  increment_body[1], increment_body[2], out, 0)
    return out


@njit(cache=True, inline="always")
def compose_rotation_vectors_into(rx, ry, rz, ix, iy, iz, out, k):
    """:func:`compose_rotation_vectors` of the rotation vector (rx, ry, rz) and the body-frame increment
    (ix, iy, iz) (rad) into ``out[k:k + 3]`` (no allocation: the net step composes every body's every step).

    Parameters
    ----------
    rx, ry, rz : float
        Current rotation body->reference (rad).
    ix, iy, iz : float
        Rotation increment (rad), body frame.
    out : (N,) float
        Output: ``out[k:k + 3]`` is set to the composed rotation body->reference (rad).
    k : int
    """
    w0, x0, y0, z0 = quaternion_from_rotation_vector_xyz(rx, ry, rz)
    w1, x1, y1, z1 = quaternion_from_rotation_vector_xyz(ix, iy, iz)
    rotation_vector_from_quaternion_into(w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
                                         w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
                                         w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
                                         w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1, out[k:k + 3])
