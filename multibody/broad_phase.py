"""Which net nodes can touch which contact shape within a step, and the exact distance to box shapes.

The kernel (:mod:`multibody.kernel`) checked every node against every shape's bounding box in the
body frame with early exits, about 8 ns a pair, 50 us a step for the reference case's 1229 nodes and
5 shapes, nearly all of them far from any shape. Here a first pass does the same box test branch-free,
shape by shape over all nodes, a loop the compiler vectorizes (about 2 ns a pair; a bounding-sphere
test was tried first and let most nodes through: the array and the ASAR are long flat plates); only
flagged nodes go on to the exact margin test and the closest-point search.

Box shapes (the case's ``kind = "box"``, a 12-triangle mesh whose corners are its body-frame
bounding box) get their signed distance in closed form instead of 12 closest-point-on-triangle
searches; the result is the same point, distance and normal (Ericson 2005, Sec. 5.1.3).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit


def box_shape_flags(triangles, triangle_range, box_min, box_max) -> np.ndarray:
    """(ns,) int64: 1 where a shape is the axis-aligned box of its body-frame bounds (12 triangles, every
    corner at a bound), else 0 (the shape keeps the triangle search).

    Parameters
    ----------
    triangles : (T, 3, 3) float
        Triangle corners of all shapes, each in its body's frame (m).
    triangle_range : (ns, 2) int
        First and past-the-last triangle of each shape.
    box_min, box_max : (ns, 3) float
        Bounds of each shape, body frame (m).
    """
    flags = np.zeros(len(triangle_range), np.int64)
    for s, (first, last) in enumerate(triangle_range):
        if last - first != 12:
            continue
        corners = triangles[first:last].reshape(-1, 3)
        size = np.maximum(box_max[s] - box_min[s], 1e-300)
        at_bound = (np.isclose(corners, box_min[s], rtol=0, atol=1e-12 * size.max())
                    | np.isclose(corners, box_max[s], rtol=0, atol=1e-12 * size.max()))
        flags[s] = int(at_bound.all() and (box_max[s] > box_min[s]).all())
    return flags


@njit(cache=True, inline="always")
def box_signed_distance(px, py, pz, box_min, box_max, s):
    """Signed distance (m) of body-frame point p to the box [lo, hi] = [box_min[s], box_max[s]] (negative
    inside), and the unit normal from the surface to the point (the face normal inside), body frame; as
    :func:`multibody.contact.signed_distance_to_mesh` on the box's mesh.

    Parameters
    ----------
    px, py, pz : float
        The point, body frame (origin at the body's CoM) (m).
    box_min, box_max : (ns, 3) float
        The shapes' lower and upper corners, body frame (m); read at row ``s`` (whole arrays and an index,
        not row views: a view is a reference count taken and dropped per node and shape).
    s : int
        The shape.

    Returns
    -------
    tuple of 4 float
        Distance (m) and the unit normal's x, y, z components, body frame.
    """
    lo0, lo1, lo2 = box_min[s, 0], box_min[s, 1], box_min[s, 2]
    hi0, hi1, hi2 = box_max[s, 0], box_max[s, 1], box_max[s, 2]
    cx, cy, cz = 0.5 * (lo0 + hi0), 0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2)
    dx, dy, dz = px - cx, py - cy, pz - cz
    qx, qy, qz = abs(dx) - 0.5 * (hi0 - lo0), abs(dy) - 0.5 * (hi1 - lo1), abs(dz) - 0.5 * (hi2 - lo2)
    # nearest face: the largest q
    if qx >= qy and qx >= qz:
        face, fx, fy, fz = qx, math.copysign(1.0, dx), 0.0, 0.0
    elif qy >= qz:
        face, fx, fy, fz = qy, 0.0, math.copysign(1.0, dy), 0.0
    else:
        face, fx, fy, fz = qz, 0.0, 0.0, math.copysign(1.0, dz)
    if face <= 0.0:
        return face, fx, fy, fz
    ox = math.copysign(max(qx, 0.0), dx)
    oy = math.copysign(max(qy, 0.0), dy)
    oz = math.copysign(max(qz, 0.0), dz)
    distance = math.sqrt(ox * ox + oy * oy + oz * oz)
    if distance > 1e-12:
        return distance, ox / distance, oy / distance, oz / distance
    return 0.0, fx, fy, fz


@njit(cache=True)
def flag_candidates(x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags):
    """``flags[s, i]`` = 1 where node ``i`` (LVLH position ``x_lvlh[i]`` (m)) is inside shape ``s``'s body-frame
    bounding box grown by ``reach[i] + shape_reach[s]`` (m: what node and shape can close within the
    step), else 0; ``flags[ns, i]`` (the row after the ns shapes' rows) = 1 where any shape's flag is,
    so the contact pass skips a far node with one read. Branch-free over the nodes, so the compiler
    vectorizes it: the positions come coordinate-major (3, n), since strided loads from (n, 3) kept the
    loop scalar (12 us against 3 us a pass for the reference case's 1229 nodes and 5 shapes); the kernel
    has them so already, for the threads.

    Parameters
    ----------
    x_lvlh_soa : (3, n) float
        Net node positions, LVLH (m), coordinate-major.
    reach : (n,) float
        Each node's contact radius plus the distance it can travel within the step (m).
    body_to_lvlh : (nb, 3, 3) float
        Body attitudes (columns: body axes in LVLH).
    com_lvlh : (nb, 3) float
        Body CoMs, LVLH (m).
    shape_body : (ns,) int
        Body carrying each shape.
    box_min, box_max : (ns, 3) float
        Bounds of each shape, body frame (m).
    shape_reach : (ns,) float
        Distance each shape's surface can travel within the step (m).
    flags : (ns + 1, n) int
        Output, overwritten: one row per shape, then the "near any shape" row.
    """
    n = x_lvlh_soa.shape[1]
    x0, x1, x2 = x_lvlh_soa[0], x_lvlh_soa[1], x_lvlh_soa[2]
    n_shapes = shape_body.shape[0]
    near_any = flags[n_shapes]
    near_any[:] = 0
    for s in range(n_shapes):
        b = shape_body[s]
        body_to_lvlh_b = body_to_lvlh[b]
        # box centre in LVLH, half sizes in the body frame
        mx, my, mz = (0.5 * (box_min[s, 0] + box_max[s, 0]), 0.5 * (box_min[s, 1] + box_max[s, 1]),
                      0.5 * (box_min[s, 2] + box_max[s, 2]))
        cx = com_lvlh[b, 0] + body_to_lvlh_b[0, 0] * mx + body_to_lvlh_b[0, 1] * my + body_to_lvlh_b[0, 2] * mz
        cy = com_lvlh[b, 1] + body_to_lvlh_b[1, 0] * mx + body_to_lvlh_b[1, 1] * my + body_to_lvlh_b[1, 2] * mz
        cz = com_lvlh[b, 2] + body_to_lvlh_b[2, 0] * mx + body_to_lvlh_b[2, 1] * my + body_to_lvlh_b[2, 2] * mz
        hx = 0.5 * (box_max[s, 0] - box_min[s, 0]) + shape_reach[s]
        hy = 0.5 * (box_max[s, 1] - box_min[s, 1]) + shape_reach[s]
        hz = 0.5 * (box_max[s, 2] - box_min[s, 2]) + shape_reach[s]
        r00, r01, r02 = body_to_lvlh_b[0, 0], body_to_lvlh_b[0, 1], body_to_lvlh_b[0, 2]
        r10, r11, r12 = body_to_lvlh_b[1, 0], body_to_lvlh_b[1, 1], body_to_lvlh_b[1, 2]
        r20, r21, r22 = body_to_lvlh_b[2, 0], body_to_lvlh_b[2, 1], body_to_lvlh_b[2, 2]
        row = flags[s]
        for i in range(n):
            dx, dy, dz = x0[i] - cx, x1[i] - cy, x2[i] - cz
            px = r00 * dx + r10 * dy + r20 * dz
            py = r01 * dx + r11 * dy + r21 * dz
            pz = r02 * dx + r12 * dy + r22 * dz
            grow = reach[i]
            row[i] = (abs(px) <= hx + grow) & (abs(py) <= hy + grow) & (abs(pz) <= hz + grow)
            near_any[i] |= row[i]


# --- the skin: most nodes skip the box pass --------------------------------------------------------------------

#: Above sqrt(3): the LVLH axis-aligned box of a body-frame box grown by e along its own axes reaches at most
#: e * sum_k |R_jk| <= sqrt(3) e beyond the LVLH box of the ungrown one (R a rotation; each row a unit vector).
SKIN_ROTATION_FACTOR = 1.7321
#: Absolute slack (m) for the rounding of the distances below (about 1e-13 m at 1 km from the origin).
SKIN_ROUNDING_M = 1e-6
#: A new skin after this many force evaluations, whatever else happens.
SKIN_MAX_AGE = 200
#: A new skin when this many more nodes need the exact test than right after the last one.
SKIN_GROWTH_NODES = 64
#: The full pass instead while more than 1 / this of the nodes needed the test right after the skin was made.
SKIN_FULL_PASS_SHARE = 8


class BroadPhaseSkin(NamedTuple):
    """What :func:`flag_candidates_skin` keeps between evaluations (n nodes, ns shapes): where every node was
    when the skin was made and how far it then was from every shape's LVLH box."""

    position: np.ndarray    # (3, n) node positions (m), LVLH, coordinate-major, when the skin was made
    clearance: np.ndarray   # (n,) L-infinity distance (m) from there to the nearest shape's LVLH box (0 inside)
    box: np.ndarray         # (ns, 6) every shape's LVLH box then (m): lower corner, upper corner
    box_now: np.ndarray     # (ns, 6) work space: the boxes at this evaluation
    index: np.ndarray       # (n,) int64 work space: the nodes that take the test
    compact: np.ndarray     # (4, n) work space: their positions (m, LVLH) and reaches (m), gathered
    compact_flags: np.ndarray  # (ns, n) uint8 work space: their flags
    need: np.ndarray        # (n,) uint8 work space: 1 where the node takes the exact box test
    counts: np.ndarray      # (4,) int64: evaluations since the skin was made (SKIN_MAX_AGE + 1: none yet),
                            # nodes needing the test right after it, skins made, exact node tests (statistics)


def broad_phase_skin(n_nodes: int, n_shapes: int) -> BroadPhaseSkin:
    """An empty :class:`BroadPhaseSkin` (the first evaluation makes one).

    Parameters
    ----------
    n_nodes, n_shapes : int
    """
    counts = np.zeros(4, np.int64)
    counts[0] = SKIN_MAX_AGE + 1
    return BroadPhaseSkin(np.zeros((3, n_nodes)), np.zeros(n_nodes), np.zeros((n_shapes, 6)),
                          np.zeros((n_shapes, 6)), np.zeros(n_nodes, np.int64), np.zeros((4, n_nodes)),
                          np.zeros((n_shapes, n_nodes), np.uint8), np.zeros(n_nodes, np.uint8), counts)


@njit(cache=True)
def shape_lvlh_boxes(body_to_lvlh, com_lvlh, shape_body, box_min, box_max, out):
    """Each shape's LVLH axis-aligned box (m), which holds its body-frame box: centre c = com + R m, half size
    a_j = sum_k |R_jk| h_k (m, h: the body-frame box's centre and half sizes).

    Parameters
    ----------
    body_to_lvlh : (nb, 3, 3) float
    com_lvlh : (nb, 3) float
        Body CoMs, LVLH (m).
    shape_body : (ns,) int
    box_min, box_max : (ns, 3) float
        Body-frame bounds of each shape (m).
    out : (ns, 6) float
        Output: lower corner, upper corner (m), LVLH.
    """
    for s in range(shape_body.shape[0]):
        b = shape_body[s]
        for j in range(3):
            centre = com_lvlh[b, j]
            half = 0.0
            for k in range(3):
                middle = 0.5 * (box_min[s, k] + box_max[s, k])
                centre += body_to_lvlh[b, j, k] * middle
                half += abs(body_to_lvlh[b, j, k]) * 0.5 * (box_max[s, k] - box_min[s, k])
            out[s, j] = centre - half
            out[s, 3 + j] = centre + half


@njit(cache=True)
def flag_candidates_skin(x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags,
                         skin):
    """:func:`flag_candidates`, the same flags to the bit, with most nodes skipped: a node whose clearance from
    every shape when the skin was made, less how far it and the shapes' LVLH boxes have moved since, exceeds
    sqrt(3) times its reach plus the shapes' (:data:`SKIN_ROTATION_FACTOR`) cannot be flagged, so its flags
    are 0 without the box test; the others take :func:`flag_candidates`'s test, with its arithmetic.

    Why that is exact: flagged for shape s means inside s's body-frame box grown by e = reach + shape reach
    along its axes, hence inside the LVLH box of that, which is s's LVLH box grown by at most sqrt(3) e; the
    current LVLH box lies inside the one kept with the skin grown by ``growth`` (the largest amount any
    corner moved outward since), and the node is within ``moved`` (L-infinity) of where it was. So its
    distance from the kept box is at most sqrt(3) e + growth + moved. The skin is made again (one pass
    like :func:`flag_candidates`'s, without the rotation) when it is :data:`SKIN_MAX_AGE` evaluations old
    or :data:`SKIN_GROWTH_NODES` more nodes need the test than right after it was made. A node moving at
    20 m/s covers 2 mm in a 1e-4 s step, so a node 1 m from every box skips hundreds of box tests. While more
    than 1 / :data:`SKIN_FULL_PASS_SHARE` of the nodes needed the test right after the skin was made (a net
    wrapped around a tilted body, whose LVLH box holds hundreds of nodes), the full pass runs instead: it
    costs less then (docs/model.md, Speed, helper "speed8").

    Parameters
    ----------
    x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags
        As :func:`flag_candidates`.
    skin : BroadPhaseSkin
        Carried from evaluation to evaluation (any states: the test holds between any two).
    """
    n = x_lvlh_soa.shape[1]
    n_shapes = shape_body.shape[0]
    position, clearance, box, box_now, need, counts = (skin.position, skin.clearance, skin.box, skin.box_now,
                                                       skin.need, skin.counts)
    shape_lvlh_boxes(body_to_lvlh, com_lvlh, shape_body, box_min, box_max, box_now)
    shape_reach_max = 0.0
    for s in range(n_shapes):
        shape_reach_max = max(shape_reach_max, shape_reach[s])
    finite = shape_reach_max < math.inf
    for s in range(n_shapes):
        for j in range(6):
            finite &= abs(box_now[s, j]) < math.inf
    waiting = 0
    if not finite:
        # a body's state is not finite (the run is failing): every node takes the test, a new skin next time
        need[:] = 1
        counts[0] = SKIN_MAX_AGE + 1
        _flag_needed(x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags,
                     need, skin)
        return
    rebuild = counts[0] > SKIN_MAX_AGE
    if not rebuild and counts[1] > n // SKIN_FULL_PASS_SHARE:
        # too many nodes near the boxes right after the skin was made (a net wrapped around a body): the full
        # pass, vectorized over every node, costs less than the skin's pass and the gathered test; until the
        # skin is due again
        counts[0] += 1
        flag_candidates(x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags)
        return
    if not rebuild:
        growth = 0.0
        for s in range(n_shapes):
            for j in range(3):
                growth = max(growth, box[s, j] - box_now[s, j], box_now[s, 3 + j] - box[s, 3 + j])
        _skin_need(x_lvlh_soa, position, clearance, reach, growth, shape_reach_max, need)
        for i in range(n):
            waiting += need[i]
        rebuild = waiting > counts[1] + SKIN_GROWTH_NODES
    if rebuild:
        _make_skin(x_lvlh_soa, box_now, position, clearance, box)
        _skin_need(x_lvlh_soa, position, clearance, reach, 0.0, shape_reach_max, need)
        waiting = 0
        for i in range(n):
            waiting += need[i]
        counts[0] = 0
        counts[1] = waiting
        counts[2] += 1
    counts[0] += 1
    counts[3] += waiting
    _flag_needed(x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags, need,
                 skin)


@njit(cache=True, inline="always")
def _skin_need(x, position, clearance, reach, growth, shape_reach_max, need):
    """need[i] = 1 where node i may be flagged (:func:`flag_candidates_skin`); 2D indexing, few arrays: the
    loop vectorizes."""
    for i in range(x.shape[1]):
        moved = max(abs(x[0, i] - position[0, i]), abs(x[1, i] - position[1, i]), abs(x[2, i] - position[2, i]))
        # written as "not beyond": a NaN anywhere takes the test
        need[i] = not (clearance[i] - moved - growth
                       > SKIN_ROTATION_FACTOR * (reach[i] + shape_reach_max) + SKIN_ROUNDING_M)


@njit(cache=True)
def _make_skin(x, box_now, position, clearance, box):
    """Keep the nodes' positions, the shapes' LVLH boxes, and each node's L-infinity distance to the nearest."""
    n = x.shape[1]
    box[:] = box_now
    for d in range(3):
        for i in range(n):
            position[d, i] = x[d, i]
    clearance[:] = math.inf
    for s in range(box_now.shape[0]):
        lo0, lo1, lo2 = box_now[s, 0], box_now[s, 1], box_now[s, 2]
        hi0, hi1, hi2 = box_now[s, 3], box_now[s, 4], box_now[s, 5]
        for i in range(n):
            outside = max(lo0 - x[0, i], x[0, i] - hi0, lo1 - x[1, i], x[1, i] - hi1, lo2 - x[2, i], x[2, i] - hi2,
                          0.0)
            clearance[i] = min(clearance[i], outside)


@njit(cache=True)
def _flag_needed(x_lvlh_soa, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach, flags, need,
                 skin):
    """:func:`flag_candidates`'s test, with its arithmetic (the same flags to the bit), on the nodes with
    ``need``, gathered into ``skin.compact`` so that the test's loop vectorizes as the full pass's does;
    every other node's flags 0."""
    n = x_lvlh_soa.shape[1]
    n_shapes = shape_body.shape[0]
    index, compact, compact_flags = skin.index, skin.compact, skin.compact_flags
    m = 0
    for i in range(n):
        if need[i]:
            index[m] = i
            m += 1
    c0, c1, c2, c_reach = compact[0], compact[1], compact[2], compact[3]
    for j in range(m):
        i = index[j]
        c0[j] = x_lvlh_soa[0, i]
        c1[j] = x_lvlh_soa[1, i]
        c2[j] = x_lvlh_soa[2, i]
        c_reach[j] = reach[i]
    for s in range(n_shapes):
        b = shape_body[s]
        body_to_lvlh_b = body_to_lvlh[b]
        mx, my, mz = (0.5 * (box_min[s, 0] + box_max[s, 0]), 0.5 * (box_min[s, 1] + box_max[s, 1]),
                      0.5 * (box_min[s, 2] + box_max[s, 2]))
        cx = com_lvlh[b, 0] + body_to_lvlh_b[0, 0] * mx + body_to_lvlh_b[0, 1] * my + body_to_lvlh_b[0, 2] * mz
        cy = com_lvlh[b, 1] + body_to_lvlh_b[1, 0] * mx + body_to_lvlh_b[1, 1] * my + body_to_lvlh_b[1, 2] * mz
        cz = com_lvlh[b, 2] + body_to_lvlh_b[2, 0] * mx + body_to_lvlh_b[2, 1] * my + body_to_lvlh_b[2, 2] * mz
        hx = 0.5 * (box_max[s, 0] - box_min[s, 0]) + shape_reach[s]
        hy = 0.5 * (box_max[s, 1] - box_min[s, 1]) + shape_reach[s]
        hz = 0.5 * (box_max[s, 2] - box_min[s, 2]) + shape_reach[s]
        r00, r01, r02 = body_to_lvlh_b[0, 0], body_to_lvlh_b[0, 1], body_to_lvlh_b[0, 2]
        r10, r11, r12 = body_to_lvlh_b[1, 0], body_to_lvlh_b[1, 1], body_to_lvlh_b[1, 2]
        r20, r21, r22 = body_to_lvlh_b[2, 0], body_to_lvlh_b[2, 1], body_to_lvlh_b[2, 2]
        row = compact_flags[s]
        for j in range(m):
            dx, dy, dz = c0[j] - cx, c1[j] - cy, c2[j] - cz
            px = r00 * dx + r10 * dy + r20 * dz
            py = r01 * dx + r11 * dy + r21 * dz
            pz = r02 * dx + r12 * dy + r22 * dz
            grow = c_reach[j]
            row[j] = (abs(px) <= hx + grow) & (abs(py) <= hy + grow) & (abs(pz) <= hz + grow)
    flags[:, :] = 0
    near_any = flags[n_shapes]
    for j in range(m):
        i = index[j]
        for s in range(n_shapes):
            flags[s, i] = compact_flags[s, j]
            near_any[i] |= compact_flags[s, j]
