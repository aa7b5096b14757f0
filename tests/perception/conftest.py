"""Fixtures of the perception tests: the debris of Tang et al. (2023), Table 1."""
import numpy as np
import pytest

from multibody.geometry import shape_mesh
from perception.lidar import LidarSpec, cast, sensor_to_platform

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
