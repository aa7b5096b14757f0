"""The shared fixed-step RK4 (multibody/maths/rk4.py) against analytic solutions."""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.maths.rk4 import rk4_integrator


@njit(cache=True)
def _oscillator_rate(t, x, omega):
    """x = [position, velocity] of x'' = -omega^2 x (t not read)."""
    return np.array([x[1], -omega * omega * x[0]])


@njit(cache=True)
def _spin_rate(t, x, omega_body):
    """x = quaternion [w, x, y, z] body -> world of a body spinning at the constant ``omega_body``."""
    w = omega_body
    return 0.5 * np.array([-x[1] * w[0] - x[2] * w[1] - x[3] * w[2], x[0] * w[0] + x[2] * w[2] - x[3] * w[1],
                           x[0] * w[1] + x[3] * w[0] - x[1] * w[2], x[0] * w[2] + x[1] * w[1] - x[2] * w[0]])


@njit(cache=True)
def _forced_rate(t, x, amplitude):
    """x' = amplitude cos t: the time argument reaches the derivative."""
    return np.array([amplitude * np.cos(t)])


_oscillator_rk4 = rk4_integrator(_oscillator_rate)
_spin_rk4 = rk4_integrator(_spin_rate, 0)
_forced_rk4 = rk4_integrator(_forced_rate)


@njit(cache=True)
def _oscillator(omega, x0, t0, times, max_step):
    return _oscillator_rk4((omega,), x0, t0, times, max_step)


def _spin(omega_body, q0, times, max_step):
    return _spin_rk4((omega_body,), q0, 0.0, times, max_step)      # called from Python as well


@njit(cache=True)
def _forced(amplitude, t0, times, max_step):
    return _forced_rk4((amplitude,), np.zeros(1), t0, times, max_step)


def test_rk4_is_fourth_order_on_the_harmonic_oscillator():
    # x(t) = cos(omega t) from x(0) = 1, x'(0) = 0; the global error of RK4 scales as h^4, so halving
    # the step divides it by 2^4 = 16 (asymptotically; 15 to 17 at these steps, omega h <= 0.2)
    omega, times = 2.0, np.linspace(0.0, 10.0, 11)
    errors = []
    for step in (0.1, 0.05, 0.025):
        states = _oscillator(omega, np.array([1.0, 0.0]), 0.0, times, step)
        errors.append(np.abs(states[:, 0] - np.cos(omega * times)).max())
    # RK4's phase error on the oscillator: omega t (omega h)^4 / 120 = 2 x 10 x 0.2^4 / 120 = 2.7e-4
    assert errors[0] < 3e-4
    for coarse, fine in zip(errors, errors[1:]):
        assert 15.0 < coarse / fine < 17.0


def test_rk4_outputs_start_at_t0_and_use_the_time_argument():
    # x' = a cos t from x(t0) = 0: x(t) = a (sin t - sin t0); the first output at t0 is x0 itself,
    # a repeated output time takes no step
    times = np.array([1.0, 1.0, 2.5, 4.0])
    states = _forced(3.0, 1.0, times, 0.01)
    assert states[0, 0] == 0.0 and states[1, 0] == 0.0
    assert np.allclose(states[:, 0], 3.0 * (np.sin(times) - np.sin(1.0)), atol=1e-9)


def test_rk4_keeps_the_quaternion_unit_and_on_the_analytic_spin():
    # constant spin omega about a unit axis n: q(t) = [cos(|omega| t / 2), sin(|omega| t / 2) n]
    omega_body = np.array([0.3, -0.2, 0.5])
    rate, axis = np.linalg.norm(omega_body), omega_body / np.linalg.norm(omega_body)
    times = np.linspace(0.0, 60.0, 61)
    qs = _spin(omega_body, np.array([1.0, 0.0, 0.0, 0.0]), times, 0.05)
    assert np.abs(np.linalg.norm(qs, axis=1) - 1.0).max() < 1e-15 * 4
    exact = np.column_stack([np.cos(0.5 * rate * times), np.sin(0.5 * rate * times)[:, None] * axis])
    # RK4 phase error ~ (|omega| h / 2)^4 / 120 per step over 1200 steps: about 1e-10
    assert np.abs(qs - exact).max() < 1e-8


def test_one_integrator_per_derivative_and_quaternion_index():
    # rk4_integrator binds the derivative into the compiled loop once; asked again, it gives the same one
    assert rk4_integrator(_spin_rate, 0) is _spin_rk4
    assert rk4_integrator(_spin_rate, -1) is not _spin_rk4
