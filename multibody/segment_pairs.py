"""Which net threads may touch which box shapes within a step: the contact-pair search of the thread (segment)
contact, :mod:`multibody.contact_segment`.

* **broad phase** (:func:`_near_shapes`): a speed bound for every node over the step, a bounding sphere and a
  surface-speed bound for every box; of the candidate pairs (:mod:`multibody.segment_candidates`: a list kept from
  step to step with a skin, a superset of the pairs the slab test below passes), a thread whose every point stays
  farther from a box's centre than the box's sphere plus what thread and surface can close within the step
  (``reach``) is skipped, then one that misses the box's slabs widened by ``reach``.
* **narrow phase** (:func:`_touches_within_step`): the thread's deepest point penetrates now or at the end of the
  step's free motion (:func:`_node_motion`: each node's velocity relative to the body and its non-contact
  acceleration, body frame), or exactly one of its nodes is in its own contact with the box.
* the pairs found (:func:`_contact_pairs`) go to ``SegmentBuffers.pair_thread`` / ``pair_shape``, with each
  node's count of threads in contact and the box they touch, for the clustering (:mod:`multibody.thread_cluster`).
* **tests skipped where their answer is proven no** (helper speed23): the test at the end of the free motion when
  the start's separating-axis bound less the nodes' displacement clears both radii (:func:`_apart_after_motion`), and
  a listed pair's whole step when the clearance it kept since the list's build does (:func:`_still_apart`); the
  distance from a segment to a box is 1-Lipschitz in its ends, so the pairs found are the same to the bit
  (``SegmentBuffers.candidate_scalar[2]`` = 0 tests every listed pair at both states, for A/B runs).

Frames: LVLH unless named; the shapes in their body frames (origin at the body's CoM). SI units.
"""
from __future__ import annotations

import math

from numba import njit

from multibody.jit_cache import NO_REFCOUNTS

from multibody.broad_phase import box_signed_distance
from multibody.segment_box import TIE_DISTANCE, segment_box_separation
from multibody.segment_cycle import thread_contact_geometry


@njit(cache=True, **NO_REFCOUNTS)
def _near_shapes(x, v, net_force_lvlh, net_mass, velocity_lag, seg, states, shapes, step):
    """Each node's speed bound over the step (``seg.node_speed``, m/s: L1 norms, an upper bound), and each box
    shape's bounding sphere (``seg.shape_work``: radius (m), surface speed bound (m/s), centre in LVLH (m), its body's
    speed (m/s) and spin (rad/s)), for the thread broad phase."""
    n = x.shape[1]
    speed = seg.node_speed
    lag = seg.lag_velocity_lvlh
    for i in range(n):
        speed[i] = (abs(v[0, i] + velocity_lag[0, i] + lag[0, i]) + abs(v[1, i] + velocity_lag[1, i] + lag[1, i])
                    + abs(v[2, i] + velocity_lag[2, i] + lag[2, i])
                    + step * (abs(net_force_lvlh[0, i]) + abs(net_force_lvlh[1, i]) + abs(net_force_lvlh[2, i]))
                    / net_mass[i])
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    box_min, box_max = shapes.box_min_body, shapes.box_max_body
    for s in range(shapes.body.shape[0]):
        if shapes.is_box[s] == 0:
            continue
        b = shapes.body[s]
        mx, my, mz = (0.5 * (box_min[s, 0] + box_max[s, 0]), 0.5 * (box_min[s, 1] + box_max[s, 1]),
                      0.5 * (box_min[s, 2] + box_max[s, 2]))
        seg.shape_work[2, s] = (com_lvlh[b, 0] + body_to_lvlh[b, 0, 0] * mx + body_to_lvlh[b, 0, 1] * my
                                + body_to_lvlh[b, 0, 2] * mz)
        seg.shape_work[3, s] = (com_lvlh[b, 1] + body_to_lvlh[b, 1, 0] * mx + body_to_lvlh[b, 1, 1] * my
                                + body_to_lvlh[b, 1, 2] * mz)
        seg.shape_work[4, s] = (com_lvlh[b, 2] + body_to_lvlh[b, 2, 0] * mx + body_to_lvlh[b, 2, 1] * my
                                + body_to_lvlh[b, 2, 2] * mz)
        seg.shape_work[0, s] = 0.5 * math.sqrt((box_max[s, 0] - box_min[s, 0]) ** 2
                                               + (box_max[s, 1] - box_min[s, 1]) ** 2
                                               + (box_max[s, 2] - box_min[s, 2]) ** 2)
        extent = math.sqrt(max(box_min[s, 0] ** 2 + box_min[s, 1] ** 2 + box_min[s, 2] ** 2,
                               box_max[s, 0] ** 2 + box_max[s, 1] ** 2 + box_max[s, 2] ** 2))
        speed_b = math.sqrt(velocity_lvlh[b, 0] ** 2 + velocity_lvlh[b, 1] ** 2 + velocity_lvlh[b, 2] ** 2)
        spin_b = math.sqrt(omega_lvlh[b, 0] ** 2 + omega_lvlh[b, 1] ** 2 + omega_lvlh[b, 2] ** 2)
        seg.shape_work[1, s] = speed_b + spin_b * extent
        seg.shape_work[5, s], seg.shape_work[6, s] = speed_b, spin_b


