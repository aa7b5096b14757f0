"""Open3D registration of a noisy LiDAR scan of the paper's debris, and the alignment check."""
import numpy as np
import open3d as o3d
import pytest
from scipy.spatial.transform import Rotation

from perception.lidar import cast
from perception.registration import Alignment, DebrisTracker, _cloud, known_shape_model
from perception.visibility import free_space_violation
from perception.shape import half_turn_symmetry_transforms

SENSOR = np.zeros(3)
RANGE = 10.0   # m, the case's hold distance


def _scan(mesh, lidar, body_to_world, position, seed):
    vertices = mesh.vertices @ body_to_world.T + position
    return cast(lidar, [(vertices, mesh.faces)], 0.0, np.random.default_rng(seed)).points_sensor


def _tracker(mesh):
    tracker = DebrisTracker(0.03, 0.1, 30, *known_shape_model(mesh, 0.03, seed=0))
    return tracker


def _pose(rotation, position):
    """world_to_body of a body at ``position`` with attitude ``rotation`` (body->world)."""
    pose = np.eye(4)
    pose[:3, :3] = rotation.T
    pose[:3, 3] = -rotation.T @ position
    return pose


@pytest.mark.parametrize("seed", range(8))
def test_icp_recovers_a_known_transform_of_a_noisy_scan(paper_ellipsoid, c_fans_lidar, seed):
    # The scan is ray-cast with 2 cm range noise; ICP starts 10 deg and 5 cm off. On this smooth,
    # nearly axisymmetric body one frame pins the attitude to ~1 deg (the turn about the long
    # axis is weakly seen: semi-axes 0.65 vs 0.7 m); 4 deg and 1 cm hold for every seed tried (0-19)
    # with the mesh model (exact normals); the voxel model with estimated normals once reached 4.01 deg.
    rng = np.random.default_rng(seed)
    truth = Rotation.random(random_state=seed).as_matrix()
    position = np.array([RANGE, 0.0, 0.0]) + rng.normal(0, 0.1, 3)
    points = _scan(paper_ellipsoid, c_fans_lidar, truth, position, seed)
    tracker = _tracker(paper_ellipsoid)
    start = _pose(Rotation.from_rotvec(np.radians(10.0) * rng.normal(size=3) / np.sqrt(3)).as_matrix() @ truth,
                  position + rng.normal(0, 0.05 / np.sqrt(3), 3))
    pose = tracker._icp(_cloud(points).voxel_down_sample(tracker.voxel), start)
    found = np.linalg.inv(pose)
    assert Rotation.from_matrix(found[:3, :3] @ truth.T).magnitude() < np.radians(4.0)
    assert np.linalg.norm(found[:3, 3] - position) < 0.01
    check = tracker._judge(0.0, points, pose, pose, SENSOR, has_motion=True)
    assert check.ok


def _icp_from(tracker, points, truth, position, wrong_turn):
    scan = _cloud(points).voxel_down_sample(tracker.voxel)
    pose = tracker._icp(scan, _pose(truth @ Rotation.from_rotvec(wrong_turn).as_matrix(), position))
    fitness = o3d.pipelines.registration.evaluate_registration(scan, tracker._model, tracker.max_correspondence,
                                                               pose).fitness
    error = Rotation.from_matrix(np.linalg.inv(pose)[:3, :3] @ truth.T).magnitude()
    return pose, fitness, error


def test_check_rejects_a_wrong_pose_that_open3d_scores_well(paper_ellipsoid, c_fans_lidar):
    # ICP seeded 90 deg off about the body x axis stays ~90 deg off; Open3D still reports
    # ~0.78 fitness at its correspondence distance (above the 0.6-0.7 often used to accept).
    # Geometry alone (no motion prediction) rejects it: tight fitness and free-space violation.
    truth = Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix()
    position = np.array([RANGE, 0.0, 0.0])
    points = _scan(paper_ellipsoid, c_fans_lidar, truth, position, 0)
    tracker = _tracker(paper_ellipsoid)
    pose, fitness, error = _icp_from(tracker, points, truth, position, [np.pi / 2, 0.0, 0.0])
    assert error > np.radians(45.0) and fitness > 0.7
    check = tracker._judge(0.0, points, pose, pose, SENSOR, has_motion=False)
    assert not check.ok
    assert check.tight_fitness < 0.8 and check.free_space_violation > 0.05


