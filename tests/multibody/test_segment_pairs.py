"""The thread contact's narrow phase (multibody/segment_pairs.py): its shortcut gives the full geometry's answer."""
from __future__ import annotations

import numpy as np
import pytest

from multibody.broad_phase import box_signed_distance
from multibody.segment_box import MAX_BREAKPOINTS, segment_box_separation
from multibody.segment_cycle import thread_contact_geometry
from multibody.segment_pairs import _contact_can_act

# a plate like Envisat's ASAR and a block like its main body (m, body frame)
BOX_MIN = np.array([[-0.75, -0.078, -5.0], [-1.6875, -1.875, -3.9375]])
BOX_MAX = np.array([[0.75, 0.078, 5.0], [1.6875, 1.875, 3.9375]])
NODE_RADIUS = 1e-3       # m, the net's node contact radius (thread diameter / 2)
BULLET_RADIUS = 0.01     # m


def geometry_answer(pa, pc, s, radius_a, radius_c) -> bool:
    """The narrow phase's test as it was written before the shortcut (the full geometry)."""
    g = thread_contact_geometry(pa, pc, BOX_MIN, BOX_MAX, s, radius_a, radius_c, np.zeros(MAX_BREAKPOINTS))
    return bool(g[0] > 0.0 or (g[5] > 0.0) != (g[6] > 0.0))


def on_face(rng, s, n):
    """``n`` threads lying on a random face of box ``s``: ends within +-1.5 radii of resting (about a radius out),
    a mesh-sized run along the face, some ends past its edges (over the edge, the interior can be deepest)."""
    lo, hi = BOX_MIN[s], BOX_MAX[s]
    out = []
    for _ in range(n):
        axis, side = rng.integers(3), rng.choice([-1.0, 1.0])
        level = hi[axis] if side > 0 else lo[axis]
        ends = []
        start = rng.uniform(lo - 0.3, hi + 0.3)
        direction = rng.normal(size=3)
        direction[axis] = 0.0
        direction *= rng.uniform(0.5, 2.5) / np.linalg.norm(direction)
        for point in (start, start + direction):
            p = point.copy()
            p[axis] = level + side * NODE_RADIUS * rng.uniform(-0.5, 2.5) + rng.normal() * 1e-7
            ends.append(tuple(p))
        out.append(ends)
    return out


def near_box(rng, s, n):
    """``n`` threads with both ends within 0.1 m of box ``s``'s surface region, any direction (edges, corners)."""
    lo, hi = BOX_MIN[s], BOX_MAX[s]
    return [[tuple(rng.uniform(lo - 0.1, hi + 0.1)), tuple(rng.uniform(lo - 0.1, hi + 0.1))] for _ in range(n)]


def across_edges(rng, s, n):
    """``n`` threads across box ``s``'s edges and corners: ends beyond two different faces, a few millimetres to a few
    centimetres out, so that some pass the edge just clear of it and some cut into it."""
    lo, hi = BOX_MIN[s], BOX_MAX[s]
    out = []
    for _ in range(n):
        ends = []
        for _ in range(2):
            p = rng.uniform(lo, hi)
            axis = rng.integers(3)
            p[axis] = (hi[axis] if rng.random() < 0.5 else lo[axis]) + rng.choice([-1.0, 1.0]) * rng.uniform(0.0, 0.05)
            ends.append(tuple(p))
        out.append(ends)
    return out


@pytest.mark.parametrize("seed", range(4))
def test_contact_can_act_gives_the_full_geometry_answer(seed):
    """Threads lying on faces (ends resting about a radius out), across edges and corners, and anywhere near the
    two boxes, with node and bullet radii: the shortcut's answer is the full geometry's in every case (a boolean: no
    tolerance), and the separating-axis bound decides most of those that do not touch (else it saves nothing)."""
    rng = np.random.default_rng(seed)
    apart = untouched = 0
    for s in range(2):
        for kind, threads in (("face", on_face(rng, s, 300)), ("edge", across_edges(rng, s, 300)),
                              ("near", near_box(rng, s, 300))):
            for pa, pc in threads:
                for radius_a, radius_c in ((NODE_RADIUS, NODE_RADIUS), (BULLET_RADIUS, NODE_RADIUS)):
                    full = geometry_answer(pa, pc, s, radius_a, radius_c)
                    fast = _contact_can_act(pa, pc, BOX_MIN, BOX_MAX, s, radius_a, radius_c, np.zeros(MAX_BREAKPOINTS))
                    assert fast == full, (kind, s, pa, pc, radius_a)
                    if not full:
                        untouched += 1
                        apart += segment_box_separation(pa, tuple(np.subtract(pc, pa)), tuple(BOX_MIN[s]),
                                                        tuple(BOX_MAX[s])) > min(radius_a, radius_c) + 1e-9
    assert apart > 0.5 * untouched


@pytest.mark.parametrize("seed", range(4))
def test_separation_is_a_lower_bound_of_the_distance(seed):
    """The separating-axis bound never exceeds the segment's distance to the box sampled at 2001 points (a sampled
    distance is at least the true one, so bound <= sampled up to round-off, 1e-12 m), and it is the distance itself
    for a segment crossing above an edge at right angles (the closest points on the edge and the segment's interior:
    the axis d x e_i is their common normal), to round-off."""
    rng = np.random.default_rng(seed)
    s = 1
    lo, hi = tuple(BOX_MIN[s]), tuple(BOX_MAX[s])
    for pa, pc in across_edges(rng, s, 200) + near_box(rng, s, 200):
        d = np.subtract(pc, pa)
        sampled = min(box_signed_distance(*(np.asarray(pa) + t * d), BOX_MIN, BOX_MAX, s)[0]
                      for t in np.linspace(0.0, 1.0, 2001))
        assert segment_box_separation(pa, tuple(d), lo, hi) <= max(sampled, 0.0) + 1e-12
    # over the edge x = hi, y = hi (along z), 3 cm clear along the diagonal, the segment along (1, -1, 0)
    gap = 0.03
    corner = np.array([hi[0], hi[1], 0.0]) + gap / np.sqrt(2.0) * np.array([1.0, 1.0, 0.0])
    pa, pc = corner - 0.4 * np.array([1.0, -1.0, 0.0]), corner + 0.4 * np.array([1.0, -1.0, 0.0])
    assert segment_box_separation(tuple(pa), tuple(pc - pa), lo, hi) == pytest.approx(gap, abs=1e-12)
