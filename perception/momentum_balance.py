"""The momentum step of the collision (Tang et al. 2023, Sec. 3.3): the debris' mass from the linear
momentum balance and its smallest principal moment C from the angular one, each with its covariance,
from the free-flight fits before and after (:mod:`perception.free_flight`) and the momentum of the
chaser and net (all in world components, angular momenta about a stated origin)."""
from __future__ import annotations

import numpy as np

from perception.free_flight import FreeMotion
from perception.momentum import mass_from_linear_momentum, smallest_moment_from_angular_momentum


def _skew(v) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _line_covariances(line) -> tuple[np.ndarray, np.ndarray]:
    """Covariances (3, 3) of the fitted CoM position at time0 and of the CoM velocity."""
    c = line.covariance
    return (c[3:6, 3:6], c[6:9, 6:9]) if c.shape[0] == 9 else (c[:3, :3], c[3:6, 3:6])


def _orbital_per_mass(line, origin) -> tuple[np.ndarray, np.ndarray]:
    """(p - O) x v of a CoM line (constant along it) and its covariance, first order."""
    p = line.position0_world - origin
    v = line.velocity_world
    cov_p, cov_v = _line_covariances(line)
    return np.cross(p, v), _skew(v) @ cov_p @ _skew(v).T + _skew(p) @ cov_v @ _skew(p).T


def _mean_and_covariance_of_mean(samples) -> tuple[np.ndarray, np.ndarray]:
    samples = np.asarray(samples)
    return samples.mean(axis=0), np.cov(samples.T) / len(samples)


def momentum_step(before: FreeMotion, after: FreeMotion, others_before, others_after, origin) -> dict:
    """Mass and smallest principal moment C from the two momentum balances of the collision
    (see :mod:`perception.momentum`).

    Parameters
    ----------
    before, after : FreeMotion
        Free-flight fits of the debris before and after the collision (world frame).
    others_before : tuple of two (3,) float arrays
        Linear (kg m/s) and angular (kg m^2/s, about ``origin``) momentum of the chaser and net before,
        world components.
    others_after : tuple of two (k, 3) float arrays
        The same at each of the k free-flight frames after the collision.
    origin : (3,) float array
        Point the angular momenta are taken about (m, world).

    Returns
    -------
    dict
        ``mass`` and ``c``: estimates with their standard deviations (:mod:`perception.momentum`).
    """
    p_before, l_before = others_before
    p_after, cov_p_after = _mean_and_covariance_of_mean(others_after[0])
    l_after, cov_l_after = _mean_and_covariance_of_mean(others_after[1])
    cov_v = _line_covariances(before.line)[1] + _line_covariances(after.line)[1]
    mass = mass_from_linear_momentum(after.line.velocity_world - before.line.velocity_world,
                                     p_after - p_before, cov_v, cov_p_after)
    orbital0, cov0 = _orbital_per_mass(before.line, origin)
    orbital1, cov1 = _orbital_per_mass(after.line, origin)
    c = smallest_moment_from_angular_momentum(
        after.spin_per_c - before.spin_per_c, orbital1 - orbital0, mass.value, l_after - l_before,
        before.spin_per_c_cov + after.spin_per_c_cov, cov0 + cov1, mass.sigma, cov_l_after)
    return {"mass": mass, "c": c}
