"""The towing scenario's plant: the towing case's lower-order model with the debris' initial state
as the diagnosis' nominal parameters, and its measured channels.

Frames: **ECI** Earth-centred inertial (the towing model's); **LVLH** the chaser's orbital frame at
time t, from the chaser's CoM position r_C and velocity v_C (ECI): x = r_C/|r_C| (radial),
z = (r_C x v_C)/|r_C x v_C| (orbit normal), y = z x x; **L0** that frame at the record's t = 0
(the diagnosis' inertial frame I, fixed); **D** the debris body frame (the towing case's debris
frame; its origin, the *target origin*, is the towing case's debris CoM).

Channels (:func:`channels`): ``omega_x..z`` the debris' inertial angular velocity in D (rad/s);
``q_w..q_z`` the attitude D -> LVLH(t), unit quaternion, scalar first; ``rel_x..z`` the target
origin minus the chaser's CoM, LVLH(t) components (m); ``tether_tension`` the main tether's tension
(N, including a viscoelastic branch when the effect is on). Record time 0 is the towing case's
``simulation.start_time``.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from riskassess.diagnosis.plants.channels import OMEGA, QUATERNION, REL, TENSION
from riskassess.diagnosis.plants.towing_dynamics import diagnostics_size, no_towing_load
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.towing import packed
from multibody.towing_kernel import MT_TENSION, verlet_run
from multibody.orbit import lvlh_to_eci
from multibody.maths.rotations import quaternion_from_matrix
from riskassess.models.towing import towing_model

#: Nominal parameters of the towing scenario: name -> (size, unit), the fitted vector's order.
TOWING_PARAMETERS = {"attitude": (3, "rad"), "angular_velocity": (3, "rad/s"), "position": (3, "m"),
                     "velocity": (3, "m/s")}


#: Every channel's value when a run diverges (channel units): far from any data, so the fit steps back.
FAILED = 1e6


@dataclass(frozen=True)
class TowingPlant:
    """The towing case and the debris' initial state (SI).

    Attributes
    ----------
    case : TowingCase                 The lower-order model (riskassess/cases/towing.py).
    fit_step : float                  Largest step of the fast model (s).
    attitude0 : (3, 3) float          D -> ECI at t = 0.
    omega0 : (3,) float               Debris angular velocity, D (rad/s).
    position0 : (3,) float            Target origin minus chaser CoM at t = 0, L0 (m).
    velocity0 : (3,) float            Debris CoM velocity minus the chaser's, L0 axes (m/s).
    com_offset : (3,) float           Debris CoM minus target origin, D (m) (the com_offset effect).
    """

    kind = "towing"
    hinged = False
    case: object
    fit_step: float
    attitude0: np.ndarray
    omega0: np.ndarray
    position0: np.ndarray
    velocity0: np.ndarray
    com_offset: np.ndarray

    @classmethod
    def from_case(cls, diagnosis_case) -> "TowingPlant":
        """The towing plant of a towing diagnosis case: the towing case's debris state, replaced by the
        diagnosis case's ``[initial]`` values where given.

        Parameters
        ----------
        diagnosis_case : TowingDiagnosisCase
            Validated case (:mod:`riskassess.cases.diagnosis`) with its towing case loaded; ``initial``:
            attitude change (rad, D), angular velocity (rad/s, D), position and velocity (m, m/s, L0).

        Returns
        -------
        plant : TowingPlant
        """
        c = diagnosis_case.towing_case
        init = diagnosis_case.initial
        de, ch = c.debris, c.chaser
        l0 = lvlh_to_eci(ch.position_inertial, ch.velocity_inertial)
        rot = Rotation.from_quat(np.roll(de.attitude_quaternion, -1)).as_matrix() @ \
            Rotation.from_rotvec(init.attitude_change).as_matrix()
        spin = np.deg2rad(de.spin_rate_deg_s) * np.asarray(de.spin_axis_body, float) / np.linalg.norm(de.spin_axis_body)
        rel = l0.T @ (np.asarray(de.position_inertial) - np.asarray(ch.position_inertial))
        vel = l0.T @ (np.asarray(de.velocity_inertial) - np.asarray(ch.velocity_inertial))
        pick = (lambda given, default: np.asarray(default if given is None else given, float))
        return cls(c, diagnosis_case.fit_step, rot, pick(init.angular_velocity, spin), pick(init.position_lvlh, rel),
                   pick(init.velocity_lvlh, vel), np.zeros(3))

    def replace(self, **changes) -> "TowingPlant":
        return dataclasses.replace(self, **changes)

    # -- what the effects and the fit read -------------------------------------------------
    @property
    def lvlh0(self) -> np.ndarray:
        """L0 -> ECI."""
        return lvlh_to_eci(self.case.chaser.position_inertial, self.case.chaser.velocity_inertial)

    @property
    def mass_main(self) -> float:
        """Debris mass with its share of the net (kg), as the lower-order model carries it."""
        c = self.case
        return c.debris.nominal_mass + c.net_mass * (1.0 - c.sub_tethers.connection_mass_fraction)

    @property
    def inertia_main(self) -> np.ndarray:
        return np.diag(self.case.debris.principal_inertia).astype(float)

    @property
    def orbit_radius(self) -> float:
        return float(np.linalg.norm(self.case.chaser.position_inertial))

    @property
    def mean_motion(self) -> float:
        """Of a circular orbit at the chaser's initial radius (rad/s)."""
        return float(np.sqrt(self.case.simulation.mu / self.orbit_radius ** 3))

    def rate_scale(self) -> float:
        return float(max(np.linalg.norm(self.omega0), 0.01))

    def nominal_vector(self, names) -> np.ndarray:
        """The plant's values of the nominal parameters ``names``, flattened (attitude as a zero perturbation).

        Parameters
        ----------
        names : sequence of str
            Keys of ``TOWING_PARAMETERS``.

        Returns
        -------
        vector : (3 m,) float
            Attitude perturbation (rad, D), angular velocity (rad/s, D), position (m, L0), velocity
            (m/s, L0), in the order of ``names``.
        """
        values = {"attitude": np.zeros(3), "angular_velocity": self.omega0, "position": self.position0,
                  "velocity": self.velocity0}
        return np.concatenate([values[n] for n in names]) if names else np.zeros(0)

    def with_nominal(self, names, vector) -> "TowingPlant":
        """The plant with the nominal parameters ``names`` set from ``vector`` (attitude: a rotation vector
        composed after the plant's attitude, D).

        Parameters
        ----------
        names : sequence of str
            Keys of ``TOWING_PARAMETERS``.
        vector : (3 m,) float
            Their values, laid out as :meth:`nominal_vector` returns them.

        Returns
        -------
        plant : TowingPlant
            A changed copy.
        """
        changes = {}
        for k, name in enumerate(names):
            value = np.asarray(vector[3 * k:3 * k + 3], float)
            if name == "attitude":
                changes["attitude0"] = self.attitude0 @ Rotation.from_rotvec(value).as_matrix()
            else:
                changes[{"angular_velocity": "omega0", "position": "position0", "velocity": "velocity0"}[name]] = value
        return self.replace(**changes)

    # -- the lower-order model -------------------------------------------------------------
    def towing_case(self, step: float):
        """The towing case with this plant's debris state and CoM, sampled at ``step`` (s).

        Parameters
        ----------
        step : float
            Output interval (s) of the returned case.

        Returns
        -------
        case : TowingCase
            Debris CoM position and velocity (m, m/s, ECI), attitude quaternion and spin from the
            plant; sub-tether attachments moved by the CoM offset (m, D).
        """
        c = self.case
        ch = c.chaser
        l0 = self.lvlh0
        com = np.asarray(ch.position_inertial) + l0 @ self.position0 + self.attitude0 @ self.com_offset
        speed = float(np.linalg.norm(self.omega0))
        axis = self.omega0 / speed if speed > 0 else np.array([0.0, 0.0, 1.0])
        quat = np.roll(Rotation.from_matrix(self.attitude0).as_quat(), 1)
        debris = c.debris.model_copy(update={
            "position_inertial": com.tolist(), "velocity_inertial": (np.asarray(ch.velocity_inertial) + l0 @ self.velocity0).tolist(),
            "attitude_quaternion": quat.tolist(), "spin_axis_body": axis.tolist(), "spin_rate_deg_s": float(np.rad2deg(speed))})
        attach = (np.asarray(c.sub_tethers.attachment_points_body, float) - self.com_offset).tolist()
        return c.model_copy(update={
            "debris": debris, "sub_tethers": c.sub_tethers.model_copy(update={"attachment_points_body": attach}),
            "simulation": c.simulation.model_copy(update={"output_interval": step})})

    def model(self, duration: float, step: float):
        """The :class:`multibody.towing.TowingModel` over ``duration`` (s) from the record's t = 0.

        Parameters
        ----------
        duration : float
            Simulated span (s) from the record's t = 0.
        step : float
            Integration step (s).

        Returns
        -------
        model : TowingModel
        """
        case = self.towing_case(step)
        return towing_model(case, step=step, end_time=case.simulation.start_time + duration)


