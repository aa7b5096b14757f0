"""The collision's momentum step (perception/momentum_balance.py) on an exact, noise-free exchange:
linear and angular momentum are conserved, so the balances must return the debris' mass and its
smallest principal moment C exactly (Tang et al. 2023, eqs. 23-24)."""
from types import SimpleNamespace

import numpy as np

from perception.momentum_balance import momentum_step


def _motion(position0, velocity, spin_per_c):
    line = SimpleNamespace(position0_world=np.asarray(position0, float), velocity_world=np.asarray(velocity, float),
                           covariance=np.eye(6) * 1e-8)
    return SimpleNamespace(line=line, spin_per_c=np.asarray(spin_per_c, float), spin_per_c_cov=np.eye(3) * 1e-10)


def test_momentum_step_recovers_mass_and_smallest_moment_of_an_exact_exchange():
    mass, c = 7800.0, 17000.0                        # kg, kg m^2: an Envisat-like body
    origin = np.array([1.0, -2.0, 0.5])              # m, world: any point; both balances use it
    p0, v0, h0 = np.array([3.0, 0.0, 1.0]), np.array([0.01, -0.02, 0.0]), np.array([0.02, 0.01, -0.03])
    p1, v1, h1 = np.array([3.1, 0.2, 1.0]), np.array([0.03, 0.05, -0.01]), np.array([0.025, 0.0, -0.02])
    before, after = _motion(p0, v0, h0), _motion(p1, v1, h1)
    # the chaser and net lose exactly what the debris gains (momentum about ``origin`` conserved)
    debris_linear = mass * (v1 - v0)
    debris_angular = mass * (np.cross(p1 - origin, v1) - np.cross(p0 - origin, v0)) + c * (h1 - h0)
    others_before = (np.array([5.0, 1.0, 0.0]), np.array([0.0, 2.0, 1.0]))
    after_linear = others_before[0] - debris_linear
    after_angular = others_before[1] - debris_angular
    others_after = (np.tile(after_linear, (12, 1)), np.tile(after_angular, (12, 1)))
    step = momentum_step(before, after, others_before, others_after, origin)
    # exact data: only round-off separates the estimates from the truth
    assert abs(step["mass"].value / mass - 1.0) < 1e-9
    assert abs(step["c"].value / c - 1.0) < 1e-9
