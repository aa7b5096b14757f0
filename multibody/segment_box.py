"""The closest approach of a straight segment (a net thread) to a box, exactly: the deepest point, the part
of the segment pressed below a level, and the contact normal perpendicular to the segment.

The signed distance to a convex shape is convex along a line; for a box, between the points where the segment
crosses one of the box's six slab planes or three mid-planes (:func:`segment_box_breakpoints`), it is the norm
of the positive excesses over the slabs (outside: the root of a quadratic in the segment's parameter) or the
largest excess (inside: a maximum of lines), each minimized or thresholded in closed form. Used by the threads'
contact (:mod:`multibody.contact_segment`). Body frame of the box (m).
"""
from __future__ import annotations

import math

from numba import njit

from multibody.jit_cache import NO_REFCOUNTS, WITH_REFCOUNTS

#: Distance (m) within which points of a thread count as equally deep: a thread parallel to a face to
#: round-off (1e-9 m over a 2 m thread is a 5e-10 rad tilt) takes its load at the middle of the overlap,
#: and its interior counts as deeper than its ends only beyond this (a thread on a face adds nothing).
TIE_DISTANCE = 1e-9

#: Most breakpoints of a segment against a box: 0, 1 and three per axis (the two slab planes and the
#: mid-plane), sorted into the intervals on which the signed distance has one closed form.
MAX_BREAKPOINTS = 11


@njit(cache=True, **NO_REFCOUNTS)
def segment_box_breakpoints(a, d, lo, hi, out):
    """Sorted parameters t in [0, 1] where the segment a + t d crosses one of the box's six slab planes or
    three mid-planes, with 0 and 1; returns how many (the first entries of ``out``).

    Parameters
    ----------
    a, d : tuple of 3 float
        Segment start and direction (end minus start), body frame (m).
    lo, hi : tuple of 3 float
        The box's corners, body frame (m).
    out : (MAX_BREAKPOINTS,) float
        Output.
    """
    out[0] = 0.0
    k = 1
    for i in range(3):
        if d[i] == 0.0:
            continue
        for plane in (lo[i], 0.5 * (lo[i] + hi[i]), hi[i]):
            t = (plane - a[i]) / d[i]
            if 0.0 < t < 1.0:
                out[k] = t
                k += 1
    out[k] = 1.0
    k += 1
    # insertion sort: at most 11 entries
    for j in range(1, k):
        value = out[j]
        q = j - 1
        while q >= 0 and out[q] > value:
            out[q + 1] = out[q]
            q -= 1
        out[q + 1] = value
    return k


@njit(cache=True, inline="always")
def _pieces(a, d, lo, hi, t):
    """On the interval holding t: per axis, the signed excess over the nearer slab plane, alpha + beta t (m),
    and whether it is positive there (the point outside that slab)."""
    a0 = a1 = a2 = b0 = b1 = b2 = 0.0
    out0 = out1 = out2 = False
    for i in range(3):
        u = a[i] + d[i] * t
        if u < 0.5 * (lo[i] + hi[i]):
            alpha, beta = lo[i] - a[i], -d[i]
        else:
            alpha, beta = a[i] - hi[i], d[i]
        outside = alpha + beta * t > 0.0
        if i == 0:
            a0, b0, out0 = alpha, beta, outside
        elif i == 1:
            a1, b1, out1 = alpha, beta, outside
        else:
            a2, b2, out2 = alpha, beta, outside
    return (a0, a1, a2), (b0, b1, b2), (out0, out1, out2)


@njit(cache=True, inline="always")
def _inside_distance(alpha, beta, t):
    """max_i (alpha_i + beta_i t): the signed distance of a point inside the box (m, negative)."""
    return max(alpha[0] + beta[0] * t, alpha[1] + beta[1] * t, alpha[2] + beta[2] * t)


