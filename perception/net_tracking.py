"""The net as the LiDAR sees it, and its node positions and momentum from the scans
(Tang et al. 2023, Sec. 3.2: "identification of net node position changes").

The threads are ray-cast as thin prisms (:func:`thread_mesh`). From a scan's thread returns,
:func:`fit_net_nodes` estimates every node of the known net topology at once: each return lies
on its nearest thread (point-to-segment residual across the thread), the nodes stay close to a
prediction (the last estimate carried by the chaser's measured motion), neighbouring nodes move
alike (one smoothness term per thread) and the rim stays on the chaser's rod tips. With the
associations fixed the problem is linear in the node displacements; it is solved sparse and
re-associated a few times (an ICP on a deformable graph). Nodes the sensor does not see (the
paper's 30 deg vertical field of view shows a strip of the net) follow the smoothness prior
between the seen strip and the rim.

Node velocities come from a Savitzky-Golay filter over the frames (order 4 over 7 frames); the net's
momentum from the design's node masses (the paper's assumption (b): the thread mass lumped on the nodes).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.signal import savgol_coeffs, savgol_filter
from scipy.sparse.linalg import spsolve


def thread_mesh(positions, threads, radius, sides=6) -> tuple[np.ndarray, np.ndarray]:
    """Threads as open prisms of ``sides`` faces around each segment, for ray casting.

    Parameters
    ----------
    positions : (n, 3) float
        Node positions (m), in the frame the mesh is wanted in (world, or sensor for a cast).
    threads : (m, 2) int
        Node pairs joined by a thread.
    radius : float
        Prism circumradius (m), the thread's radius.
    sides : int
        Faces around each thread.

    Returns
    -------
    vertices : (2 sides m, 3) float
        Prism vertices (m, the frame of ``positions``).
    faces : (2 sides m, 3) int
        Triangles as vertex indices.
    """
    a = np.asarray(positions, float)[threads[:, 0]]
    b = np.asarray(positions, float)[threads[:, 1]]
    axis = b - a
    axis /= np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-12)
    helper = np.where(np.abs(axis[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(axis, e1)
    angle = 2 * np.pi * np.arange(sides) / sides
    ring = radius * (np.cos(angle)[None, :, None] * e1[:, None] + np.sin(angle)[None, :, None] * e2[:, None])
    vertices = np.concatenate([a[:, None] + ring, b[:, None] + ring], axis=1)   # (m, 2 sides, 3)
    k = np.arange(sides)
    k1 = (k + 1) % sides
    local = np.concatenate([np.c_[k, k1, sides + k], np.c_[k1, sides + k1, sides + k]])
    offsets = (2 * sides * np.arange(len(threads)))[:, None, None]
    return vertices.reshape(-1, 3), (local[None] + offsets).reshape(-1, 3)


def nearest_segments(points, positions, threads, chunk=4096):
    """For each point (p, 3): index of its nearest thread, the parameter s in [0, 1] of the
    nearest point on it (from the thread's first node) and the distance (m).

    Parameters
    ----------
    points : (p, 3) float
        Query points (m), in the frame of ``positions`` (world in the pipeline).
    positions : (n, 3) float
        Node positions (m).
    threads : (m, 2) int
        Node pairs joined by a thread.
    chunk : int
        Points handled at once (memory: chunk x m x 3 floats).

    Returns
    -------
    index : (p,) int
        Row of ``threads`` of the nearest thread.
    param : (p,) float
        Position s (-) of the nearest point along it, 0 at ``threads[index, 0]``.
    distance : (p,) float
        Distance to it (m).
    """
    a = positions[threads[:, 0]]
    ab = positions[threads[:, 1]] - a
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12)
    index = np.empty(len(points), int)
    param = np.empty(len(points))
    distance = np.empty(len(points))
    for start in range(0, len(points), chunk):
        p = points[start:start + chunk]
        rel = p[:, None, :] - a[None]
        s = np.clip(np.einsum("pmj,mj->pm", rel, ab) / length2, 0.0, 1.0)
        d2 = np.sum((rel - s[..., None] * ab[None]) ** 2, axis=2)
        best = np.argmin(d2, axis=1)
        rows = np.arange(len(p))
        index[start:start + chunk] = best
        param[start:start + chunk] = s[rows, best]
        distance[start:start + chunk] = np.sqrt(d2[rows, best])
    return index, param, distance


@dataclass
class NetFit:
    """One frame's net estimate: node positions (n, 3) (m, world), which nodes had returns on
    an adjoining thread, how many returns were used and their RMS distance to the threads (m)."""

    positions_world: np.ndarray
    observed: np.ndarray
    n_points: int
    residual_rms: float


@dataclass(frozen=True)
class NetPrior:
    """Weights of :func:`fit_net_nodes` as standard deviations (m).

    point : scatter of a return about its thread's axis (range noise and thread radius).
    prediction : how far a node may move from its prediction in one frame.
    smoothness : how differently two joined nodes may move in one frame.
    anchor : how far a rim node may sit from its rod tip (the mount's compliance).
    gate : returns farther than this from every predicted thread are not net returns.
    stretch : how far a thread may be longer than its rest length (used when :func:`fit_net_nodes` is given
        the rest lengths): a thread is inextensible in tension and free in slack, so the meshes between the
        rim held at the rod tips and a seen node are counted by the threads' lengths and a grid slid by a
        mesh costs a stretched thread (it cannot slip as the association alone can; docs/perception.md, percep21).
    """

    point: float = 0.02
    prediction: float = 0.1
    smoothness: float = 0.02
    anchor: float = 0.01
    gate: float = 0.15
    stretch: float = 0.01


def fit_net_nodes(points_world, predicted_world, threads, prior: NetPrior = NetPrior(), anchors=None,
                  iterations=4, rest_lengths=None) -> NetFit:
    """Node positions of a net of known topology from its LiDAR returns (see module docstring).

    Parameters
    ----------
    points_world : (p, 3)       Candidate returns (m), world frame.
    predicted_world : (n, 3)    Predicted node positions (m), world frame.
    threads : (m, 2) int        Node pairs joined by a thread.
    prior : NetPrior            Weights of the terms as standard deviations (m).
    anchors : (node indices (a,), positions (a, 3)) or None: nodes held near known points
                                (m, world frame; the chaser's rod tips).
    iterations : int            Re-associations of the returns to the threads.
    rest_lengths : (m,) float or None   Rest length of each thread (m): a thread longer than it at the current
                                iterate adds the residual (length - rest) / ``prior.stretch``, linearized
                                (:func:`_stretch_terms`). None: no length term (the stage's fit).
    """
    predicted = np.asarray(predicted_world, float)
    points = np.asarray(points_world, float).reshape(-1, 3)
    threads = np.asarray(threads)
    n = len(predicted)
    # Fixed parts of the normal equations: prediction, smoothness and anchors (block-diagonal
    # or thread-coupling, independent of the associations).
    eye = sp.identity(3 * n, format="csr")
    m = len(threads)
    incidence = sp.csr_matrix((np.r_[np.ones(m), -np.ones(m)], (np.r_[np.arange(m), np.arange(m)],
                                                                np.r_[threads[:, 0], threads[:, 1]])), shape=(m, n))
    smooth = sp.kron(incidence.T @ incidence, sp.identity(3), format="csr")
    normal_fixed = eye / prior.prediction**2 + smooth / prior.smoothness**2
    rhs_fixed = np.zeros(3 * n)
    if anchors is not None:
        nodes, targets = anchors
        columns = (3 * np.asarray(nodes)[:, None] + np.arange(3)).ravel()
        mask = np.zeros(3 * n)
        mask[columns] = 1.0
        normal_fixed = normal_fixed + sp.diags(mask) / prior.anchor**2
        rhs_fixed[columns] = (np.asarray(targets) - predicted[nodes]).ravel() / prior.anchor**2

    positions = predicted.copy()
    use = np.zeros(len(points), bool)
    distance = np.zeros(len(points))
    for _ in range(iterations):
        index, s, distance = nearest_segments(points, positions, threads) if len(points) else (
            np.zeros(0, int), np.zeros(0), np.zeros(0))
        use = distance < prior.gate
        normal, rhs = normal_fixed, rhs_fixed.copy()
        if use.any():
            i_node, j_node = threads[index[use], 0], threads[index[use], 1]
            s_use = s[use]
            u = positions[j_node] - positions[i_node]
            u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-12)
            across = (np.eye(3)[None] - u[:, :, None] * u[:, None, :]) / prior.point**2   # (q, 3, 3)
            # residual P (p - (1-s) x_i - s x_j) with x = predicted + d, in d:
            # J = -P [(1-s) I, s I]; normal += J^T J / sigma^2 = blocks w_a w_b P / sigma^2.
            weights = np.stack([1.0 - s_use, s_use], axis=1)
            nodes = np.stack([i_node, j_node], axis=1)
            rows, cols, vals = [], [], []
            for a in range(2):
                for b in range(2):
                    block = (weights[:, a] * weights[:, b])[:, None, None] * across
                    r = (3 * nodes[:, a])[:, None, None] + np.arange(3)[None, :, None]
                    c = (3 * nodes[:, b])[:, None, None] + np.arange(3)[None, None, :]
                    rows.append(np.broadcast_to(r, block.shape).ravel())
                    cols.append(np.broadcast_to(c, block.shape).ravel())
                    vals.append(block.ravel())
            normal = normal + sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                            shape=(3 * n, 3 * n))
            offset = points[use] - (1 - s_use)[:, None] * predicted[i_node] - s_use[:, None] * predicted[j_node]
            pulled = np.einsum("qij,qj->qi", across, offset)
            for a in range(2):
                np.add.at(rhs, (3 * nodes[:, a])[:, None] + np.arange(3), weights[:, [a]] * pulled)
        if rest_lengths is not None:
            extra_normal, extra_rhs = _stretch_terms(positions, predicted, threads, np.asarray(rest_lengths, float),
                                                     prior.stretch)
            normal, rhs = normal + extra_normal, rhs + extra_rhs
        positions = predicted + spsolve(normal.tocsc(), rhs).reshape(n, 3)
    observed = np.zeros(n, bool)
    if use.any():
        observed[threads[index[use]].ravel()] = True
    rms = float(np.sqrt(np.mean(distance[use] ** 2))) if use.any() else float("nan")
    return NetFit(positions, observed, int(use.sum()), rms)


def _stretch_terms(positions, predicted, threads, rest_lengths, sigma):
    """Normal-equation terms (3n, 3n) sparse and (3n,) of the stretched threads' residuals
    r = (|x_j - x_i| - L0) / sigma, linearized at ``positions`` in the displacements d = x - ``predicted``
    (m): with u the thread's unit vector, J = u^T on j and -u^T on i, J d_now the length change so far;
    minimizing (|x_j - x_i| - L0 + J (d - d_now))^2 / sigma^2 adds J^T J / sigma^2 and
    J^T (J d_now - (|x_j - x_i| - L0)) / sigma^2. Slack threads (shorter than L0) add nothing."""
    n = len(positions)
    vector = positions[threads[:, 1]] - positions[threads[:, 0]]
    length = np.linalg.norm(vector, axis=1)
    taut = length > rest_lengths
    if not taut.any():
        return sp.csr_matrix((3 * n, 3 * n)), np.zeros(3 * n)
    pairs, u = threads[taut], vector[taut] / length[taut, None]
    k = len(pairs)
    rows = np.repeat(np.arange(k), 6)
    cols = (3 * pairs[:, [0, 0, 0, 1, 1, 1]] + np.tile(np.arange(3), 2)).ravel()
    jacobian = sp.csr_matrix((np.c_[-u, u].ravel(), (rows, cols)), shape=(k, 3 * n))
    displacement = (positions - predicted).ravel()
    target = jacobian @ displacement - (length[taut] - rest_lengths[taut])
    return (jacobian.T @ jacobian) / sigma**2, jacobian.T @ target / sigma**2


def carried_by_chaser(positions_world, chaser_from, chaser_to) -> np.ndarray:
    """Node positions moved rigidly with the chaser from pose ``chaser_from`` to ``chaser_to``
    (each a (4, 4) chaser-body -> world transform): the net's prediction between frames.

    Parameters
    ----------
    positions_world : (n, 3) float
        Node positions at ``chaser_from`` (m, world frame).
    chaser_from, chaser_to : (4, 4) float
        Chaser body -> world transforms (m) at the earlier and the later frame.

    Returns
    -------
    (n, 3) float
        Node positions at ``chaser_to`` (m, world frame).
    """
    relative = np.asarray(chaser_to) @ np.linalg.inv(chaser_from)
    return np.asarray(positions_world) @ relative[:3, :3].T + relative[:3, 3]


#: Polynomial order of the node velocities' local fits. Order 4 over 7 frames passes a node's motion
#: within 3 % up to a tenth of the frame rate (gain 0.998 at 0.05, 0.971 at 0.1 of it; 0.68 at 0.2), where
#: order 2 (a straight-line slope over the 7 frames) keeps only 0.889 and 0.607 of it. The net's motion
#: relative to its mean after the collision has half its power below 0.2-0.6 Hz at 10 Hz frames
#: (featured debris), so order 2 under-stated the net's angular momentum by 0.10-0.12 N m s in x
#: (exact node positions differentiated; docs/perception.md, "The seen net nodes' velocities"). The price
#: is noise: 0.51 against 0.19 position standard deviations per frame period (the coefficients' norm).
VELOCITY_FIT_ORDER = 4


def velocity_gain(frequency, frame_period, window=7, order=VELOCITY_FIT_ORDER) -> float:
    """Ratio (-) of :func:`node_velocities`' estimate to the true velocity for a sinusoidal motion of
    ``frequency`` (Hz) sampled every ``frame_period`` (s), away from the ends of the frames: the
    frequency response of the Savitzky-Golay derivative, sum_k c_k sin(2 pi f k T) / (2 pi f).

    Parameters
    ----------
    frequency : float
        Frequency of the motion (Hz), > 0.
    frame_period : float
        Time between frames (s).
    window, order : int
        The local fits' frames and polynomial order.
    """
    coefficients = savgol_coeffs(window, order, deriv=1, delta=frame_period, use="dot")
    lags = frame_period * (np.arange(window) - window // 2)
    omega = 2.0 * np.pi * frequency
    return float(np.sum(coefficients * np.sin(omega * lags)) / omega)


def node_velocities(times, positions_world, window=7, order=VELOCITY_FIT_ORDER) -> np.ndarray:
    """Node velocities (k, n, 3) (m/s) from positions (k, n, 3) at equally spaced ``times``
    (k,) (s): local polynomial fits over ``window`` frames (Savitzky-Golay), not raw differences.

    Parameters
    ----------
    times : (k,) float
        Frame times (s), equally spaced, k >= 3.
    positions_world : (k, n, 3) float
        Node positions per frame (m, world frame).
    window : int
        Frames per local fit; shortened to the largest odd number <= k.
    order : int
        Polynomial order of the local fits (:data:`VELOCITY_FIT_ORDER`); lowered to window - 1 when
        the window is shortened below it.

    Returns
    -------
    (k, n, 3) float
        Node velocities (m/s, world frame).

    Notes
    -----
    A polynomial of degree <= ``order`` is differentiated exactly; a sinusoid of frequency f is scaled by
    :func:`velocity_gain`. Motion above half the frame rate cannot be recovered by any stencil (aliasing).
    """
    positions = np.asarray(positions_world, float)
    window = min(window, len(times) - (1 - len(times) % 2))
    if window < 3:
        raise ValueError("node velocities need at least 3 frames")
    step = float(np.mean(np.diff(times)))
    return savgol_filter(positions, window, min(order, window - 1), deriv=1, delta=step, axis=0, mode="interp")