@njit(cache=True, inline="always")
def _centre_distance(x, i, shape_work, s):
    """Node ``i``'s distance (m) to box ``s``'s bounding-sphere centre (``shape_work[2:5, s]``, LVLH)."""
    return math.sqrt((x[0, i] - shape_work[2, s]) ** 2 + (x[1, i] - shape_work[3, s]) ** 2
                     + (x[2, i] - shape_work[4, s]) ** 2)


@njit(cache=True, inline="always")
def _to_body(x, i, body_to_lvlh, com_lvlh, b):
    """Node ``i`` of the coordinate-major LVLH positions ``x`` in body ``b``'s frame (m), as a tuple."""
    ax, ay, az = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
    return (body_to_lvlh[b, 0, 0] * ax + body_to_lvlh[b, 1, 0] * ay + body_to_lvlh[b, 2, 0] * az,
            body_to_lvlh[b, 0, 1] * ax + body_to_lvlh[b, 1, 1] * ay + body_to_lvlh[b, 2, 1] * az,
            body_to_lvlh[b, 0, 2] * ax + body_to_lvlh[b, 1, 2] * ay + body_to_lvlh[b, 2, 2] * az)


@njit(cache=True, inline="always")
def _node_motion(i, b, x, v, net_force_lvlh, net_mass, node_lag, lag, states, half_kick):
    """Node ``i``'s start velocity relative to body ``b``'s material point at it (as the node contact's, m/s) and its
    non-contact acceleration (m/s^2), both in the body frame, as two tuples."""
    rot, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    ux = v[0, i] + node_lag[0, i] + lag[0, i] + half_kick * net_force_lvlh[0, i] / net_mass[i]
    uy = v[1, i] + node_lag[1, i] + lag[1, i] + half_kick * net_force_lvlh[1, i] / net_mass[i]
    uz = v[2, i] + node_lag[2, i] + lag[2, i] + half_kick * net_force_lvlh[2, i] / net_mass[i]
    rx, ry, rz = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
    wx = ux - velocity_lvlh[b, 0] - (omega_lvlh[b, 1] * rz - omega_lvlh[b, 2] * ry)
    wy = uy - velocity_lvlh[b, 1] - (omega_lvlh[b, 2] * rx - omega_lvlh[b, 0] * rz)
    wz = uz - velocity_lvlh[b, 2] - (omega_lvlh[b, 0] * ry - omega_lvlh[b, 1] * rx)
    fx, fy = net_force_lvlh[0, i] / net_mass[i], net_force_lvlh[1, i] / net_mass[i]
    fz = net_force_lvlh[2, i] / net_mass[i]
    rel = (rot[b, 0, 0] * wx + rot[b, 1, 0] * wy + rot[b, 2, 0] * wz,
           rot[b, 0, 1] * wx + rot[b, 1, 1] * wy + rot[b, 2, 1] * wz,
           rot[b, 0, 2] * wx + rot[b, 1, 2] * wy + rot[b, 2, 2] * wz)
    acc = (rot[b, 0, 0] * fx + rot[b, 1, 0] * fy + rot[b, 2, 0] * fz,
           rot[b, 0, 1] * fx + rot[b, 1, 1] * fy + rot[b, 2, 1] * fz,
           rot[b, 0, 2] * fx + rot[b, 1, 2] * fy + rot[b, 2, 2] * fz)
    return rel, acc


