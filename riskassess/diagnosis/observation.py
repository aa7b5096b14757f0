"""What is measured: the channels of a measured-data file, computed from simulated states.

Channels (SI): ``omega_x..z`` inertial angular velocity of the main body, its own frame B
(rad/s, a gyro); ``q_w..q_z`` attitude B->LVLH (unit quaternion, scalar first);
``hinge_angle`` (rad) and ``hinge_rate`` (rad/s); ``rel_x..z`` the target-frame origin
relative to the chaser, LVLH (m); ``tether_tension`` (N, towing only). Their names and units are
in :mod:`riskassess.diagnosis.plants.channels`.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from riskassess.diagnosis.plants.channels import HINGE, OMEGA, QUATERNION, REL, TENSION
from riskassess.diagnosis.plants.dynamics import environment, observe
from riskassess.diagnosis.plants.plant import Plant


def scenario_channels(plant: Plant) -> tuple[str, ...]:
    """Channels a scenario's model predicts.

    Parameters
    ----------
    plant : Plant or TowingPlant
        The scenario's plant.

    Returns
    -------
    channels : tuple of str
        Names from :mod:`riskassess.diagnosis.plants.channels`.
    """
    if getattr(plant, "kind", None) == "towing":
        return OMEGA + QUATERNION + REL + TENSION
    return OMEGA + QUATERNION + (HINGE if plant.hinged else ()) + REL


def lvlh_from_inertial(n: float, times) -> Rotation:
    """I -> LVLH(t): LVLH turns at ``n`` (rad/s) about its z axis (the orbit normal).

    Parameters
    ----------
    n : float
        Mean motion (rad/s).
    times : (k,) float
        Times (s) from t = 0.

    Returns
    -------
    inertial_to_lvlh : Rotation
        k rotations mapping I components to LVLH(t) components.
    """
    return Rotation.from_rotvec(np.outer(-n * np.asarray(times, float), [0.0, 0.0, 1.0]))


def outputs(plant: Plant, times, states) -> dict[str, np.ndarray]:
    """Every channel of ``scenario_channels(plant)`` at ``times`` (s) from states (k, n).

    Parameters
    ----------
    plant : Plant
        The scenario's plant.
    times : (k,) float
        Times (s) from t = 0.
    states : (k, n) float
        Fast-model states (layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics`).

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    values = observe(np.ascontiguousarray(states), np.ascontiguousarray(times, float), environment(plant),
                     np.ascontiguousarray(plant.origin_main, float))
    names = OMEGA + QUATERNION + REL + (HINGE if plant.hinged else ())
    return {c: values[:, k] for k, c in enumerate(names)}
