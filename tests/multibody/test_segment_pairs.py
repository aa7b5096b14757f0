"""The thread contact's narrow phase (multibody/segment_pairs.py): its shortcut gives the full geometry's answer."""
from __future__ import annotations

import numpy as np
import pytest

from multibody.broad_phase import box_signed_distance
from multibody.segment_box import MAX_BREAKPOINTS, segment_box_separation
from multibody.segment_cycle import thread_contact_geometry
from multibody.contact_segment import segment_buffers
from multibody.kernel import BodyStates, ShapeArrays
from multibody.segment_pairs import _apart_after_motion, _contact_can_act, _contact_test, _near_shapes, _node_motion
from tests.multibody.test_segment_candidates import _rotation

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


def box_distance(points, lo, hi):
    """(k,) Euclidean distance (m) of (k, 3) points to the box [lo, hi] (0 inside)."""
    excess = np.maximum(lo - points, 0.0) + np.maximum(points - hi, 0.0)
    return np.linalg.norm(excess, axis=1)


def segment_closest_brute(pa, pc, lo, hi, iterations=90):
    """(k,) distance (m) of the segments (pa, pc), each (k, 3), to the box, and (k,) the parameter t of the segment's
    closest point: a ternary search over t of the distance of pa + t (pc - pa) (convex in t: the distance to a convex
    set along a line), to (2/3)^90 ~ 1e-16 of the parameter, independent of multibody.segment_box's closed forms."""
    low, high = np.zeros(len(pa)), np.ones(len(pa))
    d = pc - pa
    for _ in range(iterations):
        t1, t2 = low + (high - low) / 3.0, high - (high - low) / 3.0
        f1 = box_distance(pa + t1[:, None] * d, lo, hi)
        f2 = box_distance(pa + t2[:, None] * d, lo, hi)
        left = f1 < f2
        high = np.where(left, t2, high)
        low = np.where(left, low, t1)
    t = 0.5 * (low + high)
    return box_distance(pa + t[:, None] * d, lo, hi), t


