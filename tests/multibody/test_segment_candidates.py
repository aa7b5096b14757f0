"""The thread contact's candidate pairs kept with a skin (multibody/segment_candidates.py): at every step they hold
every (thread, box) pair that the full scan's bounding-sphere and slab tests pass (multibody/segment_pairs.py), on
scenes with moving, turning bodies; and a capture on two free, spinning plates computes the same trajectory, to the
last bit, with the skin as with a rebuild at every step (skin 0: the full scan's slab test)."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.contact_segment import segment_buffers
from multibody.impact import ImpactSimulation
from multibody.kernel import BodyStates, ShapeArrays
from multibody.net import NetTopology
from multibody.segment_candidates import CANDIDATE_SKIN, refresh_candidates
from multibody.segment_pairs import _near_shapes
from tests.conftest import PAPER_CONTACT_STIFFNESS


def _rotation(axis_angle) -> np.ndarray:
    """Rodrigues' rotation matrix of the rotation vector ``axis_angle`` (rad)."""
    angle = np.linalg.norm(axis_angle)
    if angle == 0.0:
        return np.eye(3)
    k = axis_angle / angle
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * cross @ cross


def _boxes():
    """Three boxes on two bodies (body 0: a 1 x 0.6 x 0.4 m box and a 0.05 m plate beside it; body 1: a 0.8 m cube),
    body frame (m); the other ShapeArrays fields are not read by the pair search."""
    box_min = np.array([[-0.5, -0.3, -0.2], [0.6, -0.5, -0.025], [-0.4, -0.4, -0.4]])
    box_max = np.array([[0.5, 0.3, 0.2], [1.6, 0.5, 0.025], [0.4, 0.4, 0.4]])
    return ShapeArrays(triangles_body=np.zeros((0, 3, 3)), normals_body=np.zeros((0, 3)),
                       body=np.array([0, 0, 1], np.int64), triangle_range=np.zeros((3, 2), np.int64),
                       box_min_body=box_min, box_max_body=box_max, is_box=np.ones(3, np.int64))


def _full_scan_pairs(x, threads, radius, seg, states, shapes, step) -> set:
    """The (thread, box) pairs that the full scan's bounding-sphere and slab tests pass (segment_pairs._contact_pairs
    before the candidate list, written out in NumPy over all pairs)."""
    a, c = threads[:, 0], threads[:, 1]
    length = np.linalg.norm(x[:, c] - x[:, a], axis=0)
    motion = step * np.maximum(seg.node_speed[a], seg.node_speed[c])
    kept = set()
    for s in range(len(shapes.body)):
        reach = 1.001 * (np.minimum(radius[a], radius[c]) + motion + step * seg.shape_work[1, s])
        centre = np.linalg.norm(x - seg.shape_work[2:5, [s]], axis=0)
        sphere = 0.5 * (centre[a] + centre[c] - length) <= seg.shape_work[0, s] + reach
        b = shapes.body[s]
        p = states.body_to_lvlh[b].T @ (x - states.com_lvlh[b][:, None])      # (3, n) body frame
        low, high = np.minimum(p[:, a], p[:, c]), np.maximum(p[:, a], p[:, c])
        slab = ~((low > shapes.box_max_body[s][:, None] + reach).any(axis=0)
                 | (high < shapes.box_min_body[s][:, None] - reach).any(axis=0))
        kept |= {(int(j), s) for j in np.flatnonzero(sphere & slab)}
    return kept


