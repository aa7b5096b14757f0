"""Open3D registration of a noisy LiDAR scan of the paper's debris, and the alignment check."""
import numpy as np
import open3d as o3d
import pytest
from scipy.spatial.transform import Rotation

from perception.lidar import cast
from perception.registration import DebrisTracker, _cloud

SENSOR = np.zeros(3)
RANGE = 10.0   # m, the case's hold distance


def _scan(mesh, lidar, body_to_world, position, seed):
    vertices = mesh.vertices @ body_to_world.T + position
    return cast(lidar, [(vertices, mesh.faces)], 0.0, np.random.default_rng(seed)).points_sensor


def _tracker(mesh):
    tracker = DebrisTracker(voxel=0.03, max_correspondence=0.1, model_points_body=mesh.sample(20000))
    return tracker


def _pose(rotation, position):
    """world_to_body of a body at ``position`` with attitude ``rotation`` (body->world)."""
    pose = np.eye(4)
    pose[:3, :3] = rotation.T
    pose[:3, 3] = -rotation.T @ position
    return pose


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_icp_recovers_a_known_transform_of_a_noisy_scan(paper_ellipsoid, c_fans_lidar, seed):
    # The scan is ray-cast with 2 cm range noise; ICP starts 10 deg and 5 cm off. On this smooth,
    # nearly axisymmetric body one frame pins the attitude to ~1 deg (the turn about the long
    # axis is weakly seen: semi-axes 0.65 vs 0.7 m); 4 deg and 1 cm hold for every seed tried (0-19).
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