@njit(cache=True, **NO_REFCOUNTS)
def _contact_pairs(x, v, net_force_lvlh, net, states, shapes, step, n_substeps, buffers):
    """This step's (thread, box) contact pairs into ``seg.pair_thread`` / ``seg.pair_shape``, from the candidate pairs
    ``seg.candidate_thread[:k]`` / ``candidate_shape[:k]`` (k = ``seg.candidate_count[0]``, in (thread, box) order: a
    superset of those the slab test passes, :mod:`multibody.segment_candidates`): the thread's deepest point is interior
    and penetrates now, or does at the end of the step's free motion (a thread turning over an edge). Counts each
    node's threads in contact (``seg.node_threads``) and notes the box they touch (``seg.node_shape``). Returns the
    number of pairs."""
    seg = buffers.segments
    threads, net_mass, radius = net.threads, net.mass, net.radius
    node_speed, shape_work = seg.node_speed, seg.shape_work
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    box_min, box_max, shape_body = shapes.box_min_body, shapes.box_max_body, shapes.body
    n_pairs = 0
    proofs = seg.candidate_scalar[2] != 0.0
    for k in range(seg.candidate_count[0]):
        j, s = seg.candidate_thread[k], seg.candidate_shape[k]
        a, c = threads[j, 0], threads[j, 1]
        if proofs and seg.candidate_clearance[k] > -math.inf:
            b = shape_body[s]
            if _still_apart(seg, k, a, c, b, s, _to_body(x, a, body_to_lvlh, com_lvlh, b),
                            _to_body(x, c, body_to_lvlh, com_lvlh, b), radius, step):
                seg.candidate_count[2] += 1
                continue
        length = math.sqrt((x[0, c] - x[0, a]) ** 2 + (x[1, c] - x[1, a]) ** 2 + (x[2, c] - x[2, a]) ** 2)
        motion = step * max(node_speed[a], node_speed[c])
        thread_radius = min(radius[a], radius[c])
        # what the thread and the surface can close within the step, plus the thread's radius
        reach = 1.001 * (thread_radius + motion + step * shape_work[1, s])
        # every point of the segment is at least (|a - o| + |b - o| - L) / 2 from the box's centre o
        if (0.5 * (_centre_distance(x, a, shape_work, s) + _centre_distance(x, c, shape_work, s) - length)
                > shape_work[0, s] + reach):
            continue
        b = shape_body[s]
        pa = _to_body(x, a, body_to_lvlh, com_lvlh, b)
        pc = _to_body(x, c, body_to_lvlh, com_lvlh, b)
        if (min(pa[0], pc[0]) > box_max[s, 0] + reach or max(pa[0], pc[0]) < box_min[s, 0] - reach
                or min(pa[1], pc[1]) > box_max[s, 1] + reach or max(pa[1], pc[1]) < box_min[s, 1] - reach
                or min(pa[2], pc[2]) > box_max[s, 2] + reach or max(pa[2], pc[2]) < box_min[s, 2] - reach):
            continue
        touches, separation = _touches_within_step(a, c, s, b, pa, pc, x, v, net_force_lvlh, net_mass, radius,
                                                   states, shapes, step, n_substeps, buffers)
        if not touches:
            if separation > -math.inf:
                moved = math.sqrt(max(_moved_since_build(seg, b, a, pa), _moved_since_build(seg, b, c, pc)))
                seg.candidate_clearance[k] = max(seg.candidate_clearance[k], separation - moved)
            continue
        seg.pair_thread[n_pairs] = j
        seg.pair_shape[n_pairs] = s
        n_pairs += 1
        for i in (a, c):
            seg.node_threads[i] += 1
            if seg.node_shape[i] == -1:
                seg.node_shape[i] = s
            elif seg.node_shape[i] != s:
                seg.node_shape[i] = -2
    return n_pairs