@pytest.mark.parametrize("seed", range(5))
def test_candidates_hold_every_pair_the_full_scan_keeps(seed):
    """120 threads (random pairs of 150 nodes within 0.5 m of each other) drifting at up to 1.5 m/s through three
    boxes on two bodies that move (0.3 m/s) and turn (up to 1 rad/s), 1000 steps of 0.2 ms: at every step the listed
    pairs hold every pair the full scan keeps (a superset, no tolerance: the module's inequality is exact up to the
    1e-9 m tie distance), while the list is rebuilt at fewer than a quarter of the steps (the skin works: a node 2.5 m
    from a body turning at 1 rad/s crosses the 1 cm skin in 20 steps)."""
    rng = np.random.default_rng(seed)
    n, m, nb, step = 150, 120, 2, 2e-4
    shapes = _boxes()
    x = rng.uniform(-1.2, 1.8, (3, n))
    velocity = rng.uniform(-1.5, 1.5, (3, n)) * rng.uniform(0.0, 1.0, n)
    near = [(a, c) for a in range(n) for c in range(a + 1, n) if np.linalg.norm(x[:, a] - x[:, c]) < 0.5]
    threads = np.array([near[k] for k in rng.choice(len(near), size=m, replace=False)], np.int64)
    radius = np.full(n, 0.001)
    seg = segment_buffers(m, n, len(shapes.body), nb, True)
    com, body_velocity = np.array([[0.0, 0.0, 0.0], [0.3, 1.2, 0.0]]), rng.uniform(-0.3, 0.3, (nb, 3))
    omega = rng.uniform(-1.0, 1.0, (nb, 3)) / np.sqrt(3.0)
    attitude = np.stack([_rotation(rng.uniform(-np.pi, np.pi, 3)) for _ in range(nb)])
    n_full, changes, last = 0, 0, set()
    for _ in range(1000):
        states = BodyStates(attitude.copy(), com.copy(), body_velocity.copy(), omega.copy(), attitude.copy(),
                            np.einsum("bji,bj->bi", attitude, omega))
        _near_shapes(x, velocity, np.zeros((3, n)), np.ones(n), np.zeros((3, n)), seg, states, shapes, step)
        count = refresh_candidates(x, threads, radius, seg, states, shapes, step)
        listed = set(zip(seg.candidate_thread[:count].tolist(), seg.candidate_shape[:count].tolist()))
        full = _full_scan_pairs(x, threads, radius, seg, states, shapes, step)
        assert full <= listed, f"pairs the full scan keeps and the list lost: {sorted(full - listed)}"
        n_full += len(full)
        changes, last = changes + len(full ^ last), full
        x = x + step * velocity
        com = com + step * body_velocity
        attitude = np.stack([_rotation(step * omega[b]) @ attitude[b] for b in range(nb)])
    # the scene makes pairs and changes them (seeds 0-4: 6500-14300 pair-steps, 16-24 pairs in or out; with the list
    # never rebuilt after the first step, 295-3306 pair-steps are lost): the superset is not vacuous
    assert n_full > 1000 and changes >= 5
    assert seg.candidate_count[1] < 1000 / 4  # builds


def _grid_net(size, spacing, centre, node_mass=0.04223, radius=0.001) -> NetTopology:
    """A square size x size net of spacing (m) in the x-z plane around ``centre`` (LVLH, m), threads 5e4 N/m at rest
    length (envisat_small's node mass), no bending."""
    index = np.arange(size * size).reshape(size, size)
    u = (np.arange(size) - 0.5 * (size - 1)) * spacing
    positions = np.array([[centre[0] + a, centre[1], centre[2] + b] for a in u for b in u])
    threads = np.array([(index[i, k], index[i, k + 1]) for i in range(size) for k in range(size - 1)]
                       + [(index[i, k], index[i + 1, k]) for i in range(size - 1) for k in range(size)], np.int64)
    m = len(threads)
    return NetTopology(positions=positions, masses=np.full(len(positions), node_mass),
                       radii=np.full(len(positions), radius), threads=threads, rest_lengths=np.full(m, spacing),
                       stiffness=np.full(m, 5e4), damping=np.full(m, 1.58), bending_triples=np.zeros((0, 3), np.int64),
                       bending_stiffness=np.zeros(0), nodes_per_side=0, n_bullets=0)


