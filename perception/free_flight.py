"""One free-flight stretch of a tracked debris: its CoM line and torque-free attitude fit from the
registered frames, the spin angular momentum per smallest moment C, and the normalized energy and
momentum of Tang et al. 2023 (eqs. 20-22). Frames: world (the LVLH the scans are registered in), body
(the tracker's model frame), principal."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from perception.euler_poinsot import TorqueFreeFit, normalized_inertia_linear, principal_frame
from perception.motion import (NotObservable, attitude_sqrt_information, center_of_mass_line, isotropic_attitude_weights,
                               rates_from_attitudes)

#: Fewest registered free-flight frames after the collision for the momentum step.
MIN_FRAMES_AFTER = 10
#: A torque-free fit that leaves the registered attitudes more than this RMS turn (deg) from the fitted
#: ones has stopped in a wrong optimum (a right one leaves the frames' own error: 0.4-2.2 deg measured,
#: docs/perception.md); it is redone from other starting rates and the best fit kept. The stage refuses
#: a fit still beyond this (riskassess/stages/perceive.py, MAX_MODEL_FREE_RESIDUAL_DEG is this constant).
RESTART_RESIDUAL_DEG = 5.0
#: Frames whose rates give the other starting rates (the local-fit window of rates_from_attitudes).
START_WINDOW = 11


@dataclass
class FreeMotion:
    """Fits of one free-flight stretch: CoM line, torque-free motion, spin momentum per C."""

    times: np.ndarray
    line: object
    fit: TorqueFreeFit
    spin_per_c: np.ndarray
    spin_per_c_cov: np.ndarray
    attitude_residual_deg: float = float("nan")   # RMS turn between registered and fitted attitudes (deg)


#: A frame whose weighted attitude residual |W e|^2, over the median frame's, exceeds this is
#: dropped and the fit redone. It removes poses that passed the check but are wrong (during and
#: right after the collision) and frames still touched by the net. The errors are far from
#: isotropic (mostly about a near-symmetry axis), so the bound is that of one dominant axis:
#: chi^2 with 1 dof, 0.1 % tail over median = 10.83 / 0.455.
OUTLIER_OVER_MEDIAN = 23.8


def fit_free_motion(tracker, indices, times, com_body=None, moments=None, principal_to_body=None,
                    attitude_covariance=None) -> FreeMotion:
    """CoM line and torque-free fit through the registered frames ``indices``; inertia shape
    estimated (before the collision) or known (after). Frames the fitted motion does not explain
    (weighted residual above :data:`OUTLIER_OVER_MEDIAN` times the median) are dropped and the fit redone,
    starting from the fit before. A fit that leaves the frames more than :data:`RESTART_RESIDUAL_DEG`
    rms is redone from other starting rates (:func:`start_rates`) and the best kept.

    Parameters
    ----------
    tracker : perception.registration.DebrisTracker
        The tracker whose ``alignments`` hold each frame's body -> world pose and information matrix.
    indices : sequence of int
        Frames of the free-flight stretch.
    times : (n,) float array
        Time of every frame (s).
    com_body : (3,) float array, optional
        The CoM in the body (model) frame (m) when known; fitted otherwise.
    moments, principal_to_body : (3,) and (3, 3) float arrays, optional
        Normalized principal moments (-) and principal -> body rotation when known (after the
        collision); estimated from the rates otherwise.
    attitude_covariance : callable, optional
        indices (n,) -> (3n, 3n) covariance (rad^2, body-side, frame B) of the frames' attitude errors that are
        correlated from frame to frame (e.g. :meth:`perception.scan_to_scan.ReposedFrames.attitude_covariance`),
        added to the fit's own (:meth:`perception.euler_poinsot.TorqueFreeFit.add_attitude_covariance`).

    Returns
    -------
    FreeMotion
    """
    indices = np.asarray(indices)
    previous = None
    for _ in range(5):
        motion, chi2 = _fit_free_motion_once(tracker, indices, times, com_body, moments, principal_to_body, previous,
                                             attitude_covariance)
        keep = chi2 <= OUTLIER_OVER_MEDIAN * np.median(chi2)
        if keep.all():
            break
        indices = indices[keep]
        # The refit starts from this fit: the same motion through a few frames less. Started afresh
        # (rates and ratios from the thinned frames), the refit of the featured debris with its mast and
        # mesh (bench_model_check.py intact, seed 1: frames 5-12 dropped from a fit 0.23 deg rms from
        # the frames) stopped 96 deg rms off, ratios at their bound 2.
        previous = motion.fit
    return motion


def _fit_free_motion_once(tracker, indices, times, com_body, moments, principal_to_body, previous=None,
                          attitude_covariance=None):
    if len(indices) < MIN_FRAMES_AFTER:
        raise NotObservable(f"only {len(indices)} registered frames of free flight; at least {MIN_FRAMES_AFTER} "
                            "are needed")
    poses = np.array([tracker.alignments[i].body_to_world for i in indices])
    t = np.asarray(times)[indices]
    line = center_of_mass_line(t, poses[:, :3, :3], poses[:, :3, 3], com_body)
    attitudes = Rotation.from_matrix(poses[:, :3, :3])
    omega, omega_dot = rates_from_attitudes(t, attitudes)
    weights = isotropic_attitude_weights(attitude_sqrt_information([tracker.alignments[i].information for i in indices]))
    if moments is None:
        moments0, axes0 = principal_frame(normalized_inertia_linear(omega, omega_dot))
        starts = [(rate, moments0, axes0) for rate in start_rates(omega)]
        if previous is not None:
            starts.insert(0, (previous.rate_body_at(t[0]), previous.moments_, previous.principal_to_body_))
        fits = (TorqueFreeFit().fit(t, attitudes, weights, *start) for start in starts)
    else:
        rates = list(start_rates(omega))
        if previous is not None:
            rates.insert(0, previous.rate_body_at(t[0]))
        fits = (TorqueFreeFit(moments, principal_to_body).fit(t, attitudes, weights, rate) for rate in rates)
    fit, error = _best_fit(fits, t, attitudes)
    chi2 = np.sum(np.einsum("kij,kj->ki", weights, error) ** 2, axis=1)
    if attitude_covariance is not None:
        fit.add_attitude_covariance(attitude_covariance(indices))
    h, h_cov = fit.spin_momentum_per_c()
    return FreeMotion(t, line, fit, h, h_cov, _rms_deg(error)), chi2


def start_rates(omega_body):
    """Starting rates of the torque-free fit at the first frame (rad/s, body frame B), in the order
    tried: the first frame's local rate, then the component-wise median of the first
    :data:`START_WINDOW` frames' rates and the rate of the frame in the middle of them.

    The first frame's local fit is one-sided, so one bad first frame throws its rate off: on the
    paper case (seed 0) the first frame after the collision was registered 9.8 deg off, its rate came
    out (0.84, -0.73, 2.03) rad/s against the true (0.89, -0.77, 0.52), and the fit from it stopped
    96 deg rms from the frames; from the median it ends 2.1 deg rms from them. The body rate turns
    slowly over the window (0.05 rad/s in 0.5 s there), well within the fit's reach.

    Parameters
    ----------
    omega_body : (k, 3) float
        Local rates of the frames (rad/s, body frame), :func:`perception.motion.rates_from_attitudes`.

    Returns
    -------
    iterator of (3,) float
        The starting rates (rad/s, body frame).
    """
    yield omega_body[0]
    window = omega_body[:START_WINDOW]
    yield np.median(window, axis=0)
    yield window[len(window) // 2]


def _rms_deg(error) -> float:
    """RMS turn (deg) of attitude errors given as rotation vectors (k, 3) (rad)."""
    return float(np.degrees(np.sqrt(np.mean(np.sum(error**2, axis=1)))))


def _best_fit(fits, times, attitudes):
    """The first fit within :data:`RESTART_RESIDUAL_DEG` of the attitudes, else the one of least cost
    (weighted RMS) over all starts; with its attitude errors (k, 3) (rad, rotation vectors)."""
    best = None
    for fit in fits:
        error = (attitudes.inv() * fit.predict_body_to_world(times)).as_rotvec()
        if _rms_deg(error) <= RESTART_RESIDUAL_DEG:
            return fit, error
        if best is None or fit.residual_rms_ < best[0].residual_rms_:
            best = fit, error
    return best


def normalized_energy_and_momentum(motion: FreeMotion) -> dict:
    """D = 2E/C, F = L^2/C^2 and the angular momentum direction (world) of a torque-free fit
    (Tang et al. 2023, eqs. 20-22).

    Parameters
    ----------
    motion : FreeMotion
        A free-flight fit (:func:`fit_free_motion`); its torque-free fit gives the normalized
        principal moments (J1, J2, 1) (-, per smallest moment C) and the principal-frame rate
        (rad/s), its ``spin_per_c`` the spin momentum per C (3,) (rad/s, world frame).

    Returns
    -------
    dict
        ``"D"`` : float, 2E/C (rad^2/s^2); ``"F"`` : float, L^2/C^2 (rad^2/s^2);
        ``"direction_world"`` : (3,) float, unit angular momentum direction, world frame (-).
    """
    moments, omega = motion.fit.moments_, motion.fit.omega0_principal_
    h = motion.spin_per_c
    return {"D": float(moments @ omega**2), "F": float(h @ h), "direction_world": h / np.linalg.norm(h)}
