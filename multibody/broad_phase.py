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

import numpy as np
from numba import njit

from multibody.jit_cache import NO_REFCOUNTS


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


@njit(cache=True, **NO_REFCOUNTS)  # no reference counts (jit_cache.NO_REFCOUNTS)
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
