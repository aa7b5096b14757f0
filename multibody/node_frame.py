"""Each rigid body's Exudyn node carries a frame turned from the body frame, so its rotation vector never
sits near zero, where Exudyn's explicit Lie-group update loses small turns inside a step.

Measured (Exudyn 1.13.6, ``bench/bench_instep_attitude.py``; ``tests/multibody/test_node_frame.py``):
the Lie-group composition Exudyn applies to rotation-vector nodes reads the composed angle through
``cos`` of half of it, so a total rotation vector below about 2e-8 rad comes out as exactly zero and,
near it, an increment carries an absolute error of about 4e-16 rad over the angle. The end-of-step
restore of :mod:`multibody.rotation_update` corrects what the run keeps, but inside the step Exudyn's
joint springs still see its own attitude: a body on a 2 Hz rotational spring started at rest with
1e-7 rad of amplitude gains 3 % amplitude in three periods (27 % at 50 Hz), and one of 1e-9 rad is
never pulled back: its spring sees a dead zone of +-2e-8 rad, a spurious moment of up to 2e-8 k
(2 N m on a 1e8 N m/rad penalty spring) on bodies near their start attitude -- the size of the small
loads whose convergence was in doubt (docs/structures.md, "Are the judged peaks converged?").

The composition is exact to round-off away from the identity, so each body's node is given the fixed
attitude :data:`NODE_TO_LVLH_AT_START` (2 rad about a generic axis) at t = 0: the node frame is the
body frame turned by ``node_to_body = body_to_lvlh(0)^T NODE_TO_LVLH_AT_START``, fixed for the run.
Everything Exudyn sees of a body (its initial rotation vector and angular velocity, its inertia, the
joint markers' positions and frames, recorded moments) is written in the node frame once at build
time by the functions here; the compiled kernels and the recorder turn the node's attitude and rate
back to the body's (``body_to_lvlh = node_to_lvlh node_to_body^T``), so contact shapes, outputs and
every caller keep the body frame (:func:`body_state_into`, the one turn both use). The node would return
near the identity only if its body turned by that very rotation (2 rad about that axis); the end-of-step
restore still keeps the attitude exact then.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from multibody.maths.rotations import rotation_matrix_from_rotation_vector_into

#: The nodes' attitude (node->LVLH) at t = 0: 2 rad about (1, 2, 3)/sqrt(14), far from the identity
#: (where the Lie-group update loses small turns) and from a half turn (where rotation vectors flip).
NODE_TO_LVLH_AT_START = Rotation.from_rotvec(2.0 * np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)).as_matrix()


def node_to_body_rotation(body_to_lvlh_start) -> np.ndarray:
    """The fixed rotation from a body's Exudyn node frame to its body frame.

    Parameters
    ----------
    body_to_lvlh_start : (3, 3) float
        The body's attitude (body->LVLH) at t = 0.

    Returns
    -------
    (3, 3) float
        node->body rotation: ``body_to_lvlh_start @ node_to_body = NODE_TO_LVLH_AT_START``.
    """
    return np.asarray(body_to_lvlh_start, float).T @ NODE_TO_LVLH_AT_START


def node_to_body_rotations(bodies) -> np.ndarray:
    """:func:`node_to_body_rotation` of every body (from its ``body_to_lvlh`` at t = 0).

    Parameters
    ----------
    bodies : list of RigidBodySpec
        The assembly's bodies.

    Returns
    -------
    (nb, 3, 3) float
    """
    return np.array([node_to_body_rotation(b.body_to_lvlh) for b in bodies], float).reshape(-1, 3, 3)


def vector_node(vector_body, node_to_body) -> np.ndarray:
    """A body-frame vector (a position, rate or moment) in the node frame.

    Parameters
    ----------
    vector_body : (3,) float
        Body-frame components.
    node_to_body : (3, 3) float
        :func:`node_to_body_rotation`.

    Returns
    -------
    (3,) float
        Node-frame components.
    """
    return np.asarray(node_to_body, float).T @ np.asarray(vector_body, float)


def frame_node(frame_to_body, node_to_body) -> np.ndarray:
    """A frame given in the body frame (e.g. a joint frame, columns its axes) in the node frame.

    Parameters
    ----------
    frame_to_body : (3, 3) float
        frame->body rotation.
    node_to_body : (3, 3) float
        :func:`node_to_body_rotation`.

    Returns
    -------
    (3, 3) float
        frame->node rotation.
    """
    return np.asarray(node_to_body, float).T @ np.asarray(frame_to_body, float)


def inertia_node(inertia_body, node_to_body) -> np.ndarray:
    """An inertia tensor about the CoM in the node frame.

    Parameters
    ----------
    inertia_body : (3, 3) float
        Body-frame inertia (kg m^2).
    node_to_body : (3, 3) float
        :func:`node_to_body_rotation`.

    Returns
    -------
    (3, 3) float
        Node-frame inertia (kg m^2), symmetrized (round-off of the two products).
    """
    c = np.asarray(node_to_body, float)
    j = c.T @ np.asarray(inertia_body, float) @ c
    return 0.5 * (j + j.T)


@njit(cache=True, inline="always")
def body_state_into(q, qt, i, b, reference_com_lvlh, node_to_body, com_lvlh, velocity_lvlh, node_to_lvlh,
                    body_to_lvlh, omega_lvlh, omega_body):
    """Body ``b``'s state from its Exudyn node's coordinates, into row ``b`` of the outputs (no allocation, no
    row views: the force kernel calls it for every body at every evaluation, the recorder at every sample).

    Parameters
    ----------
    q, qt : (N,) float
        Exudyn's coordinates and velocities; the body's six start at ``i``: CoM displacement (m), LVLH, and
        rotation vector node->LVLH (rad); CoM velocity (m/s), LVLH, and angular velocity (rad/s), node frame.
    i, b : int
        Where the body's coordinates start; its row in the other arrays.
    reference_com_lvlh : (nb, 3) float
        Reference CoM positions (m), LVLH.
    node_to_body : (nb, 3, 3) float
        :func:`node_to_body_rotations`.
    com_lvlh, velocity_lvlh : (nb, 3) float
        Output: CoM (m) and CoM velocity (m/s), LVLH.
    node_to_lvlh, body_to_lvlh : (nb, 3, 3) float
        Output: the node's attitude and the body's (``node_to_lvlh node_to_body^T``).
    omega_lvlh, omega_body : (nb, 3) float
        Output: the angular velocity (rad/s) in LVLH and in the body frame.
    """
    for d in range(3):
        com_lvlh[b, d] = reference_com_lvlh[b, d] + q[i + d]
        velocity_lvlh[b, d] = qt[i + d]
    rotation_matrix_from_rotation_vector_into(q[i + 3], q[i + 4], q[i + 5], node_to_lvlh, b)
    wx, wy, wz = qt[i + 3], qt[i + 4], qt[i + 5]
    # in scalars: numba sends small matrix products to BLAS, microseconds a call
    for r in range(3):
        omega_lvlh[b, r] = node_to_lvlh[b, r, 0] * wx + node_to_lvlh[b, r, 1] * wy + node_to_lvlh[b, r, 2] * wz
        omega_body[b, r] = node_to_body[b, r, 0] * wx + node_to_body[b, r, 1] * wy + node_to_body[b, r, 2] * wz
        for k in range(3):
            body_to_lvlh[b, r, k] = (node_to_lvlh[b, r, 0] * node_to_body[b, k, 0]
                                     + node_to_lvlh[b, r, 1] * node_to_body[b, k, 1]
                                     + node_to_lvlh[b, r, 2] * node_to_body[b, k, 2])
