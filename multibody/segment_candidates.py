"""The thread contact's candidate (thread, box) pairs, kept from step to step with a skin (a Verlet list): the broad
phase of :mod:`multibody.segment_pairs` tests only the listed pairs, with its tests unchanged.

A pair is listed when its thread's two nodes, in the box's body frame, are not both beyond one face's plane by more
than the pair's ``reach`` (what thread and surface can close within the step, plus the thread's radius:
:func:`multibody.segment_pairs._contact_pairs`) plus the skin ``d`` (m), the slab test with the reach grown by ``d``.
The list is rebuilt when it may have lost a pair that the slab test would now pass, that is unless

.. math::

    \\max_{b, i} |p_{bi} - p^0_{bi}| + 1.001\\,h\\,\\big(\\max_i (u_i - u^0_i)^+ + \\max_s (w_s - w^0_s)^+\\big)
    \\le d - \\epsilon,

with :math:`p_{bi}` node i's position in the frame of body b (one carrying a box), :math:`u_i` its speed bound and
:math:`w_s` box s's surface speed bound (m/s), the superscript 0 their values at the last build, h the step (s;
a build at another step is rebuilt) and :math:`\\epsilon` the tie distance (1e-9 m, far above the positions' round-off
of about 1e-14 m for 10-m coordinates). Why it suffices: a pair left out failed the grown slab test on some axis k,
both nodes beyond, say, ``hi_k + reach0 + d``; each node has moved by at most the first term along k, and the pair's
reach has grown by at most the second (its reach is 1.001 (r + h max(u_a, u_c) + h w_s)), so both nodes are still
beyond ``hi_k + reach`` and the slab test of :mod:`multibody.segment_pairs` skips the pair now too. The listed pairs
go through the same tests in the same (thread, box) order as the full scan (a pair whose clearance proves it apart
skips them, :func:`multibody.segment_pairs._still_apart`: their answer is known), so the pairs found, and every
force, are the full scan's to the last bit; a skin of 0 rebuilds at every evaluation (the full scan's slab test).

Frames: LVLH unless named; the shapes in their body frames (origin at the body's CoM). SI units.
"""
from __future__ import annotations

import math

from numba import njit

from multibody.jit_cache import NO_REFCOUNTS
from multibody.segment_box import TIE_DISTANCE
from multibody.segment_pairs import _to_body

#: The skin (m): pairs within it of their slab test are listed. 1 cm: a wrapped net's threads lie within a few
#: centimetres of the faces (helper speed20's census: 296-531 of 1272 pairs within the bounding spheres, 38-55 within
#: the slabs), and a node at 2 m/s crosses half of it in 25 steps of 1e-4 s; helper speed21 measured 0.5, 1 and 2 cm
#: (docs/model.md, "Speed"). The skin changes the cost only, never a result.
CANDIDATE_SKIN = 0.01


@njit(cache=True, **NO_REFCOUNTS)
def _speed_growth(seg, is_box, step):
    """Bound (m) of how much any pair's reach has grown since the last build: 1.001 h times the largest rise of a
    node's speed bound plus the largest rise of a box's surface speed bound (module doc)."""
    rise_node = 0.0
    for i in range(seg.node_speed.shape[0]):
        rise_node = max(rise_node, seg.node_speed[i] - seg.built_speed[i])
    rise_shape = 0.0
    for s in range(is_box.shape[0]):
        if is_box[s] != 0:
            rise_shape = max(rise_shape, seg.shape_work[1, s] - seg.built_surface_speed[s])
    return 1.001 * step * (rise_node + rise_shape)


@njit(cache=True, **NO_REFCOUNTS)
def _carries_box(b, shapes):
    """Whether body ``b`` carries a box shape."""
    for s in range(shapes.body.shape[0]):
        if shapes.is_box[s] != 0 and shapes.body[s] == b:
            return True
    return False


