"""The simulated plant of a diagnosis case as SI arrays, and its nominal uncertain parameters.

Frames: **B** main body frame (origin at its CoM, axes of the target frame); **I** inertial
frame = LVLH at t = 0; **L** LVLH at time t, rotated from I by the mean motion n about z.
The appendage's frame is B rotated by the hinge angle about the hinge axis; at zero angle its
axes are B's.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.orbit import R_EARTH, mean_motion

#: Nominal uncertain parameters: name -> (size, unit); the order of the fitted vector.
NOMINAL_PARAMETERS = {
    "attitude": (3, "rad"), "angular_velocity": (3, "rad/s"), "position": (3, "m"), "velocity": (3, "m/s"),
    "hinge_angle": (1, "rad"), "hinge_rate": (1, "rad/s"), "torsional_stiffness": (1, "N m/rad"),
    "torsional_damping": (1, "N m s/rad"),
}
HINGE_PARAMETERS = ("hinge_angle", "hinge_rate", "torsional_stiffness", "torsional_damping")
POSITION_PARAMETERS = ("position", "velocity")


@dataclass(frozen=True)
class Plant:
    """Mass properties, hinge, orbit and initial state of one scenario (SI).

    Attributes
    ----------
    hinged : bool                     True for the main body + appendage scenario.
    mass_main : float                 (kg)
    inertia_main : (3, 3) float       About the main CoM, B (kg m^2).
    origin_main : (3,) float          Target-frame origin (the tracked point) minus main CoM, B (m).
    mass_appendage : float            (kg); 0 without appendage.
    inertia_appendage : (3, 3) float  About its CoM at zero hinge angle, B axes (kg m^2).
    hinge_main : (3,) float           Hinge point minus main CoM, B (m).
    axis : (3,) float                 Hinge axis, unit, B (-).
    appendage_from_hinge : (3,) float Appendage CoM minus hinge point at zero angle, B (m).
    stiffness, damping : float        Torsional spring (N m/rad) and damper (N m s/rad).
    mean_motion : float               (rad/s); 0 without orbit.
    inclination, latitude0 : float    Orbit inclination and argument of latitude at t = 0 (rad).
    orbit_radius : float              (m); 0 without orbit.
    attitude0 : (3, 3) float          B -> I at t = 0.
    omega0 : (3,) float               Inertial angular velocity, B (rad/s).
    hinge_angle0, hinge_rate0 : float (rad), (rad/s)
    position0 : (3,) float            Tracked point at t = 0, LVLH (m).
    velocity0 : (3,) float            Velocity of the whole debris' CoM at t = 0, LVLH (m/s).
    """

    hinged: bool
    mass_main: float
    inertia_main: np.ndarray
    origin_main: np.ndarray
    mass_appendage: float
    inertia_appendage: np.ndarray
    hinge_main: np.ndarray
    axis: np.ndarray
    appendage_from_hinge: np.ndarray
    stiffness: float
    damping: float
    mean_motion: float
    inclination: float
    latitude0: float
    orbit_radius: float
    attitude0: np.ndarray
    omega0: np.ndarray
    hinge_angle0: float
    hinge_rate0: float
    position0: np.ndarray
    velocity0: np.ndarray

    @classmethod
    def from_case(cls, case) -> "Plant":
        """The plant of a rigid or hinged diagnosis case, in SI.

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case (:mod:`riskassess.cases.diagnosis`): main body (kg, kg m^2, CoM in
            the target frame, m), appendage and hinge (target frame), circular orbit or none, initial
            state (attitude target -> LVLH as a rotation vector (rad), omega (rad/s, target frame),
            position and velocity in LVLH (m, m/s)).

        Returns
        -------
        plant : Plant
        """
        main = case.main_body
        com = np.asarray(main.center_of_mass, float)
        hinged = case.kind == "hinged_appendage"
        orbit = case.orbit
        n = mean_motion(orbit.altitude) if orbit.kind == "circular" else 0.0
        app = getattr(case, "appendage", None)
        hinge = getattr(case, "hinge", None)
        return cls(
            hinged=hinged, mass_main=main.mass, inertia_main=np.asarray(main.inertia, float), origin_main=-com,
            mass_appendage=app.mass if hinged else 0.0,
            inertia_appendage=np.asarray(app.inertia, float) if hinged else np.zeros((3, 3)),
            hinge_main=np.asarray(hinge.position, float) - com if hinged else np.zeros(3),
            axis=np.asarray(hinge.axis, float) / np.linalg.norm(hinge.axis) if hinged else np.array([0.0, 0.0, 1.0]),
            appendage_from_hinge=np.asarray(app.com_offset_from_hinge, float) if hinged else np.zeros(3),
            stiffness=hinge.torsional_stiffness if hinged else 0.0, damping=hinge.torsional_damping if hinged else 0.0,
            mean_motion=n, inclination=orbit.inclination if n else 0.0,
            latitude0=orbit.argument_of_latitude if n else 0.0, orbit_radius=R_EARTH + orbit.altitude if n else 0.0,
            attitude0=Rotation.from_rotvec(case.initial.attitude_rotation_vector).as_matrix(),
            omega0=np.asarray(case.initial.angular_velocity, float),
            hinge_angle0=hinge.initial_angle if hinged else 0.0, hinge_rate0=hinge.initial_rate if hinged else 0.0,
            position0=np.asarray(case.initial.position_lvlh, float),
            velocity0=np.asarray(case.initial.velocity_lvlh, float))

    def replace(self, **changes) -> "Plant":
        return dataclasses.replace(self, **changes)

    @property
    def total_mass(self) -> float:
        return self.mass_main + self.mass_appendage

    def appendage_offset(self, angle) -> np.ndarray:
        """Appendage CoM minus main CoM (m), B, at hinge angle(s) ``angle`` (rad): (3,) or (k, 3).

        Parameters
        ----------
        angle : float or (k,) float
            Hinge angle(s) (rad).

        Returns
        -------
        offset : (3,) or (k, 3) float
            Appendage CoM minus main CoM, B (m).
        """
        angle = np.asarray(angle, float)
        s = Rotation.from_rotvec(np.multiply.outer(angle, self.axis)).apply(self.appendage_from_hinge)
        return self.hinge_main + s

    def hinge_inertia(self) -> float:
        """Appendage inertia about the hinge axis through the hinge point (kg m^2)."""
        r = self.appendage_from_hinge - (self.appendage_from_hinge @ self.axis) * self.axis
        return float(self.axis @ self.inertia_appendage @ self.axis + self.mass_appendage * r @ r)

    def effective_hinge_inertia(self) -> float:
        """Inertia of the hinge mode with the main body free (kg m^2): the Schur complement
        c - b^T A^-1 b of the Kane mass matrix at the initial angle (riskassess.diagnosis.plants.dynamics)."""
        a = self.axis
        s = Rotation.from_rotvec(self.hinge_angle0 * a).apply(self.appendage_from_hinge)
        d = self.hinge_main + s
        rot = Rotation.from_rotvec(self.hinge_angle0 * a).as_matrix()
        ja = rot @ self.inertia_appendage @ rot.T
        mr = self.mass_main * self.mass_appendage / self.total_mass
        big = self.inertia_main + ja + mr * ((d @ d) * np.eye(3) - np.outer(d, d))
        b = ja @ a + mr * np.cross(d, np.cross(a, s))
        c = a @ ja @ a + mr * np.cross(a, s) @ np.cross(a, s)
        return float(c - b @ np.linalg.solve(big, b))

    def rate_scale(self) -> float:
        """Fastest rate of the nominal motion (rad/s): tumble, hinge rate or hinge natural frequency."""
        rates = [np.linalg.norm(self.omega0), 0.01]
        if self.hinged:
            rates += [abs(self.hinge_rate0), np.sqrt(self.stiffness / self.effective_hinge_inertia())]
        return float(max(rates))


def is_towing(plant) -> bool:
    """Whether ``plant`` is the towing scenario's (:class:`riskassess.diagnosis.plants.towing_plant.TowingPlant`).

    Parameters
    ----------
    plant : Plant or TowingPlant

    Returns
    -------
    towing : bool
    """
    return getattr(plant, "kind", None) == "towing"


def nominal_parameter_names(case, channels) -> list[str]:
    """Nominal parameters the fit estimates: those with a prior 1-sigma > 0 that the scenario has and
    the channels can see (position and velocity only with rel_x..z).

    Parameters
    ----------
    case : DiagnosisCase
        Validated diagnosis case (its ``uncertain`` priors and ``kind``).
    channels : sequence of str
        Measured channel names.

    Returns
    -------
    names : list of str
        Keys of ``NOMINAL_PARAMETERS``, in its order.
    """
    names = []
    for name in NOMINAL_PARAMETERS:
        if getattr(case.uncertain, name, 0.0) <= 0:
            continue
        if case.kind == "towing":     # the tether couples position and attitude: every channel sees them
            names.append(name)
            continue
        if name in HINGE_PARAMETERS and case.kind != "hinged_appendage":
            continue
        if name in POSITION_PARAMETERS and not any(c.startswith("rel_") for c in channels):
            continue
        names.append(name)
    return names


def nominal_vector(plant: Plant, names) -> np.ndarray:
    """The case values of the nominal parameters ``names``, flattened (the attitude as a zero
    perturbation, rad).

    Parameters
    ----------
    plant : Plant or TowingPlant
        The scenario's plant.
    names : sequence of str
        Nominal parameter names (``NOMINAL_PARAMETERS`` keys).

    Returns
    -------
    vector : (m,) float
        Concatenated values in each name's unit (``NOMINAL_PARAMETERS``): attitude perturbation
        (rad, B), angular velocity (rad/s, B), position (m, LVLH), velocity (m/s, LVLH), hinge angle
        (rad), rate (rad/s), stiffness (N m/rad), damping (N m s/rad).
    """
    if is_towing(plant):
        return plant.nominal_vector(names)
    values = {"attitude": np.zeros(3), "angular_velocity": plant.omega0, "position": plant.position0,
              "velocity": plant.velocity0, "hinge_angle": [plant.hinge_angle0], "hinge_rate": [plant.hinge_rate0],
              "torsional_stiffness": [plant.stiffness], "torsional_damping": [plant.damping]}
    return np.concatenate([np.atleast_1d(np.asarray(values[n], float)) for n in names]) if names else np.zeros(0)


def with_nominal(plant: Plant, names, vector) -> Plant:
    """``plant`` with the nominal parameters ``names`` set from ``vector`` (attitude: a rotation
    vector (rad), B frame, composed after the case attitude).

    Parameters
    ----------
    plant : Plant or TowingPlant
        The scenario's plant.
    names : sequence of str
        Nominal parameter names (``NOMINAL_PARAMETERS`` keys).
    vector : (m,) float
        Their values, laid out as :func:`nominal_vector` returns them (units and frames there).

    Returns
    -------
    plant : Plant or TowingPlant
        A changed copy.
    """
    if is_towing(plant):
        return plant.with_nominal(names, vector)
    changes, k = {}, 0
    for name in names:
        size = NOMINAL_PARAMETERS[name][0]
        value = np.asarray(vector[k:k + size], float)
        k += size
        if name == "attitude":
            changes["attitude0"] = plant.attitude0 @ Rotation.from_rotvec(value).as_matrix()
        else:
            field = {"angular_velocity": "omega0", "position": "position0", "velocity": "velocity0",
                     "hinge_angle": "hinge_angle0", "hinge_rate": "hinge_rate0", "torsional_stiffness": "stiffness",
                     "torsional_damping": "damping"}[name]
            changes[field] = value if size == 3 else float(value[0])
    return plant.replace(**changes)


def prior_sigmas(case, names) -> np.ndarray:
    """The prior 1-sigma of every entry of the nominal vector of ``names``.

    Parameters
    ----------
    case : DiagnosisCase
        Validated diagnosis case (its ``uncertain`` table).
    names : sequence of str
        Nominal parameter names.

    Returns
    -------
    sigmas : (m,) float
        Per entry, in the entry's unit (rad, rad/s, m, m/s, N m/rad, N m s/rad).
    """
    return np.concatenate([np.full(NOMINAL_PARAMETERS[n][0], getattr(case.uncertain, n)) for n in names]) \
        if names else np.zeros(0)
