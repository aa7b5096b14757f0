"""What is measured: the channels of a measured-data file, computed from simulated states.

Channels (SI): ``omega_x..z`` inertial angular velocity of the main body, its own frame B
(rad/s, a gyro); ``q_w..q_z`` attitude B->LVLH (unit quaternion, scalar first);
``hinge_angle`` (rad) and ``hinge_rate`` (rad/s); ``rel_x..z`` the target-frame origin
relative to the chaser, LVLH (m); ``tether_tension`` (N, towing only).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from riskassess.diagnosis.dynamics import environment, observe
from riskassess.diagnosis.plant import Plant

OMEGA = ("omega_x", "omega_y", "omega_z")
QUATERNION = ("q_w", "q_x", "q_y", "q_z")
HINGE = ("hinge_angle", "hinge_rate")
REL = ("rel_x", "rel_y", "rel_z")
TENSION = ("tether_tension",)
CHANNELS = OMEGA + QUATERNION + HINGE + REL + TENSION
UNITS = {**{c: "rad/s" for c in OMEGA}, **{c: "-" for c in QUATERNION}, "hinge_angle": "rad",
         "hinge_rate": "rad/s", **{c: "m" for c in REL}, "tether_tension": "N"}


def scenario_channels(plant: Plant) -> tuple[str, ...]:
    """Channels a scenario's model predicts."""
    if getattr(plant, "kind", None) == "towing":
        return OMEGA + QUATERNION + REL + TENSION
    return OMEGA + QUATERNION + (HINGE if plant.hinged else ()) + REL


def lvlh_from_inertial(n: float, times) -> Rotation:
    """I -> LVLH(t): LVLH turns at ``n`` (rad/s) about its z axis (the orbit normal)."""
    return Rotation.from_rotvec(np.outer(-n * np.asarray(times, float), [0.0, 0.0, 1.0]))


def outputs(plant: Plant, times, states) -> dict[str, np.ndarray]:
    """Every channel of ``scenario_channels(plant)`` at ``times`` (s) from states (k, STATE_SIZE)."""
    values = observe(np.ascontiguousarray(states), np.ascontiguousarray(times, float), environment(plant),
                     np.ascontiguousarray(plant.origin_main, float))
    names = OMEGA + QUATERNION + REL + (HINGE if plant.hinged else ())
    return {c: values[:, k] for k, c in enumerate(names)}
