"""Torque-free propagation and the fit of inertia ratios to a tumble (Tang et al. 2023, Sec. 3.1)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from perception.euler_poinsot import (TorqueFreeFit, normalized_inertia_linear, principal_frame,
                                      propagate_torque_free, rotations_from_wxyz, _euler_rate)
from tests.perception.conftest import PAPER_MOMENTS

OMEGA0 = np.array([2.0, 0.5, 1.0])   # rad/s, Tang et al. 2023 Table 1


def _tumble(duration, rate=10.0):
    times = np.arange(int(round(duration * rate)) + 1) / rate
    qs, ws = propagate_torque_free(np.array([1.0, 0, 0, 0]), OMEGA0, PAPER_MOMENTS / PAPER_MOMENTS[2], times, 0.005)
    return times, rotations_from_wxyz(qs), ws


def test_propagation_keeps_energy_and_angular_momentum():
    # Torque-free motion: 2E = w.Jw and the world-frame L = R J w are invariants (Euler-Poinsot);
    # RK4 at 5 ms on a 2.3 rad/s tumble errs ~ (h w)^4 ~ 1e-8 per second, so 1e-7 over 60 s.
    times, rot, ws = _tumble(60.0)
    j = PAPER_MOMENTS / PAPER_MOMENTS[2]
    energy = np.einsum("ki,i,ki->k", ws, j, ws)
    momentum = rot.apply(ws * j)
    assert np.abs(energy / energy[0] - 1).max() < 1e-7
    assert np.abs(momentum - momentum[0]).max() / np.linalg.norm(momentum[0]) < 1e-7


def test_linear_fit_is_exact_on_exact_rates():
    # Noise-free rates and accelerations satisfy J w' + w x J w = 0 exactly: the null vector is J.
    _, rot, ws = _tumble(20.0)
    j = PAPER_MOMENTS / PAPER_MOMENTS[2]
    rates = np.array([_euler_rate(w, j) for w in ws])
    body_to_model = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()   # an arbitrary model frame
    estimate = normalized_inertia_linear(ws @ body_to_model.T, rates @ body_to_model.T)
    moments, principal_to_body = principal_frame(estimate)
    np.testing.assert_allclose(moments, j, rtol=1e-9)
    np.testing.assert_allclose(np.abs(principal_to_body), np.abs(body_to_model), atol=1e-9)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_trajectory_fit_recovers_inertia_ratios(seed):
    # 30 s of attitudes with 1 deg noise per axis (what ICP gives on the paper's ellipsoid, see
    # tests/perception/test_registration.py), seen in an unknown model frame, started 5 %
    # off in the ratios and ~8 deg off in the principal axes. The fit's own 1-sigma is ~0.15 %;
    # 1 % leaves over 5 sigma for any seed.
    rng = np.random.default_rng(seed)
    times, truth, _ = _tumble(30.0)
    sigma = np.radians(1.0)
    model_to_principal = Rotation.random(random_state=seed)
    measured = truth * model_to_principal * Rotation.from_rotvec(rng.normal(0, sigma, (len(times), 3)))
    weights = np.tile(np.eye(3) / sigma, (len(times), 1, 1))
    start_axes = (model_to_principal.inv() * Rotation.from_rotvec([0.1, 0.05, -0.1])).as_matrix()
    j = PAPER_MOMENTS / PAPER_MOMENTS[2]
    fit = TorqueFreeFit().fit(times, measured, weights, omega0_body=model_to_principal.inv().apply(OMEGA0) * 1.05,
                              moments0=j * [1.05, 0.95, 1.0], principal_to_body0=start_axes)
    np.testing.assert_allclose(fit.moments_, j, rtol=0.01)
    # the weights are the true noise: the weighted residual RMS is 1 within its sampling spread
    assert abs(fit.residual_rms_ - 1.0) < 0.1
    # principal axes recovered (up to sign) within 1 deg
    alignment = np.abs(np.sum(fit.principal_to_body_ * model_to_principal.inv().as_matrix(), axis=0))
    assert np.all(alignment > np.cos(np.radians(1.0)))


@pytest.mark.parametrize("seed", [0, 1])
def test_a_world_side_turn_of_every_attitude_turns_the_spin_momentum_by_it(seed):
    # Known answer: attitudes all turned by one world-side rotation q (R -> exp(q) R) are the same torque-free motion
    # turned by q, so the fit's h = R J w turns by q: dh = q x h, cov(h) = [h]x cov(q) [h]x^T. Measured body-side, the
    # turn is e_k = R_k^T q on frame k, correlated between all frames: cov(e_k, e_l) = R_k^T cov(q) R_l. Propagated
    # by add_attitude_covariance through the fit's linear response it must give the same covariance; the fit is on
    # exact attitudes (its own covariance zero), the moments known; what is left is the finite-difference Jacobian
    # of h (1e-6 steps) and of the least squares: 1e-4 of the largest entry.
    rng = np.random.default_rng(seed)
    times, truth, _ = _tumble(5.0)
    j = PAPER_MOMENTS / PAPER_MOMENTS[2]
    weights = np.tile(np.eye(3) / np.radians(0.3), (len(times), 1, 1))
    fit = TorqueFreeFit(j, np.eye(3)).fit(times, truth, weights, omega0_body=OMEGA0 * 1.02)
    fit.covariance_ = np.zeros_like(fit.covariance_)   # exact attitudes: only the added part
    root = rng.normal(0.0, np.radians(0.1), (3, 3))
    cov_q = root @ root.T
    rotations = truth.as_matrix()
    attitude_covariance = np.block([[a.T @ cov_q @ b for b in rotations] for a in rotations])
    h, cov_h = fit.add_attitude_covariance(attitude_covariance).spin_momentum_per_c()
    cross = np.cross(np.eye(3), h)   # [h]x: cross @ q = h x q
    expected = cross @ cov_q @ cross.T
    np.testing.assert_allclose(cov_h, expected, atol=1e-4 * np.abs(expected).max())