@njit(cache=True, **NO_REFCOUNTS)
def segment_box_separation(a, d, lo, hi):
    """A lower bound (m) of the distance between the segment a + t d, t in [0, 1], and the box [lo, hi]: the largest
    gap between their projections on the separating axes of a segment and a box, the box's three axes e_i and the
    three directions d x e_i across the segment (the set that separates any disjoint pair of them, Gottschalk et al.
    1996). The distance is at least the gap along any unit axis u, since |x - y| >= u . (x - y); a positive bound
    proves the two apart, zero or less proves nothing.

    .. math:: g_u = \frac{|u \cdot (a - c)| - \sum_k |u_k| h_k}{|u|}, \qquad u = d \times e_i

    (c the box's centre, h its half sizes; the segment projects to the one value u . a on such an axis). The axes'
    components are d's own (no round-off), so the bound's round-off is that of the dot products, about 1e-16 of the
    coordinates (1e-14 m for a body of some 10 m).

    Parameters
    ----------
    a, d : tuple of 3 float
        Segment start and direction (end minus start), body frame (m).
    lo, hi : tuple of 3 float
        The box's corners, body frame (m).

    Returns
    -------
    float
        (m).

    References
    ----------
    Gottschalk, Lin & Manocha 1996, "OBBTree: a hierarchical structure for rapid interference detection", SIGGRAPH,
    Sec. 4 (the separating axis theorem for boxes; for a segment the axes are the box's faces and d x e_i).
    """
    best = -math.inf
    for i in range(3):
        low, high = min(a[i], a[i] + d[i]), max(a[i], a[i] + d[i])
        best = max(best, lo[i] - high, low - hi[i])
    r0, r1, r2 = a[0] - 0.5 * (lo[0] + hi[0]), a[1] - 0.5 * (lo[1] + hi[1]), a[2] - 0.5 * (lo[2] + hi[2])
    h0, h1, h2 = 0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]), 0.5 * (hi[2] - lo[2])
    # d x e_x = (0, d2, -d1), d x e_y = (-d2, 0, d0), d x e_z = (d1, -d0, 0)
    norm = math.sqrt(d[1] * d[1] + d[2] * d[2])
    if norm > 0.0:
        best = max(best, (abs(d[2] * r1 - d[1] * r2) - abs(d[2]) * h1 - abs(d[1]) * h2) / norm)
    norm = math.sqrt(d[0] * d[0] + d[2] * d[2])
    if norm > 0.0:
        best = max(best, (abs(d[0] * r2 - d[2] * r0) - abs(d[2]) * h0 - abs(d[0]) * h2) / norm)
    norm = math.sqrt(d[0] * d[0] + d[1] * d[1])
    if norm > 0.0:
        best = max(best, (abs(d[1] * r0 - d[0] * r1) - abs(d[1]) * h0 - abs(d[0]) * h1) / norm)
    return best


@njit(cache=True, **NO_REFCOUNTS)
def segment_box_deepest(a, d, lo, hi, work):
    """The segment's deepest point against a box: t* minimizing the signed distance, and that distance.

    Exact: between breakpoints (:func:`segment_box_breakpoints`) the signed distance is the norm of the
    positive excesses (a square root of a quadratic, minimized in closed form) or, inside the box, the
    largest excess (a maximum of lines, minimized at an end or where two lines cross); it is convex, so the
    least of the intervals' minima is the minimum.

    Parameters
    ----------
    a, d : tuple of 3 float
        Segment start and direction (end minus start), body frame (m).
    lo, hi : tuple of 3 float
        The box's corners, body frame (m).
    work : (MAX_BREAKPOINTS,) float
        Work space.

    Returns
    -------
    t_deepest : float
        (-).
    distance : float
        Signed distance there (m; negative inside).
    """
    return deepest_between_breakpoints(a, d, lo, hi, work, segment_box_breakpoints(a, d, lo, hi, work))