def model_step(plant: TowingPlant, times, step: float | None = None) -> float:
    """Step (s) no longer than ``step`` (default: the plant's) that divides the median sample spacing,
    so that uniformly sampled records fall on steps.

    Parameters
    ----------
    plant : TowingPlant
        Its ``fit_step`` (s) is the default.
    times : (k,) float
        Sample times (s).
    step : float, optional
        Longest step (s).

    Returns
    -------
    step : float
        (s).
    """
    h = step or plant.fit_step
    dt = float(np.median(np.diff(times))) if len(times) > 1 else h
    return dt / np.ceil(dt / h - 1e-9)


def simulate(plant: TowingPlant, times, law=no_towing_load, p=None, step: float | None = None, states=None) -> dict:
    """Channels (dict of (k,) arrays) at ``times`` (s from the record's t = 0, non-decreasing) of the
    fast model with the towing ``law`` at parameters ``p``; linear between the steps around a time.

    Parameters
    ----------
    plant : TowingPlant
        The towing plant.
    times : (k,) float
        Sample times (s from the record's t = 0).
    law : compiled function, optional
        Towing law (``TOWING_LAW_SIGNATURE``); default: none.
    p : (j,) float, optional
        The law's parameters.
    step : float, optional
        Longest step (s); default the plant's ``fit_step``.
    states : callable, optional
        ``states(model) -> (e,) float``: the law's own states at t = 0 from the built
        :class:`multibody.towing.TowingModel` (an effect's, :func:`riskassess.diagnosis.effects.base.own_states`);
        default none.

    Returns
    -------
    channels : dict of str to (k,) float
        See the module doc (rad/s, D; quaternion D -> LVLH; m, LVLH; N); every entry ``FAILED``
        when the run diverges.
    """
    times = np.asarray(times, float)
    h = model_step(plant, times, step)
    model = plant.model(float(times[-1]) + 2 * h, h)
    position = times / h
    lower = np.clip(np.floor(position + 1e-9).astype(np.int64), 0, model.n_steps - 1)
    weight = np.clip(position - lower, 0.0, 1.0)
    weight[weight < 1e-9] = 0.0
    record = np.unique(np.r_[lower, lower[weight > 0] + 1]).astype(np.int64)
    q, v = model.initial_state()
    tow = packed(model)
    xe = np.zeros(0) if states is None else np.ascontiguousarray(states(model), float)
    out = [np.zeros((len(record), n)) for n in (15, 15, diagnostics_size(tow.work), xe.size)]
    p = np.zeros(1) if p is None or len(p) == 0 else np.ascontiguousarray(p, float)
    verlet_run(tow, law, p, q, v, model.start_time, int(record[-1]), xe, record, *out)
    if not all(np.isfinite(a).all() for a in out[:3]):      # a run that blew up (a parameter far off)
        return {c: np.full(len(times), FAILED) for c in OMEGA + QUATERNION + REL + TENSION}
    rows = channels(plant, model, *out)
    index = np.searchsorted(record, lower)
    upper = np.searchsorted(record, np.minimum(lower + 1, record[-1]))
    return {c: (1 - weight) * y[index] + weight * y[upper] for c, y in rows.items()}


