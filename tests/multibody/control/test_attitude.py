"""Sliding-mode attitude controller (multibody/control/attitude.py; Boonrath et al. 2024 eqs. 7-10)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from multibody.control.attitude import kinematics_matrix, sampled_boundary_layer, sliding_mode_torque
from multibody.maths.rotations import quaternion_from_matrix, quaternion_to_matrix

J = np.diag([266.67, 266.67, 266.67]) + np.array([[0, 5.0, -3.0], [5.0, 0, 2.0], [-3.0, 2.0, 0]])  # kg m^2
K, G, EPS = 24.0, np.ones(3), 1e-3      # Sec. 4.1


@pytest.mark.parametrize("seed", range(5))
def test_quaternion_round_trip(seed):
    """eq. (6) and its inverse against scipy (scalar-last there); round-off only."""
    rot = Rotation.random(random_state=seed).as_matrix()
    q = quaternion_from_matrix(rot)
    np.testing.assert_allclose(quaternion_to_matrix(q), rot, atol=1e-14)
    q_scipy = Rotation.from_matrix(rot).as_quat()
    np.testing.assert_allclose(np.abs(q), np.abs(np.r_[q_scipy[3], q_scipy[:3]]), atol=1e-14)


@pytest.mark.parametrize("seed", range(5))
def test_sliding_variable_obeys_reaching_law(seed):
    """Under the control torque alone the Euler equation (3) and q' = Q(q) w / 2 give
    dS/dt = -G sat(S, eps): checked by central differences of S along the closed-loop flow
    (h = 1e-6 s; O(h^2) = 1e-12 truncation against values ~1e-3, so 1e-6 relative)."""
    rng = np.random.default_rng(seed)
    desired = Rotation.random(random_state=rng).as_matrix()
    actual = Rotation.from_rotvec(rng.normal(0, 0.05, 3)).as_matrix() @ desired
    omega = rng.normal(0, 1e-3, 3)
    width = np.full(3, 0.2)          # wide boundary layer: the linear part of sat is exercised

    def flow(rot, w, dt):
        torque, _ = sliding_mode_torque(rot, w, desired, J, K, G, width)
        w_dot = np.linalg.solve(J, torque - np.cross(w, J @ w))
        q = quaternion_from_matrix(rot)
        q_new = q + dt * 0.5 * kinematics_matrix(q) @ w
        return quaternion_to_matrix(q_new / np.linalg.norm(q_new)), w + dt * w_dot

    h = 1e-6
    _, s0 = sliding_mode_torque(actual, omega, desired, J, K, G, width)
    s_plus = sliding_mode_torque(*flow(actual, omega, h), desired, J, K, G, width)[1]
    s_minus = sliding_mode_torque(*flow(actual, omega, -h), desired, J, K, G, width)[1]
    expected = -G * np.clip(s0 / width, -1, 1)
    np.testing.assert_allclose((s_plus - s_minus) / (2 * h), expected, rtol=1e-6, atol=1e-9)


def test_sampled_boundary_layer():
    # -> eps as the step vanishes; exact discrete decay exp(-h G/eps) per step (formula in the docstring)
    assert sampled_boundary_layer(EPS, G, 0.0)[0] == EPS
    assert sampled_boundary_layer(EPS, G, 1e-6)[0] == pytest.approx(EPS * (1 + 5e-4), rel=1e-6)
    h = 3.7e-3
    width = sampled_boundary_layer(EPS, G, h)[0]
    assert 1.0 - h * G[0] / width == pytest.approx(np.exp(-h / EPS), rel=1e-12)
