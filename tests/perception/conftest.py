"""Fixtures of the perception tests: the debris of Tang et al. (2023), Table 1."""
import numpy as np
import pytest

from multibody.geometry import shape_mesh
from perception.lidar import LidarSpec

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
