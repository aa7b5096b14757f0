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


def fit_free_motion(tracker, indices, times, com_body=None, moments=None, principal_to_body=None) -> FreeMotion:
    """CoM line and torque-free fit through the registered frames ``indices``; inertia shape
    estimated (before the collision) or known (after). Frames the fitted motion does not explain
    (weighted residual above :data:`OUTLIER_OVER_MEDIAN` times the median) are dropped and the fit redone.

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

    Returns
    -------
    FreeMotion
    """
    indices = np.asarray(indices)
    for _ in range(5):
        motion, chi2 = _fit_free_motion_once(tracker, indices, times, com_body, moments, principal_to_body)
        keep = chi2 <= OUTLIER_OVER_MEDIAN * np.median(chi2)
        if keep.all():
            break
        indices = indices[keep]
    return motion


def _fit_free_motion_once(tracker, indices, times, com_body, moments, principal_to_body):
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
        fit = TorqueFreeFit().fit(t, attitudes, weights, omega[0], moments0, axes0)
    else:
        fit = TorqueFreeFit(moments, principal_to_body).fit(t, attitudes, weights, omega[0])
    error = (attitudes.inv() * fit.predict_body_to_world(t)).as_rotvec()
    chi2 = np.sum(np.einsum("kij,kj->ki", weights, error) ** 2, axis=1)
    h, h_cov = fit.spin_momentum_per_c()
    residual = float(np.degrees(np.sqrt(np.mean(np.sum(error**2, axis=1)))))
    return FreeMotion(t, line, fit, h, h_cov, residual), chi2


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