def test_symmetric_flip_is_caught_by_the_motion_check(paper_ellipsoid, c_fans_lidar):
    # Seeded 90 deg off about z, ICP lands on the 180 deg flip: the ellipsoid is congruent to
    # itself there, so no surface test can see it (Open3D fitness 1, our geometry passes);
    # only the innovation against the predicted motion does.
    truth = Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix()
    position = np.array([RANGE, 0.0, 0.0])
    points = _scan(paper_ellipsoid, c_fans_lidar, truth, position, 0)
    tracker = _tracker(paper_ellipsoid)
    pose, fitness, error = _icp_from(tracker, points, truth, position, [0.0, 0.0, np.pi / 2])
    assert error > np.radians(170.0) and fitness > 0.99
    assert tracker._judge(0.0, points, pose, pose, SENSOR, has_motion=False).ok
    check = tracker._judge(0.0, points, pose, _pose(truth, position), SENSOR, has_motion=True)
    assert not check.ok and check.innovation > np.radians(170.0)


def _attitude_error(alignment, truth):
    """Attitude error (rad) up to the ellipsoid's symmetries (half turns about its axes)."""
    return min(Rotation.from_matrix(alignment.body_to_world[:3, :3] @ (truth @ np.diag(flip)).T).magnitude()
               for flip in ([1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]))


def _seen(time_s, pose, ok=True):
    return Alignment(time_s, pose, np.eye(6), 1.0 if ok else 0.0, 0.0, 0.0, ok, False, 0.0, 0)


def test_lost_track_is_found_again_over_all_attitudes(paper_ellipsoid, c_fans_lidar):
    # Frames failed since the last good one (say a collision): the body may have turned far. Here
    # 90 deg about its x axis, beyond the small-turn search (30 deg) and no symmetry of the body,
    # then turning on at 0.05 rad per frame about the world z axis (across the view); the search over
    # all attitudes finds it, not the RANSAC fallback. A re-acquired pose counts only once the next
    # frames continue it as one rigid motion (perception/registration.py, _continue_chains) and the
    # chain's view of the body has turned by CONFIRMING_VIEW_TURN (45 deg from its second frame: here
    # 2.9 deg a frame, so 17 frames): the searched frame and the ones after it are pending until then (not accepted after
    # 3 frames as before), and all are accepted together. Seen this way the turn about the long axis is
    # weak: ICP from the true pose itself ends 3-4 deg off.
    # The tracker knows the ellipsoid's half turns (as the stage does for a mesh): without them they
    # are rigid motions as good as the truth and nothing is accepted (tests/perception/test_reacquisition.py).
    truth = Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix()
    position = np.array([RANGE, 0.0, 0.0])
    tracker = DebrisTracker(0.03, 0.1, 30, *known_shape_model(paper_ellipsoid, 0.03, seed=0),
                            symmetries_body=half_turn_symmetry_transforms(paper_ellipsoid, 0.015))
    tracker.alignments = [_seen(0.0, _pose(truth, position)), _seen(0.1, np.eye(4), ok=False)]
    turned = [Rotation.from_rotvec([0.0, 0.0, 0.05 * k]).as_matrix() @ truth
              @ Rotation.from_rotvec([np.pi / 2, 0.0, 0.0]).as_matrix() for k in range(21)]
    first = tracker.update(0.2, _scan(paper_ellipsoid, c_fans_lidar, turned[0], position, 0), SENSOR)
    assert not first.ok and not first.global_init
    revised = []
    for k in range(1, len(turned)):
        tracker.update(0.2 + 0.1 * k, _scan(paper_ellipsoid, c_fans_lidar, turned[k], position, k), SENSOR)
        revised += tracker.revised
        if k == 2:   # three frames of one rigid motion, the view turned by 6 deg: still pending
            assert not any(a.ok for a in tracker.alignments[2:])
    assert revised and revised[0] == 2 and revised == list(range(2, revised[-1] + 1))
    for alignment, rotation in zip(tracker.alignments[2:], turned):
        assert alignment.ok and _attitude_error(alignment, rotation) < np.radians(6.0)