@njit(cache=True)
def debris_in_lvlh(lvlh_to_eci_rows, rotation_vectors, debris_minus_chaser, com_offset):
    """Attitude D -> LVLH(t) (k, 4) (unit quaternions, scalar first, w >= 0) and target origin minus
    chaser CoM, LVLH(t) components (k, 3) (m), from the rows' LVLH -> ECI rotations (k, 3, 3), the
    debris' rotation vectors D -> ECI (k, 3) (rad), its CoM minus the chaser's, ECI (k, 3) (m) and its
    CoM minus target origin, D (3,) (m). Compiled: scipy's rotations of these rows took 7 % of a fit.

    Parameters
    ----------
    lvlh_to_eci_rows : (k, 3, 3) float
        LVLH(t) -> ECI rotations.
    rotation_vectors : (k, 3) float
        Debris rotation vectors D -> ECI (rad).
    debris_minus_chaser : (k, 3) float
        Debris CoM minus chaser CoM, ECI (m).
    com_offset : (3,) float
        Debris CoM minus target origin, D (m).

    Returns
    -------
    quat : (k, 4) float
        D -> LVLH(t), scalar first (-).
    rel : (k, 3) float
        Target origin minus chaser CoM, LVLH(t) (m).
    """
    k = rotation_vectors.shape[0]
    quat, rel = np.empty((k, 4)), np.empty((k, 3))
    m = np.empty((3, 3))
    for i in range(k):
        a = lvlh_to_eci_rows[i]
        d = rotation_matrix_from_rotation_vector(rotation_vectors[i])
        target = debris_minus_chaser[i] - (d[:, 0] * com_offset[0] + d[:, 1] * com_offset[1] + d[:, 2] * com_offset[2])
        for r in range(3):   # m = a^T d, rel = a^T target, written out (numba sends 3x3 products to BLAS)
            rel[i, r] = a[0, r] * target[0] + a[1, r] * target[1] + a[2, r] * target[2]
            for c in range(3):
                m[r, c] = a[0, r] * d[0, c] + a[1, r] * d[1, c] + a[2, r] * d[2, c]
        quat[i] = quaternion_from_matrix(m)
    return quat, rel


