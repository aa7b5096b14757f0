"""Rates and centre of mass from a registered pose sequence (Tang et al. 2023, Sec. 3.1).

The paper takes rates and accelerations from central differences of the poses (its eqs. 9-10)
and the CoM from intersecting spheres around feature points (eqs. 14-16). Here:

* rates and accelerations come from local quadratic fits of the rotation over a sliding
  window (a Savitzky-Golay filter on the rotation group), which smooths the ~1 deg frame-to-
  frame registration noise instead of differencing it;
* the CoM is the one body-fixed point that moves on a straight line: with body->world poses
  (R_k, t_k), ``R_k c_B + t_k = p_0 + v (t_k - t_0)`` is linear in (c_B, p_0, v) and solved by
  least squares over all frames. It is observable only if the body turns.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation


class NotObservable(ValueError):
    """The data cannot determine the quantity asked for (the message says why)."""


def rates_from_attitudes(times, body_to_world: Rotation, half_window: int = 5):
    """Angular velocity (k, 3) (rad/s) and acceleration (k, 3) (rad/s^2), body frame, from a
    quadratic fit of log(R_k^-1 R_j) against (t_j - t_k) over the 2 half_window + 1 frames
    around each frame (fewer at the ends).

    Parameters
    ----------
    times : (k,) float
        Frame times (s), increasing.
    body_to_world : Rotation (k,)
        Attitudes B->world at ``times``.
    half_window : int
        Frames on each side of a frame in its local fit.

    Returns
    -------
    omega_body : (k, 3) float
        Angular velocity (rad/s, body frame B).
    omega_dot_body : (k, 3) float
        Angular acceleration (rad/s^2, body frame B).
    """
    times = np.asarray(times, float)
    k = len(times)
    omega = np.zeros((k, 3))
    omega_dot = np.zeros((k, 3))
    for i in range(k):
        lo, hi = max(0, i - half_window), min(k, i + half_window + 1)
        dt = times[lo:hi] - times[i]
        local = (body_to_world[i].inv() * body_to_world[lo:hi]).as_rotvec()   # body frame at i
        basis = np.vander(dt, 3, increasing=True)
        coefficients, *_ = np.linalg.lstsq(basis, local, rcond=None)
        omega[i] = coefficients[1]
        omega_dot[i] = 2.0 * coefficients[2]
    return omega, omega_dot


@dataclass
class CenterOfMassLine:
    """CoM of a freely moving body from its poses.

    Attributes: ``com_body`` (3,) CoM in the model frame B (m); ``position0_world`` (3,) at
    ``time0`` (m); ``velocity_world`` (3,) (m/s); ``residual_rms`` (m); ``covariance`` (9, 9).
    """

    com_body: np.ndarray
    position0_world: np.ndarray
    velocity_world: np.ndarray
    time0: float
    residual_rms: float
    covariance: np.ndarray

    def position_world(self, times) -> np.ndarray:
        """CoM positions (k, 3) (m, world frame) on the fitted line.

        Parameters
        ----------
        times : (k,) float
            Times (s), on the clock of ``time0``.
        """
        return self.position0_world + np.outer(np.asarray(times) - self.time0, self.velocity_world)


def center_of_mass_line(times, body_to_world, origin_world, com_body=None) -> CenterOfMassLine:
    """Fit ``R_k c_B + t_k = p_0 + v (t_k - t_0)``; with ``com_body`` given, only p_0 and v.

    Parameters
    ----------
    times : (k,) float             (s)
    body_to_world : (k, 3, 3)      Attitudes B->world.
    origin_world : (k, 3) float    Position of B's origin, world frame (m).
    com_body : (3,) float, optional  Known CoM (m, frame B); None: estimated (the body must turn).

    Returns
    -------
    CenterOfMassLine
        ``time0`` = ``times[0]``; ``covariance`` (9, 9) over (c_B, p_0, v), or (6, 6) over
        (p_0, v) with ``com_body`` given.
    """
    times = np.asarray(times, float)
    rot = np.asarray(body_to_world, float)
    origin = np.asarray(origin_world, float)
    k = len(times)
    eye = np.tile(np.eye(3), (k, 1, 1))
    tau = (times - times[0])[:, None, None] * eye
    if com_body is None:
        # The largest turn of the mean attitude of 5-frame blocks from the first block's: the
        # registration noise (degrees per frame) averages out, a real turn does not.
        blocks = [Rotation.from_matrix(rot[i:i + 5]).mean() for i in range(0, k, 5)]
        turn = np.degrees(max((blocks[0].inv() * b).magnitude() for b in blocks))
        if turn < 5.0:
            raise NotObservable(f"the CoM needs the body to turn; it turned only {turn:.2f} deg over the frames")
        design = np.concatenate([rot, -eye, -tau], axis=2).reshape(3 * k, 9)
        rhs = -origin.reshape(-1)
    else:
        design = np.concatenate([-eye, -tau], axis=2).reshape(3 * k, 6)
        rhs = -(origin + rot @ np.asarray(com_body, float)).reshape(-1)
    solution, *_ = np.linalg.lstsq(design, rhs, rcond=None)
    residual = design @ solution - rhs
    dof = max(len(rhs) - len(solution), 1)
    rms = float(np.sqrt(residual @ residual / dof))
    correlation = integrated_autocorrelation_time(residual.reshape(k, 3))
    covariance = np.linalg.pinv(design.T @ design) * rms**2 * correlation
    if com_body is None:
        return CenterOfMassLine(solution[:3], solution[3:6], solution[6:9], times[0], rms, covariance)
    return CenterOfMassLine(np.asarray(com_body, float), solution[:3], solution[3:6], times[0], rms, covariance)


def integrated_autocorrelation_time(residuals) -> float:
    """Integrated autocorrelation time tau (frames, >= 1) of a residual series (k, d), pooled
    over its d components: tau = 1 + 2 sum_lag rho(lag), summed while rho stays positive
    (Geyer's initial positive sequence, truncated at the first non-positive lag).

    Registration errors of successive scans are correlated (the same view gives the same bias
    for a while); a least-squares covariance that assumes white errors is then too small by
    about tau, the number of frames that carry one independent error (variance of a mean of k
    correlated samples = sigma^2 tau / k).

    Parameters
    ----------
    residuals : (k, d) float
        Residuals in frame order, any unit (d components, pooled; one row per frame).

    Returns
    -------
    float
        tau (frames, >= 1).
    """
    r = np.asarray(residuals, float)
    r = (r - r.mean(axis=0)).reshape(len(r), -1)
    variance = np.sum(r * r)
    if variance == 0.0:
        return 1.0
    tau = 1.0
    for lag in range(1, len(r) // 4):
        rho = np.sum(r[:-lag] * r[lag:]) / variance
        if rho <= 0.0:
            break
        tau += 2.0 * rho
    return float(tau)


def attitude_sqrt_information(informations) -> np.ndarray:
    """Square roots W (k, 3, 3) (1/rad) of the attitude information of k registrations, from their
    (6, 6) pose information (rotation first): the rotation block of the covariance, the
    translation marginalized out, so that |W e|^2 is the attitude error's chi^2. A frame whose
    information is singular (too few or degenerate points) gets the mean of the others.

    Parameters
    ----------
    informations : sequence of k (6, 6) float
        Pose information of each registration over (rotation vector, translation), left
        perturbation, body frame B (1/rad^2, 1/(rad m), 1/m^2), e.g. ``Alignment.information``.

    Returns
    -------
    (k, 3, 3) float
        Upper-triangular W with W^T W the attitude information (1/rad, body frame B).
    """
    weights = np.full((len(informations), 3, 3), np.nan)
    for k, information in enumerate(informations):
        if np.linalg.matrix_rank(information) == 6:
            attitude_covariance = np.linalg.inv(information)[:3, :3]
            weights[k] = np.linalg.cholesky(np.linalg.inv(attitude_covariance)).T
    bad = np.isnan(weights[:, 0, 0])
    if bad.all():
        raise NotObservable("no registration carried attitude information (all scans degenerate)")
    weights[bad] = np.mean(weights[~bad], axis=0)
    return weights


def isotropic_attitude_weights(sqrt_information) -> np.ndarray:
    """Per-frame isotropic weights (k, 3, 3) s_k I (1/rad) from the attitude information square
    roots W_k (k, 3, 3): s_k = |det W_k|^(1/3), the geometric mean of the frame's precisions.

    The point-to-plane information only knows the range noise. It rates the rotations about the
    long axes of a near-symmetric body as 5 times better known than the rotation about the
    symmetry axis, but the registration's view-dependent errors are of a similar size on all
    axes. Weighting by the anisotropic information then lets those errors bias the fitted motion:
    on Tang et al.'s ellipsoid the angular momentum direction came out 0.27 deg off, against
    0.03-0.1 deg with isotropic weights (60 s of 10 Hz scans, seeds 0 and 1). A frame's overall
    quality (how many points, how much of the surface) is kept.

    Parameters
    ----------
    sqrt_information : (k, 3, 3) float
        Attitude information square roots (1/rad, body frame B), from
        :func:`attitude_sqrt_information`.

    Returns
    -------
    (k, 3, 3) float
        s_k I (1/rad); isotropic, so the same in any frame.
    """
    w = np.asarray(sqrt_information, float)
    scale = np.abs(np.linalg.det(w)) ** (1.0 / 3.0)
    return scale[:, None, None] * np.eye(3)