def test_gate_drops_returns_in_front_of_the_debris(paper_ellipsoid, c_fans_lidar):
    # A panel (net threads, say) 0.4 m in front of the debris, seen over part of it. With the
    # motion known from two frames, a 0.1 m gate around the predicted debris registers only the
    # debris's returns; without it the panel's returns dilute the tight fitness.
    spin = Rotation.from_rotvec([0.05, 0.1, 0.2])            # rad per frame
    start = Rotation.from_rotvec([0.3, 0.2, 0.1])
    position = np.array([RANGE, 0.0, 0.0])
    truth = [(spin ** k * start).as_matrix() for k in range(3)]
    x = RANGE - 1.3
    corners = np.array([[x, -0.6, -0.1], [x, 0.6, -0.1], [x, 0.6, 0.3], [x, -0.6, 0.3]])
    panel = (corners, np.array([[0, 1, 2], [0, 2, 3]]))
    debris = (paper_ellipsoid.vertices @ truth[2].T + position, paper_ellipsoid.faces)
    scan = cast(c_fans_lidar, [debris, panel], 0.0, np.random.default_rng(0))
    debris_points = len(_cloud(scan.points_sensor[scan.label == 0]).voxel_down_sample(0.03).points)
    alignments = {}
    for gate in (None, 0.1):
        tracker = _tracker(paper_ellipsoid)
        tracker.alignments = [_seen(0.1 * k, _pose(truth[k], position)) for k in range(2)]
        alignments[gate] = tracker.update(0.2, scan.points_sensor, SENSOR, gate=gate)
    gated = alignments[0.1]
    assert gated.ok and _attitude_error(gated, truth[2]) < np.radians(4.0)
    assert abs(gated.n_points - debris_points) <= 0.02 * debris_points
    assert alignments[None].n_points > 1.1 * gated.n_points
    assert alignments[None].tight_fitness < gated.tight_fitness


@pytest.mark.parametrize("seed", range(3))
def test_check_accepts_the_right_pose_at_far_range(paper_ellipsoid, c_fans_lidar, seed):
    # At 25 m the LiDAR's rays are ~4-5 cm apart, wider than the 3 cm voxel, and the nearest return
    # in a limb bin lies up to tens of cm deeper than the model points there. Without the limb
    # margin (one sample spacing x tan(incidence)) correct poses scored up to 0.145 violation here
    # (12 attitudes, after ICP from the truth); with it at most 0.008. Limit of the check: 0.05.
    rng = np.random.default_rng(100 + seed)
    truth = Rotation.random(random_state=rng).as_matrix()
    position = np.array([25.0, 0.0, 0.0]) + rng.normal(0, 0.3, 3)
    points = _scan(paper_ellipsoid, c_fans_lidar, truth, position, seed)
    tracker = _tracker(paper_ellipsoid)
    pose = tracker._icp(_cloud(points).voxel_down_sample(tracker.voxel), _pose(truth, position))
    check = tracker._judge(0.0, points, pose, pose, SENSOR, has_motion=True)
    assert check.free_space_violation < 0.03 and check.ok


def test_global_alignment_repeats_exactly(paper_ellipsoid, c_fans_lidar):
    # Open3D's RANSAC draws from a process-wide generator; the tracker re-seeds it per frame, so a
    # re-acquisition (and all tracking after it) is the same in every run of a case. Unseeded,
    # two calls on this scan gave different transforms.
    truth = Rotation.random(random_state=3).as_matrix()
    scan = _cloud(_scan(paper_ellipsoid, c_fans_lidar, truth, np.array([RANGE, 0.0, 0.0]), 0)).voxel_down_sample(0.03)
    tracker = _tracker(paper_ellipsoid)
    first, again = tracker._global(scan, np.eye(4)), tracker._global(scan, np.eye(4))
    np.testing.assert_array_equal(first, again)


def _lost_then_turned(paper_ellipsoid, c_fans_lidar, **budget):
    """A tracker whose track was lost a frame ago, and the scan of the body turned 90 deg since (as in
    test_lost_track_is_found_again_over_all_attitudes): the frame needs the search over all attitudes."""
    truth = Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix()
    position = np.array([RANGE, 0.0, 0.0])
    tracker = DebrisTracker(0.03, 0.1, 30, *known_shape_model(paper_ellipsoid, 0.03, seed=0),
                            symmetries_body=half_turn_symmetry_transforms(paper_ellipsoid, 0.015), **budget)
    tracker.alignments = [_seen(0.0, _pose(truth, position)), _seen(0.1, np.eye(4), ok=False)]
    turned = truth @ Rotation.from_rotvec([np.pi / 2, 0.0, 0.0]).as_matrix()
    return tracker, _scan(paper_ellipsoid, c_fans_lidar, turned, position, 0), truth, position