def channels(plant: TowingPlant, model, q, v, diag, xe) -> dict:
    """The measured channels (see the module doc) from kernel-layout states (k, 15), diagnostics and
    effect states.

    Parameters
    ----------
    plant : TowingPlant
        The plant (its CoM offset, m, D).
    model : TowingModel
        The model that ran (its reference positions, m, ECI).
    q, v : (k, 15) float
        States, kernel layout (:mod:`multibody.towing_kernel`).
    diag : (k, n_diag) float
        Diagnostics rows (main-tether tension in column ``MT_TENSION``, N).
    xe : (k, e) float
        The effect's own states (not used: a branch's tension is in the kernel's).

    Returns
    -------
    channels : dict of str to (k,) float
        omega_x..z (rad/s, D), q_w..q_z (D -> LVLH(t)), rel_x..z (m, LVLH(t)), tether_tension (N).
    """
    r_c, v_c = model.positions[1] + q[:, 3:6], v[:, 3:6]
    r_d = model.positions[2] + q[:, 9:12]
    quat, rel = debris_in_lvlh(lvlh_to_eci(r_c, v_c), np.ascontiguousarray(q[:, 12:15]), r_d - r_c,
                               np.asarray(plant.com_offset, float))
    # q and -q are one attitude: keep the sign continuous (rows are interpolated, plotted, and aligned
    # with the measured quaternion sample by sample)
    quat *= np.r_[1.0, np.cumprod(np.where(np.sum(quat[1:] * quat[:-1], axis=1) < 0, -1.0, 1.0))][:, None]
    out = {f"omega_{a}": v[:, 12 + i] for i, a in enumerate("xyz")}
    out.update({f"q_{a}": quat[:, i] for i, a in enumerate("wxyz")})
    out.update({f"rel_{a}": rel[:, i] for i, a in enumerate("xyz")})
    out["tether_tension"] = diag[:, MT_TENSION]      # a viscoelastic branch included (it acts through the kernel)
    return out