def moved_threads(rng, s, n):
    """``n`` threads near box ``s`` (over faces, across edges and corners, anywhere near) and a displacement of each
    node (m): half random, |m| log-uniform over 1e-7-3e-2 m (a step's 1e-5 m to a strike's centimetres), half the
    tightest case, both nodes moved by the same vector straight towards the box along the segment's closest approach
    (the distance then falls by |m| exactly), of up to 1.2 times the gap."""
    lo, hi = BOX_MIN[s], BOX_MAX[s]
    ends = on_face(rng, s, n // 3) + across_edges(rng, s, n // 3) + near_box(rng, s, n - 2 * (n // 3))
    pa, pc = np.array([e[0] for e in ends]), np.array([e[1] for e in ends])
    size = 10.0 ** rng.uniform(-7.0, np.log10(3e-2), size=(n, 2))
    direction = rng.normal(size=(n, 2, 3))
    move = direction / np.linalg.norm(direction, axis=2, keepdims=True) * size[:, :, None]
    # the tight half: the segment's closest point and its nearest point of the box give the direction
    closest = pa + segment_closest_brute(pa, pc, lo, hi)[1][:, None] * (pc - pa)
    towards = np.clip(closest, lo, hi) - closest
    gap = np.linalg.norm(towards, axis=1)
    tight = (rng.random(n) < 0.5) & (gap > 0.0)
    step = (towards[tight] / gap[tight, None]) * (gap[tight] * rng.uniform(0.0, 1.2, tight.sum()))[:, None]
    move[tight, 0], move[tight, 1] = step, step
    return pa, pc, move


@pytest.mark.parametrize("seed", range(4))
def test_distance_after_motion_is_at_least_the_bound_less_the_largest_displacement(seed):
    """The separating-axis bound S of a segment, less the larger of its ends' displacements, is a lower bound of the
    moved segment's distance to the box (the 1-Lipschitz argument of segment_pairs._apart_after_motion): 25 000 draws a
    seed over the two boxes (10^5 over the four seeds), never violated beyond round-off (1e-12 m; the brute force's
    own error is some 1e-16 m). Half the draws are the tight case (moved straight towards the box), where the
    inequality holds with equality when S is the distance (a thread square across an edge): so the bound cannot be
    made tighter, and the check is not vacuous (some draws come within 1e-9 m of it)."""
    rng = np.random.default_rng(seed)
    worst, close = -np.inf, 0
    for s in range(2):
        lo, hi = BOX_MIN[s], BOX_MAX[s]
        pa, pc, move = moved_threads(rng, s, 12500)
        separation = np.array([segment_box_separation(tuple(a), tuple(c - a), tuple(lo), tuple(hi))
                               for a, c in zip(pa, pc)])
        bound = separation - np.linalg.norm(move, axis=2).max(axis=1)
        after = segment_closest_brute(pa + move[:, 0], pc + move[:, 1], lo, hi)[0]
        apart = separation > 0.0
        worst = max(worst, np.max(bound[apart] - after[apart]))
        close += int(np.sum(np.abs(bound[apart] - after[apart]) < 1e-9))
    assert worst <= 1e-12
    assert close > 0


@pytest.mark.parametrize("seed", range(4))
def test_end_of_step_test_skipped_only_when_it_answers_no(seed):
    """Wherever segment_pairs._apart_after_motion skips the test at the moved nodes, that test (_contact_can_act, the
    full geometry's answer) says no: thread and node radii, bullet and node radii, 25 000 draws a seed (a boolean: no
    tolerance). The skip is not vacuous: it decides every draw whose start bound clears the larger radius by 0.2 mm
    with both displacements within 0.1 mm (ten steps' motion of a node at 1 m/s), as its inequality says."""
    rng = np.random.default_rng(seed)
    work = np.zeros(MAX_BREAKPOINTS)
    skipped = small_apart = small_skipped = 0
    for s in range(2):
        pa, pc, move = moved_threads(rng, s, 6250)
        for radius_a, radius_c in ((NODE_RADIUS, NODE_RADIUS), (BULLET_RADIUS, NODE_RADIUS)):
            for a, c, m in zip(pa, pc, move):
                acts, separation = _contact_test(tuple(a), tuple(c), BOX_MIN, BOX_MAX, s, radius_a, radius_c, work)
                skip = _apart_after_motion(separation, tuple(m[0]), tuple(m[1]), radius_a, radius_c)
                if skip:
                    assert not acts
                    assert not _contact_can_act(tuple(a + m[0]), tuple(c + m[1]), BOX_MIN, BOX_MAX, s, radius_a,
                                                radius_c, work), (s, a, c, m, radius_a)
                    skipped += 1
                if not acts and separation > max(radius_a, radius_c) + 2e-4 and np.linalg.norm(m, axis=1).max() <= 1e-4:
                    small_apart += 1
                    small_skipped += skip
    assert skipped > 0
    assert small_skipped == small_apart > 0


@pytest.mark.parametrize("seed", range(4))
def test_free_motion_in_a_body_frame_is_within_the_clearance_bound(seed):
    """segment_pairs._still_apart bounds a node's displacement over the step's free motion in a box's body frame,
    h rel + h^2 / 2 acc (_node_motion, as _touches_within_step moves it), by h (u_i + v_b + w_b |r_i|): u_i the node's
    speed bound (_near_shapes), v_b, w_b its body's speed and spin, |r_i| its distance from the body's CoM. 400 nodes
    against two bodies (speeds to 3 m/s, spins to 2 rad/s, pulls to 5e4 m/s^2, the carried velocities included), with
    the half kick (sub-cycled) and without: never exceeded (the triangle inequality and |x|_2 <= |x|_1: exact, up to
    round-off, 1e-12 relative), and not loose by more than a factor 2 + sqrt(3) for some draw (it is a useful bound)."""
    rng = np.random.default_rng(seed)
    n, nb, step = 400, 2, 1e-4
    shapes = ShapeArrays(triangles_body=np.zeros((0, 3, 3)), normals_body=np.zeros((0, 3)),
                         body=np.array([0, 1], np.int64), triangle_range=np.zeros((2, 2), np.int64),
                         box_min_body=BOX_MIN.copy(), box_max_body=BOX_MAX.copy(), is_box=np.ones(2, np.int64))
    seg = segment_buffers(1, n, 2, nb, True)
    x = rng.uniform(-8.0, 8.0, (3, n))
    v = rng.normal(size=(3, n)) * rng.uniform(0.0, 3.0, n)
    mass = rng.uniform(0.004, 0.05, n)
    force = rng.normal(size=(3, n)) * mass * 10.0 ** rng.uniform(-2.0, np.log10(5e4), n)
    node_lag, thread_lag = rng.normal(size=(3, n)) * 1e-2, rng.normal(size=(3, n)) * 1e-2
    attitude = np.stack([_rotation(rng.uniform(-np.pi, np.pi, 3)) for _ in range(nb)])
    omega = rng.normal(size=(nb, 3)) * 2.0 / np.sqrt(3.0)
    states = BodyStates(attitude, rng.uniform(-2.0, 2.0, (nb, 3)), rng.normal(size=(nb, 3)) * 3.0 / np.sqrt(3.0), omega,
                        attitude, np.einsum("bji,bj->bi", attitude, omega))
    seg.lag_velocity_lvlh[:] = thread_lag
    _near_shapes(x, v, force, mass, node_lag, seg, states, shapes, step)
    ratios = []
    for half_kick in (0.5 * step, 0.0):
        for s in range(2):
            b = shapes.body[s]
            for i in range(n):
                rel, acc = _node_motion(i, b, x, v, force, mass, node_lag, thread_lag, states, half_kick)
                move = np.linalg.norm(step * np.asarray(rel) + 0.5 * step * step * np.asarray(acc))
                lever = np.linalg.norm(x[:, i] - states.com_lvlh[b])
                bound = step * (seg.node_speed[i] + seg.shape_work[5, s] + seg.shape_work[6, s] * lever)
                ratios.append(move / bound)
    assert max(ratios) <= 1.0 + 1e-12
    assert max(ratios) > 1.0 / (2.0 + np.sqrt(3.0))
