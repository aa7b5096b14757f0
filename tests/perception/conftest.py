"""Fixtures of the perception tests: the debris of Tang et al. (2023), Table 1."""
from types import SimpleNamespace

import numpy as np
import pytest
import trimesh

from multibody.geometry import shape_mesh
from perception.euler_poinsot import propagate_torque_free, rotations_from_wxyz
from perception.lidar import LidarSpec, cast, sensor_to_platform
from perception.scan_to_map import thinned_scan, track_scans

#: Principal moments of the paper's debris (kg m^2), Tang et al. 2023 Table 1: a uniform
#: 1715.23 kg ellipsoid of semi-axes 0.65 x 0.7 x 0.9 m (m/5 (b^2 + c^2) etc.).
PAPER_MOMENTS = np.array([445.98, 422.80, 313.04])


@pytest.fixture(scope="session")
def paper_ellipsoid():
    """The paper's debris surface, its own (principal) frame (Tang et al. 2023, Sec. 4.1)."""
    return shape_mesh("ellipsoid", semi_axes=[0.65, 0.7, 0.9])


@pytest.fixture(scope="session")
def c_fans_lidar():
    """C-Fans-256-like LiDAR of the paper's Table 3: 150 x 30 deg, 0.09 x 0.12 deg, 2 cm, 10 Hz."""
    deg = np.pi / 180
    return LidarSpec(150 * deg, 30 * deg, 0.09 * deg, 0.12 * deg, 0.02, 10.0)


#: The sensor at the world origin, its platform's up axis world z: the registration tests' scene.
SENSOR = np.zeros(3)
UP = np.array([0.0, 0.0, 1.0])


def scan_of_body(mesh, lidar, rotation, position, seed=0):
    """Scan of the body (body -> world ``rotation``, origin at ``position``, m) from the sensor at the
    origin, boresight on the body: returns (m, world), the sensor attitude and the true world -> B."""
    sensor_to_world = sensor_to_platform(position - SENSOR, UP)
    vertices = np.asarray(mesh.vertices) @ rotation.T + position
    scan = cast(lidar, [((vertices - SENSOR) @ sensor_to_world, mesh.faces)], 0.0, np.random.default_rng(seed))
    truth = np.eye(4)
    truth[:3, :3], truth[:3, 3] = rotation.T, -rotation.T @ position
    return scan.points_sensor @ sensor_to_world.T + SENSOR, sensor_to_world, truth


#: The synthetic tumble of tests/perception/test_scan_to_map.py and test_pose_graph.py (model-free tracking).
VOXEL = 0.03             # m, the case's scan thinning
CORRESPONDENCE = 0.1     # m, the case's ICP distance
OMEGA0 = np.array([2.0, 0.5, 1.0])         # rad/s, Tang et al. 2023 Table 1
COM0 = np.array([10.0, 0.0, 0.0])          # m, the case's 10 m hold distance
VELOCITY = np.array([0.01, 0.0, -0.01])    # m/s, Tang et al. 2023 Table 1


def featured_debris():
    """A satellite-like body (1.2 x 1.0 x 1.6 m bus, a 2 x 0.8 m array on one side): flat faces
    and edges, the surface features a scan-to-map registration needs (the paper's smooth
    ellipsoid has none about its near-symmetry axis: docs/perception.md, Known limits). Its
    origin (the point the tumble turns about) is the bus centre."""
    return trimesh.util.concatenate([shape_mesh("box", size=[1.2, 1.0, 1.6]),
                                     shape_mesh("box", size=[0.05, 2.0, 0.8], center=(0.0, 1.5, 0.2))])


@pytest.fixture(scope="session")
def tumble(c_fans_lidar):
    """10 s of 10 Hz scans of the featured body tumbling torque-free with the paper's normalized
    moments and initial rates, its origin on a straight line; tracked without the mesh."""
    times = np.arange(101) / 10.0
    qs, _ = propagate_torque_free(np.array([1.0, 0, 0, 0]), OMEGA0, PAPER_MOMENTS / PAPER_MOMENTS[2], times, 0.005)
    body_to_world = rotations_from_wxyz(qs).as_matrix()
    mesh = featured_debris()
    rng = np.random.default_rng(3)
    scans = [cast(c_fans_lidar, [(mesh.vertices @ r.T + COM0 + VELOCITY * t, mesh.faces)], t, rng).points_sensor
             for t, r in zip(times, body_to_world)]
    track = track_scans(scans, VOXEL, CORRESPONDENCE)
    # Frame B: world axes at the first scan (the body's attitude there is the identity), origin at
    # the first thinned scan's centroid; the true CoM sits at COM0 - centroid in B.
    centroid = thinned_scan(scans[0], VOXEL).mean(axis=0)
    return SimpleNamespace(times=times, body_to_world=body_to_world, track=track, com_body=COM0 - centroid, scans=scans)
