"""What is measured: the channels of a measured-data file, computed from simulated states.

Channels (SI): ``omega_x..z`` inertial angular velocity of the main body, its own frame B
(rad/s, a gyro); ``q_w..q_z`` attitude B->LVLH (unit quaternion, scalar first);
``hinge_angle`` (rad) and ``hinge_rate`` (rad/s); ``rel_x..z`` the target-frame origin
relative to the chaser, LVLH (m); ``tether_tension`` (N, towing only).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from diagnosis.dynamics import X_Q, X_R, X_TH, X_THD, X_W
from diagnosis.plant import Plant

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
    return OMEGA + QUATERNION + (HINGE if plant.hinged else ()) + REL


def lvlh_from_inertial(n: float, times) -> Rotation:
    """I -> LVLH(t): LVLH turns at ``n`` (rad/s) about its z axis (the orbit normal)."""
    return Rotation.from_rotvec(np.outer(-n * np.asarray(times, float), [0.0, 0.0, 1.0]))


def outputs(plant: Plant, times, states) -> dict[str, np.ndarray]:
    """Every channel of ``scenario_channels(plant)`` at ``times`` (s) from states (k, STATE_SIZE)."""
    times = np.asarray(times, float)
    to_lvlh = lvlh_from_inertial(plant.mean_motion, times)
    body_to_inertial = Rotation.from_quat(states[:, [X_Q + 1, X_Q + 2, X_Q + 3, X_Q]])
    q = (to_lvlh * body_to_inertial).as_quat()[:, [3, 0, 1, 2]]
    share = plant.mass_appendage / plant.total_mass
    offset_b = plant.origin_main - share * plant.appendage_offset(states[:, X_TH]) if plant.hinged \
        else np.tile(plant.origin_main, (len(times), 1))
    rel = to_lvlh.apply(states[:, X_R:X_R + 3] + body_to_inertial.apply(offset_b))
    out = {c: states[:, X_W + k] for k, c in enumerate(OMEGA)}
    out.update({c: q[:, k] for k, c in enumerate(QUATERNION)})
    out.update({c: rel[:, k] for k, c in enumerate(REL)})
    if plant.hinged:
        out["hinge_angle"], out["hinge_rate"] = states[:, X_TH], states[:, X_THD]
    return out
