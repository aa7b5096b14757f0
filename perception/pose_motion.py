"""Constant-rate motion of a registered pose: the next frame's prediction and the propagation across frames a
track missed, from two frames or fitted to several.

Poses are ``world_to_body`` homogeneous transforms (4, 4) (m) of the debris' model frame B, as
:class:`perception.registration.DebrisTracker` registers them.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def predict_pose(previous, before) -> np.ndarray:
    """world_to_body at the next frame from the last two, at constant rotation and translation
    rates (equal frame spacing): T_next = (T_prev T_before^-1) T_prev.

    Parameters
    ----------
    previous : (4, 4) float
        world_to_body at the last frame (homogeneous transform, m).
    before : (4, 4) float
        world_to_body at the frame before it.

    Returns
    -------
    (4, 4) float
        Predicted world_to_body at the next frame.
    """
    return previous @ np.linalg.inv(before) @ previous


def propagate_pose(previous, before, steps) -> np.ndarray:
    """world_to_body ``steps`` frame spacings (any real number) after ``previous``, at the constant
    rates of the two frames: the attitude turned on at the constant rotation rate, the frame B's
    origin moved on at its constant velocity (for steps = 1 the rotation of :func:`predict_pose`).

    .. math:: R(t) = \\exp(n \\log(R_1 R_0^T)) R_1, \\quad p(t) = p_1 + n (p_1 - p_0)

    with R the body -> world rotation, p the origin of B in the world frame and n = ``steps``. Exact for a
    turn at a constant rate about a fixed axis through B's origin moving at a constant velocity (a
    torque-free tumble about a principal axis, B's origin at the CoM); with B's origin off the CoM the
    place is off by the turned offset (the re-acquisition's search places the body itself; only the
    attitude is used to choose).

    Parameters
    ----------
    previous, before : (4, 4) float
        world_to_body at the last good frame and at the good frame before it (m).
    steps : float
        Time from ``previous`` over the time between the two (-).

    Returns
    -------
    (4, 4) float
        Propagated world_to_body (m).
    """
    body_to_world_1, body_to_world_0 = np.linalg.inv(previous), np.linalg.inv(before)
    turn = Rotation.from_matrix(body_to_world_1[:3, :3] @ body_to_world_0[:3, :3].T).as_rotvec()
    propagated = np.eye(4)
    propagated[:3, :3] = Rotation.from_rotvec(steps * turn).as_matrix() @ body_to_world_1[:3, :3]
    propagated[:3, 3] = body_to_world_1[:3, 3] + steps * (body_to_world_1[:3, 3] - body_to_world_0[:3, 3])
    return np.linalg.inv(propagated)


def propagate_fitted_pose(times, world_to_body, time_s) -> np.ndarray:
    """world_to_body at ``time_s`` from constant rotation and translation rates fitted by least squares
    to registered frames: with the last frame k as reference, the rotation vectors
    x_i = log(R_i R_k^T) and the positions p_i are fitted by straight lines in t_i - t_k,

    .. math:: x_i \approx a + \omega (t_i - t_k), \quad p_i \approx b + v (t_i - t_k),
              \quad R(t) = \exp(a + \omega (t - t_k)) R_k, \quad p(t) = b + v (t - t_k)

    with R the body -> world rotation and p the origin of B in the world frame (m). Exact for a turn at a
    constant rate about a fixed axis (x_i is then exactly linear); with two frames the line passes
    through both and this is :func:`propagate_pose`. With more frames the rate's error from the frames'
    attitude errors falls (1-sigma sigma_R sqrt(12 / (n (n^2 - 1))) / dt for n frames dt apart, against
    sigma_R sqrt(2) / dt for two).

    Parameters
    ----------
    times : (n,) float
        Times of the registered frames (s), n >= 2, increasing.
    world_to_body : sequence of n (4, 4) float
        Their world_to_body transforms (m).
    time_s : float
        Time of the propagated pose (s).

    Returns
    -------
    (4, 4) float
        Propagated world_to_body (m).
    """
    times = np.asarray(times, float)
    if len(times) < 2 or len(times) != len(world_to_body):
        raise ValueError(f"propagate_fitted_pose needs n >= 2 times and as many poses; got {len(times)} "
                         f"times and {len(world_to_body)} poses")
    body_to_world = [np.linalg.inv(pose) for pose in world_to_body]
    reference = body_to_world[-1][:3, :3]
    elapsed = times - times[-1]
    turns = Rotation.from_matrix(np.array([pose[:3, :3] @ reference.T for pose in body_to_world])).as_rotvec()
    places = np.array([pose[:3, 3] for pose in body_to_world])
    design = np.column_stack([np.ones_like(elapsed), elapsed])
    (turn_0, rate), (place_0, velocity) = (np.linalg.lstsq(design, values, rcond=None)[0] for values in (turns, places))
    propagated = np.eye(4)
    propagated[:3, :3] = Rotation.from_rotvec(turn_0 + rate * (time_s - times[-1])).as_matrix() @ reference
    propagated[:3, 3] = place_0 + velocity * (time_s - times[-1])
    return np.linalg.inv(propagated)
