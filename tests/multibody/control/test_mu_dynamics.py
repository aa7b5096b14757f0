"""MU planar dynamics (seed paper maneuverable-units-2d-guidance, eqs. 1-3, 11-12) against
independent mechanics: two point masses' momentum and angular momentum, and the rocket mass law."""
import casadi as ca
import numpy as np
import pytest

from multibody.control.mu_dynamics import (IndependentMUs, RigidRodMUs, controls_from_angles, rigid_rod_rhs,
                                 rod_unit_positions, thrust_angles)


@pytest.mark.parametrize("seed", range(5))
def test_rod_acceleration_is_newton_euler_of_two_point_masses(seed):
    # Independent check of eqs. 1-3: force on the pair / 2m, and the torque r_rel x F about the
    # CoM over I = 2 m (L/2)^2 (cross products by numpy, not the paper's expanded formula).
    rng = np.random.default_rng(seed)
    m, length = 2.5, 22.0
    state = rng.normal(size=6)
    thrust, theta = rng.uniform(0, 5, 2), rng.uniform(0, 2 * np.pi, 2)
    d = rigid_rod_rhs(state, controls_from_angles(*thrust, *theta), m, length)
    phi = state[4]
    forces = [t * np.array([np.cos(phi - th), np.sin(phi - th)]) for t, th in zip(thrust, theta)]
    x1, y1, x2, y2 = rod_unit_positions(state, length)
    com = np.array([state[0], state[2]])
    torque = sum(np.cross(p - com, f) for p, f in zip((np.array([x1, y1]), np.array([x2, y2])), forces))
    assert d[[1, 3]] == pytest.approx(sum(forces) / (2 * m), rel=1e-12, abs=1e-12)
    assert d[5] == pytest.approx(torque / (2 * m * (length / 2) ** 2), rel=1e-12, abs=1e-12)
    assert d[[0, 2, 4]] == pytest.approx(state[[1, 3, 5]], rel=0, abs=0)


def test_numpy_and_casadi_evaluate_the_same_expressions():
    # one code path for both backends: exact agreement to round-off
    rng = np.random.default_rng(1)
    for model, n in ((RigidRodMUs(2.5, 22.0, 0.0014), 6), (IndependentMUs(0.0014), 10)):
        x = rng.normal(size=n) + (np.r_[0, 0, 0, 0, 3, 0, 0, 0, 0, 3] if n == 10 else 0)
        u = np.asarray(controls_from_angles(3.0, 7.0, 0.4, 2.2))
        sx, su = ca.SX.sym("x", n), ca.SX.sym("u", 6)
        f = ca.Function("f", [sx, su], [model.rhs(sx, su)])
        assert np.array(f(x, u)).ravel() == pytest.approx(model.rhs(x, u), rel=1e-14, abs=1e-14)


def test_unit_mass_falls_by_k_times_impulse():
    # eq. 11: dm/dt = -k T; with constant thrust the mass falls linearly (exact)
    model = IndependentMUs(0.0014)
    x = np.r_[0, 0, 0, 0, 2.5, 1, 1, 0, 0, 2.4]
    d = model.rhs(x, controls_from_angles(12.0, 5.0, 0.3, 4.0))
    assert d[[4, 9]] == pytest.approx([-0.0014 * 12.0, -0.0014 * 5.0], rel=1e-15)
    assert np.hypot(d[2], d[3]) == pytest.approx(12.0 / 2.5, rel=1e-14)
    angles = thrust_angles(np.asarray(controls_from_angles(1.0, 1.0, 7.0, -1.0)))
    assert angles == pytest.approx((7.0 - 2 * np.pi, 2 * np.pi - 1.0), rel=1e-12)