@njit(cache=True, **NO_REFCOUNTS)
def deepest_between_breakpoints(a, d, lo, hi, work, k):
    """:func:`segment_box_deepest` given the segment's ``k`` sorted breakpoints in ``work``
    (:func:`segment_box_breakpoints`), so that :func:`sublevel_between_breakpoints` can reuse them."""
    best_t, best = 0.0, math.inf
    for j in range(k - 1):
        t0, t1 = work[j], work[j + 1]
        if t1 <= t0:
            continue
        alpha, beta, outside = _pieces(a, d, lo, hi, 0.5 * (t0 + t1))
        if outside[0] or outside[1] or outside[2]:
            quad = linear = 0.0
            for i in range(3):
                if outside[i]:
                    quad += beta[i] * beta[i]
                    linear += alpha[i] * beta[i]
            t = min(max(-linear / quad, t0), t1) if quad > 0.0 else t0
            value = 0.0
            for i in range(3):
                if outside[i]:
                    value += (alpha[i] + beta[i] * t) ** 2
            value = math.sqrt(value)
        else:
            t, value = t0, _inside_distance(alpha, beta, t0)
            end = _inside_distance(alpha, beta, t1)
            if end < value:
                t, value = t1, end
            for i in range(3):
                for q in range(i + 1, 3):
                    if beta[i] != beta[q]:
                        cross = (alpha[q] - alpha[i]) / (beta[i] - beta[q])
                        if t0 < cross < t1:
                            at = _inside_distance(alpha, beta, cross)
                            if at < value:
                                t, value = cross, at
        if value < best:
            best_t, best = t, value
    return best_t, best


@njit(cache=True, **NO_REFCOUNTS)
def segment_box_sublevel(a, d, lo, hi, level, work):
    """The interval [t_low, t_high] of the segment whose signed distance to the box is at most ``level`` (m),
    exact per breakpoint interval (:func:`segment_box_deepest`); empty (t_low > t_high) if none.

    Parameters
    ----------
    a, d, lo, hi, work
        As :func:`segment_box_deepest`.
    level : float
        (m).

    Returns
    -------
    t_low, t_high : float
    """
    return sublevel_between_breakpoints(a, d, lo, hi, level, work, segment_box_breakpoints(a, d, lo, hi, work))


@njit(cache=True, **NO_REFCOUNTS)
def sublevel_between_breakpoints(a, d, lo, hi, level, work, k):
    """:func:`segment_box_sublevel` given the segment's ``k`` sorted breakpoints in ``work``
    (:func:`segment_box_breakpoints`): a thread's contact geometry
    (:func:`multibody.segment_cycle.thread_contact_geometry`) finds its deepest point and then its tie interval on
    the same breakpoints, sorted once (helper speed23: sorting them twice was some 1 % of a late capture's step)."""
    low, high = math.inf, -math.inf
    for j in range(k - 1):
        t0, t1 = work[j], work[j + 1]
        if t1 <= t0:
            continue
        alpha, beta, outside = _pieces(a, d, lo, hi, 0.5 * (t0 + t1))
        u0, u1 = t0, t1
        if outside[0] or outside[1] or outside[2]:
            if level <= 0.0:
                continue
            quad = linear = constant = 0.0
            for i in range(3):
                if outside[i]:
                    quad += beta[i] * beta[i]
                    linear += alpha[i] * beta[i]
                    constant += alpha[i] * alpha[i]
            constant -= level * level
            if quad > 0.0:
                disc = linear * linear - quad * constant
                if disc < 0.0:
                    continue
                root = math.sqrt(disc)
                u0, u1 = max(t0, (-linear - root) / quad), min(t1, (-linear + root) / quad)
            elif constant > 0.0:
                continue
        else:
            for i in range(3):
                if beta[i] > 0.0:
                    u1 = min(u1, (level - alpha[i]) / beta[i])
                elif beta[i] < 0.0:
                    u0 = max(u0, (level - alpha[i]) / beta[i])
                elif alpha[i] > level:
                    u1 = -math.inf
        if u0 <= u1:
            low, high = min(low, u0), max(high, u1)
    return low, high


