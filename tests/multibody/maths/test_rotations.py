"""Tests of multibody.maths.rotations against the log and exponential maps they shortcut."""
import numpy as np
import pytest

from multibody.maths.rotations import (half_rotation_matrix_into, rotation_matrix_from_rotation_vector,
                                       rotation_vector_from_matrix)


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-3, 0.7, 2.0, np.pi - 1e-6, np.pi])
def test_half_rotation_is_the_exponential_of_half_the_log(angle):
    """Exp(Log(R) / 2) by the log and exponential maps (the joints' mid frame's definition) against the half-angle
    quaternion's matrix: equal to round-off (1e-14 on entries of order 1; near pi the log's axis carries the
    matrix's round-off, ~1e-8 of the angle at pi - 1e-6, so a looser bound there), and its square is R."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        rotation = rotation_matrix_from_rotation_vector(angle * axis)
        expected = rotation_matrix_from_rotation_vector(0.5 * rotation_vector_from_matrix(rotation))
        out = np.zeros((2, 3, 3))
        half_rotation_matrix_into(rotation, out, 1)
        tolerance = 1e-14 if angle < 3.0 else 1e-7
        assert np.abs(out[1] - expected).max() < tolerance
        assert np.abs(out[1] @ out[1] - rotation).max() < 1e-14
        assert np.abs(out[1].T @ out[1] - np.eye(3)).max() < 1e-14
        assert np.array_equal(out[0], np.zeros((3, 3)))
