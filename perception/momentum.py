"""True mass and principal moments of the debris from momentum conservation across the net
collision (Tang et al. 2023, Sec. 3.2, eqs. 23-24).

Chaser + net + debris form a closed system over the short collision, so with every momentum
about one fixed point O of the inertial (world) frame W:

* linear (eq. 23):  ``m_deb (v1 - v0) = -(Delta P_chaser + Delta P_net)``;
* angular (eq. 24): ``m_deb Delta(p x v) + C (h1 - h0) = -(Delta L_chaser + Delta L_net)``,

where ``v0, v1`` are the debris CoM velocities before and after, ``p`` its CoM, and
``h = R_T->W diag(A/C, B/C, 1) omega_T`` its spin angular momentum per unit C: the torque-free
fits before and after give ``h`` (the normalized inertia is known from before the collision),
so each balance is linear in its one unknown (``m_deb``, then ``C``) and is solved by least
squares over its three components weighted by their covariance (the debris' orbital term after the
collision is known along its flight direction, not across it). Uncertainties are first-order
propagations of the inputs' covariances, widened when the balance's weighted misfit is beyond chance.

Everything here is a pure function of SI arrays in the world frame W.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from perception.motion import NotObservable

#: A momentum change smaller than this many standard deviations of its own uncertainty carries
#: no information on the unknown: the answer is "not observable" rather than a noisy number.
MIN_SIGNIFICANCE = 5.0


def point_masses_momentum(masses, positions_world, velocities_world, origin_world=(0.0, 0.0, 0.0)):
    """Linear (3,) (N s) and angular (3,) (N m s, about ``origin_world``) momentum of point masses
    (n,) (kg) at positions (n, 3) (m) moving at velocities (n, 3) (m/s), world frame.

    Parameters
    ----------
    masses : (n,) float
        Point masses (kg).
    positions_world : (n, 3) float
        Their positions (m, world frame).
    velocities_world : (n, 3) float
        Their velocities (m/s, world frame).
    origin_world : (3,) float
        Point the angular momentum is taken about (m, world frame).

    Returns
    -------
    linear : (3,) float
        Linear momentum (N s, world frame).
    angular : (3,) float
        Angular momentum about ``origin_world`` (N m s, world frame).
    """
    masses = np.asarray(masses, float)
    p = masses[:, None] * np.asarray(velocities_world, float)
    arms = np.asarray(positions_world, float) - np.asarray(origin_world, float)
    return p.sum(axis=0), np.cross(arms, p).sum(axis=0)


def rigid_body_momentum(mass, inertia_body, com_world, velocity_world, body_to_world, omega_body,
                        origin_world=(0.0, 0.0, 0.0)):
    """Linear (3,) and angular (3,) momentum (about ``origin_world``) of a rigid body, world frame.

    Parameters
    ----------
    mass : float
        Body mass (kg).
    inertia_body : (3, 3) float
        Inertia about the CoM (kg m^2, body frame).
    com_world : (3,) float
        CoM position (m, world frame).
    velocity_world : (3,) float
        CoM velocity (m/s, world frame).
    body_to_world : (3, 3) float
        Attitude, rotation body -> world.
    omega_body : (3,) float
        Angular velocity (rad/s, body frame).
    origin_world : (3,) float
        Point the angular momentum is taken about (m, world frame).

    Returns
    -------
    linear : (3,) float
        Linear momentum (N s, world frame).
    angular : (3,) float
        Angular momentum about ``origin_world`` (N m s, world frame): orbital plus spin.
    """
    linear = mass * np.asarray(velocity_world, float)
    spin = np.asarray(body_to_world, float) @ (np.asarray(inertia_body, float) @ np.asarray(omega_body, float))
    return linear, np.cross(np.asarray(com_world, float) - np.asarray(origin_world, float), linear) + spin


@dataclass(frozen=True)
class Estimate:
    """A scalar estimate with its 1-sigma uncertainty, the misfit of the three-component balance it
    came from (same unit as the balance) and that misfit weighted by the balance's covariance
    (chi-square, 2 degrees of freedom: three components, one unknown)."""

    value: float
    sigma: float
    misfit: float
    chi2: float = float("nan")


#: Weighting iterations of the balance's least squares (the weight depends on the estimate through
#: the direction's covariance): the estimate settles to 1e-12 relative within 3-4 on the runs measured.
GLS_ITERATIONS = 8


#: A weighted misfit of the three-component balance above this (its expectation: chi-square with 2 degrees of
#: freedom) says its covariances do not cover the disagreement, and the 1-sigma is scaled up by
#: sqrt(chi2 / 2) (the Particle Data Group's scale factor S = sqrt(chi2 / (N - 1)) applied for S > 1; PDG,
#: Review of Particle Physics, Introduction, Sec. 5.2.2). It was 9.21 (the 1 % tail) until the model-free
#: featured debris' runs showed the angular balance's chi2 at 4.1-19.5 on all 9 runs of 2026-11-27 (median
#: 10.5, against 1.4 with right covariances), and seed 3's C 3.0 of its unscaled 1-sigma off (chi2 6.4;
#: docs/perception.md, "The re-acquisition's candidates"). Cost with right covariances: the mean 1-sigma
#: is E[max(1, sqrt(chi2 / 2))] = 1 - 1/e + Gamma(3/2, 1) = 1.139 times the scatter.
MISFIT_CHI2 = 2.0


def _total_covariance(cov_direction, cov_target, x) -> np.ndarray:
    """Covariance (3, 3) of the balance's residual b - x d for errors in both d and b, floored at 1e-12
    of its largest eigenvalue so that an exactly known component does not make it singular."""
    total = np.asarray(cov_target, float) + x**2 * np.asarray(cov_direction, float)
    largest = float(np.max(np.linalg.eigvalsh(total))) if np.any(total) else 0.0
    return total + 1e-12 * max(largest, 1e-300) * np.eye(3)


def _scalar_least_squares(direction, target, cov_direction, cov_target, name, unit):
    """x minimizing the residual b - x d of a three-component balance weighted by its covariance
    (generalized least squares), with its first-order uncertainty.

    The three components are not equally well known. In the angular balance the debris' orbital term
    m (p x v) after the collision is uncertain across the flight direction (the CoM line's lateral
    position, 2-5 cm at 15-30 m from a model-free map) and exact along it ((p x v).v = 0): weighted by
    the covariance, the balance takes C from what is known, and its 1-sigma says what that is
    (docs/perception.md, "Model-free moments"). With equal, isotropic covariances this is the ordinary
    least squares x = d.b / |d|^2.

    The weight W = (cov_b + x^2 cov_d)^-1 depends on x: iterated from the ordinary solution. With W
    held, x = d'Wb / d'Wd, so dx/db = W d / d'Wd and dx/dd = (W b - 2 x W d) / d'Wd, propagated with
    the two covariances. When the weighted misfit exceeds its expectation (chi-square over its 2 degrees
    of freedom above 1, :data:`MISFIT_CHI2`), the components disagree more than their covariances allow,
    and the variance is scaled by that ratio (never shrunk).
    """
    d = np.asarray(direction, float)
    b = np.asarray(target, float)
    cov_d, cov_b = np.asarray(cov_direction, float), np.asarray(cov_target, float)
    norm2 = float(d @ d)
    sigma_d = float(np.sqrt(max(np.trace(cov_d), 0.0)))
    sigma_b = float(np.sqrt(max(np.trace(cov_b), 0.0)))
    if np.linalg.norm(b) == 0.0 or np.linalg.norm(b) < MIN_SIGNIFICANCE * sigma_b:
        raise NotObservable(f"the collision transferred {np.linalg.norm(b):.3g} of momentum, not significant "
                            f"against its uncertainty {sigma_b:.3g}")
    if norm2 == 0.0 or np.sqrt(norm2) < MIN_SIGNIFICANCE * sigma_d:
        raise NotObservable(f"the collision changed the debris {name} by {np.sqrt(norm2):.3g} {unit}, "
                            f"not significant against its uncertainty {sigma_d:.3g} {unit}")
    x = float(d @ b) / norm2
    weight = np.eye(3)
    if np.any(cov_b) or np.any(cov_d):
        for _ in range(GLS_ITERATIONS):
            weight = np.linalg.inv(_total_covariance(cov_d, cov_b, x))
            x = float(d @ weight @ b) / float(d @ weight @ d)
    information = float(d @ weight @ d)
    g_b = weight @ d / information
    g_d = (weight @ b - 2.0 * x * weight @ d) / information
    variance = g_b @ cov_b @ g_b + g_d @ cov_d @ g_d
    residual = b - x * d
    misfit = float(np.linalg.norm(residual))
    chi2 = float(residual @ weight @ residual) if np.any(cov_b) or np.any(cov_d) else float("nan")
    if chi2 > MISFIT_CHI2:
        variance *= chi2 / 2.0
    return x, float(np.sqrt(max(variance, 0.0))), misfit, chi2


def mass_from_linear_momentum(velocity_change_world, others_momentum_change_world,
                              cov_velocity_change=None, cov_others_change=None) -> Estimate:
    """Debris mass (kg) from ``m (v1 - v0) = -Delta P_others`` (Tang et al. 2023, eq. 23).

    Parameters
    ----------
    velocity_change_world : (3,)      v1 - v0 of the debris CoM (m/s, world frame).
    others_momentum_change_world : (3,)  Change of chaser + net linear momentum (N s, world frame).
    cov_velocity_change : (3, 3)      Covariance of ``velocity_change_world`` ((m/s)^2), zero if omitted.
    cov_others_change : (3, 3)        Covariance of ``others_momentum_change_world`` ((N s)^2), zero if omitted.
    """
    zero = np.zeros((3, 3))
    mass, sigma, misfit, chi2 = _scalar_least_squares(
        velocity_change_world, -np.asarray(others_momentum_change_world, float),
        zero if cov_velocity_change is None else cov_velocity_change,
        zero if cov_others_change is None else cov_others_change, "velocity", "m/s")
    if mass <= 0.0:
        raise NotObservable(f"the linear momentum balance gives a non-positive mass ({mass:.3g} kg): "
                            "the debris velocity change and the momentum the chaser and net lost disagree")
    return Estimate(mass, sigma, misfit, chi2)


def spin_momentum_per_c(normalized_moments, principal_to_world, omega_principal) -> np.ndarray:
    """h = R_T->W diag(A/C, B/C, 1) omega_T (rad/s), world frame: the debris spin angular
    momentum divided by its smallest principal moment C.

    Parameters
    ----------
    normalized_moments : (3,) float
        [A/C, B/C, 1] (-).
    principal_to_world : (3, 3) float
        Rotation principal frame T -> world W.
    omega_principal : (3,) float
        Angular velocity (rad/s, principal frame T).

    Returns
    -------
    (3,) float
        h (rad/s, world frame).
    """
    return np.asarray(principal_to_world, float) @ (np.asarray(normalized_moments, float)
                                                     * np.asarray(omega_principal, float))


def smallest_moment_from_angular_momentum(spin_change_per_c, orbital_change_per_mass, mass,
                                          others_angular_change, cov_spin_change=None,
                                          cov_orbital_change_per_mass=None, mass_sigma=0.0,
                                          cov_others_change=None) -> Estimate:
    """C (kg m^2) from ``m Delta(p x v) + C Delta h = -Delta L_others`` (Tang et al. 2023, eq. 24).

    Parameters
    ----------
    spin_change_per_c : (3,)       h1 - h0 (rad/s, world frame), see :func:`spin_momentum_per_c`.
    orbital_change_per_mass : (3,)  Delta (p x v) of the debris CoM about O (m^2/s, world frame).
    mass, mass_sigma : float       Debris mass and its 1 sigma (kg), from the linear balance.
    others_angular_change : (3,)   Change of chaser + net angular momentum about O (N m s, world frame).
    cov_spin_change : (3, 3)       Covariance of ``spin_change_per_c`` ((rad/s)^2), zero if omitted.
    cov_orbital_change_per_mass : (3, 3)  Covariance of ``orbital_change_per_mass`` ((m^2/s)^2), zero if omitted.
    cov_others_change : (3, 3)     Covariance of ``others_angular_change`` ((N m s)^2), zero if omitted.
    """
    zero = np.zeros((3, 3))
    orbital = np.asarray(orbital_change_per_mass, float)
    target = -np.asarray(others_angular_change, float) - mass * orbital
    cov_target = (zero if cov_others_change is None else np.asarray(cov_others_change))
    cov_target = cov_target + mass**2 * (zero if cov_orbital_change_per_mass is None
                                         else np.asarray(cov_orbital_change_per_mass))
    cov_target = cov_target + mass_sigma**2 * np.outer(orbital, orbital)
    c, sigma, misfit, chi2 = _scalar_least_squares(spin_change_per_c, target,
                                             zero if cov_spin_change is None else cov_spin_change,
                                             cov_target, "spin", "rad/s")
    if c <= 0.0:
        raise NotObservable(f"the angular momentum balance gives a non-positive moment ({c:.3g} kg m^2)")
    return Estimate(c, sigma, misfit, chi2)