def _spinning_plates_capture(skin: float, proofs: float = 1.0):
    """A 7 x 7 net (0.12 m mesh) at 3 m/s onto two free plates (2 kg, 0.5 x 0.05 x 0.4 m, side by side with a 4 cm
    gap), spinning at 3 and -2 rad/s about their long axes and drifting apart, 40 ms; returns the run's net
    snapshots, body series and the candidate buffers. ``proofs`` 0 tests every listed pair at both states (no skip of
    a test whose answer is proven, multibody.segment_pairs)."""
    v, step = 3.0, 1e-4
    net = _grid_net(7, 0.12, (0.0, -0.06, 0.0))
    plates = []
    for x_centre, spin in ((-0.27, 3.0), (0.27, -2.0)):
        extents = np.array([0.5, 0.05, 0.4])
        inertia = 2.0 / 12.0 * np.diag([extents[1] ** 2 + extents[2] ** 2, extents[0] ** 2 + extents[2] ** 2,
                                        extents[0] ** 2 + extents[1] ** 2])
        plates.append(RigidBodySpec(name=f"plate{len(plates)}", mass=2.0, inertia_body=inertia,
                                    com_lvlh=np.array([x_centre, 0.0, 0.0]),
                                    velocity_lvlh=np.array([np.sign(x_centre) * 0.2, 0.0, 0.0]),
                                    omega_body=np.array([spin, 0.0, 0.0]),
                                    meshes_body=[trimesh.creation.box(extents=extents)]))
    assembly = ImpactAssembly(
        net=net, net_velocity=np.tile([0.0, v, 0.0], (len(net.masses), 1)), bodies=plates, joints=[],
        contact=ContactLaw(stiffness=PAPER_CONTACT_STIFFNESS, hunt_crossley_alpha=0.05, mu_static=0.19,
                           mu_kinetic=0.152, thread_segments=True),
        solver=SolverSpec(end_time=0.04, step=step, output_rate=1.0 / step, net_output_rate=1000.0))
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None          # compare the trajectories, do not judge them
    segments = simulation.system.kernel.buffers.segments
    segments.candidate_scalar[0] = skin
    segments.candidate_scalar[2] = proofs
    return simulation.run(), segments


def test_a_capture_on_spinning_plates_is_the_same_with_the_skin():
    """The listed pairs go through the full scan's tests in its order, so the skin changes no force: the net's
    positions and velocities and the plates' states agree to the last bit with a rebuild at every step (skin 0, the
    full scan's slab test) over a 40 ms capture with threads in contact with both spinning plates; the skin's run
    rebuilt its list at under a quarter of the 400 steps."""
    with_skin, segments = _spinning_plates_capture(CANDIDATE_SKIN)
    every_step, segments_zero = _spinning_plates_capture(0.0)
    assert segments_zero.candidate_count[1] >= 400                  # skin 0: a build at every evaluation
    assert segments.candidate_count[1] < 100
    assert segments.dissipated.sum() > 0.0                          # threads did touch
    assert (np.abs(with_skin.series["contact_force_lvlh"]).max(axis=(0, 2)) > 100.0).all()   # both plates (N)
    for key in ("positions_lvlh", "velocities_lvlh"):
        np.testing.assert_array_equal(with_skin.net[key], every_step.net[key])
    for key in ("body_velocity_lvlh", "body_omega_body", "contact_force_lvlh"):
        np.testing.assert_array_equal(with_skin.series[key], every_step.series[key])


def test_a_capture_on_spinning_plates_is_the_same_without_the_skipped_pair_tests():
    """The pair tests skipped by a proof that they answer no (multibody.segment_pairs: a listed pair's whole step by
    its clearance, the test at the end of the free motion by the start's separating-axis bound) change no force: the
    same 40 ms capture with every listed pair tested at both states agrees to the last bit, and both skips did act
    (counted in ``candidate_count[2:4]``; none when switched off)."""
    skipped, segments = _spinning_plates_capture(CANDIDATE_SKIN)
    tested, segments_all = _spinning_plates_capture(CANDIDATE_SKIN, proofs=0.0)
    assert segments.candidate_count[2] > 0 and segments.candidate_count[3] > 0
    assert segments_all.candidate_count[2] == segments_all.candidate_count[3] == 0
    assert segments.dissipated.sum() > 0.0                          # threads did touch
    for key in ("positions_lvlh", "velocities_lvlh"):
        np.testing.assert_array_equal(skipped.net[key], tested.net[key])
    for key in ("body_velocity_lvlh", "body_omega_body", "contact_force_lvlh"):
        np.testing.assert_array_equal(skipped.series[key], tested.series[key])