@njit(cache=True, **NO_REFCOUNTS)
def _touches_within_step(a, c, s, b, pa, pc, x, v, net_force_lvlh, net_mass, radius, states, shapes, step, n_substeps,
                         buffers):
    """Whether thread (a, c)'s contact with box ``s`` can act within the step, and the separating-axis bound (m) of its
    distance to the box at the start when that bound decided no (else -inf): it penetrates now, or at the end of
    the step's free motion (a thread turning over an edge, whose deepest point is not yet interior at the start), or
    exactly one of its nodes is in its own contact with the box now or then.

    The last: a thread with one node striking a face and the other beyond the face's edge lies flat at first (its
    deepest point ties with the node: no excess), then turns over the edge within the node's own 0.15 ms impact,
    which the free motion does not foresee (the node's rebound raises the edge point's excess over it). Found late,
    such a thread started the next step up to about a millimetre into its contact, energy no force paid for:
    measured, 24 such arrivals made +2.87 % of the reference case's energy at its ASAR strike (0.049 s; helper
    thread13, bench/thread_contact_drift.py, the record's "arrivals (a node in its own contact)").

    The test at the end of the free motion is skipped when the separating-axis bound at the start keeps the thread
    so far from the box that the motion cannot bring it into reach (:func:`_apart_after_motion`): its answer is then
    known to be "no", so the pairs found are the same to the bit (helper speed23: late in a whole capture some 100
    listed pairs a step are apart, each tested at both states before)."""
    seg = buffers.segments
    box_min, box_max = shapes.box_min_body, shapes.box_max_body
    acts, separation = _contact_test(pa, pc, box_min, box_max, s, radius[a], radius[c], seg.breakpoints)
    if acts:
        return True, -math.inf
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    rel_a, acc_a = _node_motion(a, b, x, v, net_force_lvlh, net_mass, buffers.velocity_lag, seg.lag_velocity_lvlh,
                                states, half_kick)
    rel_c, acc_c = _node_motion(c, b, x, v, net_force_lvlh, net_mass, buffers.velocity_lag, seg.lag_velocity_lvlh,
                                states, half_kick)
    h2 = 0.5 * step * step
    move_a = (step * rel_a[0] + h2 * acc_a[0], step * rel_a[1] + h2 * acc_a[1], step * rel_a[2] + h2 * acc_a[2])
    move_c = (step * rel_c[0] + h2 * acc_c[0], step * rel_c[1] + h2 * acc_c[1], step * rel_c[2] + h2 * acc_c[2])
    if seg.candidate_scalar[2] != 0.0 and _apart_after_motion(separation, move_a, move_c, radius[a], radius[c]):
        seg.candidate_count[3] += 1
        return False, separation
    # not pa + move_a: (pa + h v) + h^2 a / 2 is the sum the pairs were always tested at (bit-identical answers)
    qa = (pa[0] + step * rel_a[0] + h2 * acc_a[0], pa[1] + step * rel_a[1] + h2 * acc_a[1],
          pa[2] + step * rel_a[2] + h2 * acc_a[2])
    qc = (pc[0] + step * rel_c[0] + h2 * acc_c[0], pc[1] + step * rel_c[1] + h2 * acc_c[1],
          pc[2] + step * rel_c[2] + h2 * acc_c[2])
    if _contact_can_act(qa, qc, box_min, box_max, s, radius[a], radius[c], seg.breakpoints):
        return True, -math.inf
    return False, separation


@njit(cache=True, inline="always")
def _moved_since_build(seg, b, i, p):
    """Node ``i``'s squared displacement (m^2) in body ``b``'s frame since the candidate list's build, from its position
    ``p`` there now (m; ``seg.built_position_body``)."""
    built = seg.built_position_body
    return (p[0] - built[b, 0, i]) ** 2 + (p[1] - built[b, 1, i]) ** 2 + (p[2] - built[b, 2, i]) ** 2


@njit(cache=True, inline="always")
def _still_apart(seg, k, a, c, b, s, pa, pc, radius, step):
    """Whether candidate pair ``k`` (thread (a, c), box ``s`` on body ``b``, its nodes at ``pa``, ``pc`` in the body's
    frame, m) is proven apart for this whole step by its clearance C (``seg.candidate_clearance[k]``, m), so that its
    tests in :func:`_contact_pairs` would all say no.

    C was set at an earlier step of this build, C = S - max(|p_a - p^0_a|, |p_c - p^0_c|), from the separating-axis
    bound S <= D of the thread's distance to the box then (:func:`_contact_test`) and its nodes' displacements since
    the build in the body's frame (p^0: ``seg.built_position_body``). Now, with D 1-Lipschitz in the ends
    (:func:`_apart_after_motion`) and |p - p_then| <= |p - p^0| + |p_then - p^0| for each node,

    .. math:: D_{now} \\ge C - \\max(|p_a - p^0_a|, |p_c - p^0_c|)

    (:func:`_moved_since_build`), and over the step's free motion each node moves in the body frame by at most
    h (u_i + v_b + w_b |r_i|) (u_i its speed bound ``seg.node_speed``, which holds the half kick and the held force's
    h^2 |f| / m; v_b, w_b the body's speed and spin, ``seg.shape_work`` rows 5, 6; |r_i| its distance from the body's
    CoM, |p_i|). When D_now less that motion still exceeds both radii by the tie distance, the test
    at the start and the one at the end of the free motion both answer no (as in :func:`_apart_after_motion`)."""
    lever = math.sqrt(max(pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2], pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2]))
    motion = step * (max(seg.node_speed[a], seg.node_speed[c]) + seg.shape_work[5, s] + seg.shape_work[6, s] * lever)
    moved = math.sqrt(max(_moved_since_build(seg, b, a, pa), _moved_since_build(seg, b, c, pc)))
    return seg.candidate_clearance[k] - moved - motion > max(radius[a], radius[c]) + TIE_DISTANCE


