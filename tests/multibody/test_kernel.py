"""The kernel's prediction of the state Exudyn's VelocityVerlet evaluates the force at."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from multibody.kernel import verlet_evaluation_state
from multibody.maths.rotations import compose_rotation_vectors


@pytest.mark.parametrize("seed", range(5))
def test_rotation_vector_composition_matches_scipy(seed):
    # R(result) = R(rv) R(increment): rotation about body axes after rv (Exudyn's Lie-group update).
    rng = np.random.default_rng(seed)
    rv = rng.normal(size=3) * rng.uniform(0.0, 3.0)
    increment = rng.normal(size=3) * rng.uniform(0.0, 0.5)
    expected = (Rotation.from_rotvec(rv) * Rotation.from_rotvec(increment)).as_matrix()
    result = compose_rotation_vectors(rv, increment)
    assert np.linalg.norm(result) <= np.pi + 1e-12
    assert np.abs(Rotation.from_rotvec(result).as_matrix() - expected).max() < 1e-12


def test_verlet_state_is_the_drift_with_the_half_kicked_velocity():
    # one node (3 coordinates) and one body (6): x + h (v + h/2 a); body rotation composed
    rng = np.random.default_rng(7)
    q, v, a = rng.normal(size=9), rng.normal(size=9), rng.normal(size=9)
    h = 1e-3
    q_next, v_half = verlet_evaluation_state(q, v, a, h, 3, 1)
    assert np.allclose(v_half, v + 0.5 * h * a, rtol=0, atol=1e-15)
    assert np.allclose(q_next[:6], q[:6] + h * v_half[:6], rtol=0, atol=1e-15)
    assert np.allclose(q_next[6:], compose_rotation_vectors(q[6:], h * v_half[6:]), rtol=0, atol=1e-15)