@njit(cache=True, **WITH_REFCOUNTS)  # allocates (its lists); called from NO_REFCOUNTS kernels (jit_cache)
def segment_box_normal(px, py, pz, dx, dy, dz, lo, hi, wx, wy, wz):
    """Unit contact normal (body frame) from the box to a segment's deepest point p (direction d), and the
    slope of the segment's deepest penetration along it.

    Outside the box, from the nearest surface point (the segment's depth peaks there, so this is
    perpendicular to the segment). Inside, the faces nearest to p within :data:`TIE_DISTANCE` (an interior
    deepest point lies where two faces' depths cross): their combination perpendicular to the segment, which
    is the direction in which moving the segment sideways relieves it (a face's own normal, were it not
    perpendicular, would push the thread along itself, which relieves nothing). On a mid-plane of the box
    (a thread already through the middle of a thin plate) the geometry cannot tell the side: the face
    against the point's relative velocity w, so it is pushed back the way it came.

    The slope is the gradient of the deepest penetration with respect to the point's position, whose
    direction is the normal: 1 outside the box and against one face, but at an interior crossing of two
    faces the gradient is the convex combination itself, :math:`g = \lambda n_i + (1 - \lambda) n_k` with
    :math:`g \cdot d = 0` (Danskin's theorem for :math:`\min_t \max_i`), whose length
    :math:`\sqrt{\lambda^2 + (1 - \lambda)^2}` is below 1 (0.707 on a 45 degree edge). A contact force
    ``f_n`` times the unit normal there is not the gradient of the energy it books; ``f_n`` times the slope
    times the normal is (helper keyon19: the reference case's key-on energy gains at 3.22 s and 4.74 s,
    docs/model.md "The key-on contact's gain").

    Parameters
    ----------
    px, py, pz : float
        The deepest point, body frame (m).
    dx, dy, dz : float
        The segment's direction (end minus start), body frame (m).
    lo, hi : tuple of 3 float
        The box's corners, body frame (m).
    wx, wy, wz : float
        The point's velocity relative to the body, body frame (m/s).

    Returns
    -------
    nx, ny, nz : float
        The unit normal.
    slope : float
        The penetration's gradient length along it (-), in (0, 1].
    """
    p, d, w = (px, py, pz), (dx, dy, dz), (wx, wy, wz)
    ox = px - min(max(px, lo[0]), hi[0])
    oy = py - min(max(py, lo[1]), hi[1])
    oz = pz - min(max(pz, lo[2]), hi[2])
    norm = math.sqrt(ox * ox + oy * oy + oz * oz)
    if norm > 0.0:
        return ox / norm, oy / norm, oz / norm, 1.0
    deepest = -math.inf
    for i in range(3):
        deepest = max(deepest, lo[i] - p[i], p[i] - hi[i])
    n = [0.0, 0.0, 0.0]
    rate = [0.0, 0.0, 0.0]   # each active face's depth change along the segment, sigma_i d_i
    active = [False, False, False]
    for i in range(3):
        offset = p[i] - 0.5 * (lo[i] + hi[i])
        if max(lo[i] - p[i], p[i] - hi[i]) < deepest - TIE_DISTANCE:
            continue
        if abs(offset) <= 1e-9 * (hi[i] - lo[i]):
            sign = -1.0 if w[i] > 0.0 else 1.0
            out = [0.0, 0.0, 0.0]
            out[i] = sign
            return out[0], out[1], out[2], 1.0
        active[i] = True
        n[i] = 1.0 if offset > 0.0 else -1.0
        rate[i] = n[i] * d[i]
    # a convex combination with no component along the segment: two faces whose depths change oppositely along it
    for i in range(3):
        for k in range(i + 1, 3):
            if active[i] and active[k] and rate[i] * rate[k] < 0.0:
                share = rate[k] / (rate[k] - rate[i])
                out = [0.0, 0.0, 0.0]
                out[i], out[k] = share * n[i], (1.0 - share) * n[k]
                size = math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2)
                return out[0] / size, out[1] / size, out[2] / size, size
    # one face (or faces whose depths do not cross): the one the segment runs along most nearly
    best, axis = math.inf, 0
    for i in range(3):
        if active[i] and abs(rate[i]) < best:
            best, axis = abs(rate[i]), i
    out = [0.0, 0.0, 0.0]
    out[axis] = n[axis]
    return out[0], out[1], out[2], 1.0