@njit(cache=True, inline="always")
def _apart_after_motion(separation, move_a, move_c, radius_a, radius_c):
    """Whether a thread whose separating-axis bound to a box is ``separation`` (m) cannot act on it after its nodes
    have moved by ``move_a``, ``move_c`` (m, the box's body frame): :func:`_contact_can_act` at the moved nodes is then
    sure to answer no.

    The distance D from a segment to a convex set is 1-Lipschitz in its two ends together: the moved segment's point
    at parameter t is the old one's plus (1 - t) m_a + t m_c, at most max(|m_a|, |m_c|) away, and a point's distance to
    the set changes by at most its own displacement. With the bound S <= D at the start
    (:func:`multibody.segment_box.segment_box_separation`),

    .. math:: D' \ge S - \max(|m_a|, |m_c|) > \max(r_a, r_c) + \epsilon

    makes every point of the moved thread, its two nodes too, farther from the box than either node's radius: both
    nodes' own depths are negative (no node contact on one side only) and the thread's deepest depth r - D' too (no
    excess), so the geometry answers no. The tie distance epsilon (1e-9 m) covers the round-off of S, of the moved
    positions and of the test's own distances (some 1e-14 m for coordinates of 10 m). Squares, no root: S - r - eps
    must be positive and its square above both displacements' squares. ``separation`` is -inf when the bound did not
    decide the start (never apart)."""
    clearance = separation - max(radius_a, radius_c) - TIE_DISTANCE
    if not clearance > 0.0:
        return False
    limit = clearance * clearance
    return (move_a[0] * move_a[0] + move_a[1] * move_a[1] + move_a[2] * move_a[2] < limit
            and move_c[0] * move_c[0] + move_c[1] * move_c[1] + move_c[2] * move_c[2] < limit)


@njit(cache=True, **NO_REFCOUNTS)
def _contact_can_act(pa, pc, box_min, box_max, s, radius_a, radius_c, work):
    """Whether thread (``pa``, ``pc``: its nodes, body frame, m) acts on box ``s`` at these positions: its deepest point
    is interior and penetrates (:func:`multibody.segment_cycle.thread_contact_geometry`'s excess > 0), or exactly one
    of its nodes is in its own contact with the box: :func:`_contact_test`'s answer."""
    return _contact_test(pa, pc, box_min, box_max, s, radius_a, radius_c, work)[0]


@njit(cache=True, **NO_REFCOUNTS)
def _contact_test(pa, pc, box_min, box_max, s, radius_a, radius_c, work):
    """Whether thread (``pa``, ``pc``: its nodes, body frame, m) acts on box ``s`` at these positions, and the
    separating-axis bound (m) when that bound decided no (else -inf): the answer of ``thread_contact_geometry``, which
    it calls unless cheaper tests decide it. A node contact on one side only says yes (the same distances and test as
    the geometry's); a segment whose separating-axis bound (:func:`multibody.segment_box.segment_box_separation`) keeps
    it farther from the box than the thread's radius (by the tie distance, far above the bound's round-off of about
    1e-14 m) says no: then the geometry's depth is negative, so its excess is not positive. A wrapped net's candidates
    past the slab test are mostly threads across a plate's edge or a box's corner region that do not touch it, decided
    so (helper speed20: 35-38 a step of the 2.0 m/s capture, each two geometry calls before)."""
    gap_a = box_signed_distance(pa[0], pa[1], pa[2], box_min, box_max, s)[0]
    gap_c = box_signed_distance(pc[0], pc[1], pc[2], box_min, box_max, s)[0]
    if (radius_a - gap_a > 0.0) != (radius_c - gap_c > 0.0):
        return True, -math.inf
    lo = (box_min[s, 0], box_min[s, 1], box_min[s, 2])
    hi = (box_max[s, 0], box_max[s, 1], box_max[s, 2])
    d = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    separation = segment_box_separation(pa, d, lo, hi)
    if separation > min(radius_a, radius_c) + TIE_DISTANCE:
        return False, separation
    geometry = thread_contact_geometry(pa, pc, box_min, box_max, s, radius_a, radius_c, work)
    return geometry[0] > 0.0 or (geometry[5] > 0.0) != (geometry[6] > 0.0), -math.inf