@pytest.mark.parametrize("budget", [{"search_cpu_per_run": 0.0}, {"search_cpu_per_frame": 1e-6}])
def test_a_spent_search_budget_leaves_the_lost_frame_not_registered(paper_ellipsoid, c_fans_lidar, budget):
    # The search budget (perception.registration.search_cpu_per_frame / _per_run): a lost frame whose
    # search passes the frame's CPU limit, or comes after the run's search time is spent, is recorded
    # as not registered (over_budget), never as the best pose found so far; no candidate chain is left
    # to confirm later. Unlimited, the same frame starts a chain (test above: the three frames are then
    # accepted together within 6 deg).
    tracker, scan, _, _ = _lost_then_turned(paper_ellipsoid, c_fans_lidar, **budget)
    frame = tracker.update(0.2, scan, SENSOR)
    assert not frame.ok and frame.over_budget and frame.searched
    assert tracker._chains == []
    unlimited, scan, _, _ = _lost_then_turned(paper_ellipsoid, c_fans_lidar)
    frame = unlimited.update(0.2, scan, SENSOR)
    assert not frame.over_budget and frame.searched and len(unlimited._chains) >= 1
    assert unlimited.search_cpu_spent == frame.cpu_seconds


def test_tracked_frames_go_on_when_the_search_budget_is_spent(paper_ellipsoid, c_fans_lidar):
    # The budget bounds searches only: a frame with a motion prediction (two good frames before it) is
    # registered by ICP from the prediction as always, within 4 deg of the truth (the bound of
    # test_gate_drops_returns_in_front_of_the_debris for the same body, range and spin), and is not
    # counted against the budget.
    spin = Rotation.from_rotvec([0.05, 0.1, 0.2])            # rad per frame
    start = Rotation.from_rotvec([0.3, 0.2, 0.1])
    position = np.array([RANGE, 0.0, 0.0])
    truth = [(spin ** k * start).as_matrix() for k in range(3)]
    tracker = DebrisTracker(0.03, 0.1, 30, *known_shape_model(paper_ellipsoid, 0.03, seed=0), search_cpu_per_run=0.0)
    tracker.alignments = [_seen(0.1 * k, _pose(truth[k], position)) for k in range(2)]
    frame = tracker.update(0.2, _scan(paper_ellipsoid, c_fans_lidar, truth[2], position, 0), SENSOR)
    assert frame.ok and not frame.over_budget and not frame.searched
    assert _attitude_error(frame, truth[2]) < np.radians(4.0)
    assert tracker.search_cpu_spent == 0.0


def _wall(x, y_from, y_to, spacing=0.01):
    """Returns on a wall facing the sensor at the origin: x = const (m), y in [y_from, y_to), |z| < 0.2 m."""
    y, z = np.meshgrid(np.arange(y_from, y_to, spacing), np.arange(-0.2, 0.2, spacing))
    return np.column_stack([np.full(y.size, x), y.ravel(), z.ravel()])


def test_lateral_bins_forgive_a_silhouette_off_by_one_bin_not_a_body_in_free_space():
    # A foreground wall at 5 m (y < 0.5 m) and the background at 6 m beside it, seen from the origin;
    # bins of 0.01 rad (5 cm at 5 m), margin 5 cm. A model point on the foreground's plane 2 cm beyond
    # its edge lies in a background bin, 1 m in front of that bin's nearest return: with its own bin
    # alone it blocks; its neighbour bin holds the foreground's edge at its own depth, so with one bin
    # about it it does not. A model point 0.4 m beyond the edge (8 bins) blocks either way.
    returns = np.vstack([_wall(5.0, -0.5, 0.5), _wall(6.0, 0.5, 1.5)])
    edge, beyond = np.array([[5.0, 0.52, 0.0]]), np.array([[5.0, 0.9, 0.0]])
    sensor = np.zeros(3)
    share = lambda model, lateral: free_space_violation(returns, model, sensor, 0.01, 0.05, lateral_bins=lateral)
    assert share(edge, 0) > 0 and share(edge, 1) == 0.0
    assert share(beyond, 0) > 0 and share(beyond, 1) > 0