@njit(cache=True, **NO_REFCOUNTS)
def _candidates_hold(x, seg, states, shapes, step):
    """Whether the listed pairs still hold every pair the slab test can pass (module doc's inequality)."""
    skin, built_step = seg.candidate_scalar[0], seg.candidate_scalar[1]
    if built_step != step:
        return False
    limit = skin - _speed_growth(seg, shapes.is_box, step) - TIE_DISTANCE
    if limit <= 0.0:
        return False
    limit2 = limit * limit
    body_to_lvlh, com_lvlh, built = states.body_to_lvlh, states.com_lvlh, seg.built_position_body
    for b in range(body_to_lvlh.shape[0]):
        if not _carries_box(b, shapes):
            continue
        moved = 0   # an integer or-reduction: the loop vectorizes
        for i in range(x.shape[1]):
            p = _to_body(x, i, body_to_lvlh, com_lvlh, b)
            d2 = (p[0] - built[b, 0, i]) ** 2 + (p[1] - built[b, 1, i]) ** 2 + (p[2] - built[b, 2, i]) ** 2
            moved |= d2 > limit2
        if moved:
            return False
    return True


@njit(cache=True, **NO_REFCOUNTS)
def _build_candidates(x, threads, radius, seg, states, shapes, step):
    """List the (thread, box) pairs whose nodes pass the slab test grown by the skin (module doc), thread after
    thread, box after box, into ``seg.candidate_thread`` / ``candidate_shape``; note the build's body-frame positions,
    speed bounds and step."""
    skin = seg.candidate_scalar[0]
    node_speed, surface_speed = seg.node_speed, seg.shape_work[1]
    body_to_lvlh, com_lvlh, built = states.body_to_lvlh, states.com_lvlh, seg.built_position_body
    box_min, box_max, shape_body, is_box = shapes.box_min_body, shapes.box_max_body, shapes.body, shapes.is_box
    for b in range(body_to_lvlh.shape[0]):
        if not _carries_box(b, shapes):
            continue
        for i in range(x.shape[1]):
            p = _to_body(x, i, body_to_lvlh, com_lvlh, b)
            built[b, 0, i], built[b, 1, i], built[b, 2, i] = p[0], p[1], p[2]
    for i in range(node_speed.shape[0]):
        seg.built_speed[i] = node_speed[i]
    for s in range(is_box.shape[0]):
        seg.built_surface_speed[s] = surface_speed[s]
    seg.candidate_scalar[1] = step
    count = 0
    for j in range(threads.shape[0]):
        a, c = threads[j, 0], threads[j, 1]
        motion = step * max(node_speed[a], node_speed[c])
        thread_radius = min(radius[a], radius[c])
        for s in range(shape_body.shape[0]):
            if is_box[s] == 0:
                continue
            grown = 1.001 * (thread_radius + motion + step * surface_speed[s]) + skin
            b = shape_body[s]
            if (min(built[b, 0, a], built[b, 0, c]) > box_max[s, 0] + grown
                    or max(built[b, 0, a], built[b, 0, c]) < box_min[s, 0] - grown
                    or min(built[b, 1, a], built[b, 1, c]) > box_max[s, 1] + grown
                    or max(built[b, 1, a], built[b, 1, c]) < box_min[s, 1] - grown
                    or min(built[b, 2, a], built[b, 2, c]) > box_max[s, 2] + grown
                    or max(built[b, 2, a], built[b, 2, c]) < box_min[s, 2] - grown):
                continue
            seg.candidate_thread[count] = j
            seg.candidate_shape[count] = s
            seg.candidate_clearance[count] = -math.inf     # none proven yet (multibody.segment_pairs)
            count += 1
    seg.candidate_count[0] = count
    seg.candidate_count[1] += 1


@njit(cache=True, **NO_REFCOUNTS)
def refresh_candidates(x, threads, radius, seg, states, shapes, step):
    """Rebuild the candidate pairs unless they still hold (module doc); returns how many are listed.

    Parameters
    ----------
    x : (3, n) float
        Node positions, LVLH (m), coordinate-major.
    threads : (m, 2) int
        Each thread's two nodes.
    radius : (n,) float
        Node contact radii (m).
    seg : SegmentBuffers
        Reads ``node_speed`` and ``shape_work`` (this evaluation's speed bounds,
        :func:`multibody.segment_pairs._near_shapes`); writes the candidate fields.
    states, shapes : BodyStates, ShapeArrays
    step : float
        Integrator step (s).
    """
    if not _candidates_hold(x, seg, states, shapes, step):
        _build_candidates(x, threads, radius, seg, states, shapes, step)
    return seg.candidate_count[0]
