"""``eddy_current_damping``: braking torque of eddy currents induced by the geomagnetic field.

For a conductive body spinning in a field B (Gomez & Walker 2015, Ortiz Gomez & Walker,
"Eddy currents applied to de-tumbling of space debris"), the torque opposes the spin
component normal to the field:

.. math:: \\boldsymbol\\tau = -c\\,(\\boldsymbol\\omega - (\\boldsymbol\\omega\\cdot\\hat b)\\hat b)

with c = k_e |B|^2 (N m s) and the field direction b fixed in the inertial frame over the record
(a few minutes of a LEO orbit); the angular momentum is not conserved (an external torque).
Parameters: c and the field direction (azimuth, elevation in I = LVLH at t = 0). Main body only
(towing: the debris; I = the chaser's LVLH at the record's t = 0).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, L_TM, X_Q, X_W, quaternion_rows, tdot, tmtv, tmv
from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.scenario import plant_of
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.towing_kernel import DEBRIS


@njit(cache=True)
def field_direction(azimuth, elevation):
    """Unit field direction (3-tuple) in I from azimuth (about z, from x) and elevation (rad).

    Parameters
    ----------
    azimuth : float
        Angle about I z from I x (rad).
    elevation : float
        Angle above the I x-y plane (rad).

    Returns
    -------
    b_inertial : tuple of 3 float
        Unit field direction, I (towing: the chaser's LVLH at the record's t = 0) (-).
    """
    return (np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation))


@njit(cache=True)
def eddy_torque(omega_body, field_body, coefficient):
    """Eddy-current torque (N m, B, 3-tuple) at ``omega_body`` (rad/s, B), unit field ``field_body`` (B).

    Parameters
    ----------
    omega_body : (3,) float
        Inertial angular velocity of the body, body frame (rad/s).
    field_body : (3,) float
        Unit field direction, body frame (-).
    coefficient : float
        c = k_e |B|^2 (N m s).

    Returns
    -------
    torque_body : tuple of 3 float
        -c (omega - (omega . b) b), body frame (N m).
    """
    along = tdot(omega_body, field_body)
    return (-coefficient * (omega_body[0] - along * field_body[0]), -coefficient * (omega_body[1] - along * field_body[1]),
            -coefficient * (omega_body[2] - along * field_body[2]))


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """Eddy-current torque on the main body.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (3,) float
        [c (N m s), field azimuth (rad), field elevation (rad)], I.
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the torque on the main body (``L_TM``, B, N m).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the effect declares no ``extra_states``).
    """
    field = tmtv(quaternion_rows(x[X_Q:X_Q + 4]), field_direction(p[1], p[2]))
    torque = eddy_torque((x[X_W], x[X_W + 1], x[X_W + 2]), field, p[0])
    for i in range(3):
        load[L_TM + i] += torque[i]


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """On the towed debris; ``p`` = [c, azimuth, elevation, I -> ECI (9, row-major)].

    Parameters
    ----------
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        Evaluation state, kernel layout (:mod:`multibody.towing_kernel`): P, chaser and debris
        displacements from their reference positions (m, ECI; P's are stale, see
        :func:`~riskassess.diagnosis.plants.towing_dynamics.point_position`) and rotation vectors body -> ECI
        (rad); velocities (m/s, ECI) and angular velocities (rad/s, body frames).
    p : (12,) float
        c (N m s), field azimuth and elevation (rad) in I (the chaser's LVLH at the record's t = 0), I
        -> ECI rotation (9, row-major, -).
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (0,) float
        The law's own states: none (the effect declares no ``towing_extra_states``).
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: the torque on the debris (N m, debris body
        frame).
    """
    b_eci = tmv(p[3:12], field_direction(p[1], p[2]))
    rot = rotation_matrix_from_rotation_vector(q[DEBRIS + 3:DEBRIS + 6])
    field = rot.T @ np.array(b_eci)
    torque = eddy_torque((v[DEBRIS + 3], v[DEBRIS + 4], v[DEBRIS + 5]), field, p[0])
    for i in range(3):
        load[DEBRIS + 3 + i] += torque[i]


class EddyCurrentDamping(Effect):
    id = "eddy_current_damping"
    title = "eddy-current braking in the geomagnetic field (spin normal to the field decays)"
    channels = ("omega_x", "omega_y", "omega_z", "q_w")
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    law = staticmethod(law)
    towing_law = staticmethod(towing_law)

    def towing_law_parameters(self, plant, values):
        """[c, azimuth, elevation] followed by the plant's L0 -> ECI rotation (row-major).

        Parameters
        ----------
        plant : TowingPlant
            The towing plant (its ``lvlh0``, L0 -> ECI).
        values : (m,) float
            [c (N m s), field azimuth (rad), field elevation (rad)].

        Returns
        -------
        p : (12,) float
            The towing law's parameters.
        """
        return np.r_[np.asarray(values, float), plant.lvlh0.ravel()]

    def parameter_specs(self, case, channels=None):
        """c (N m s) up to J_max / 10, and the field's azimuth and elevation (rad) in I.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; the largest principal inertia of its main body (kg m^2) sizes c.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        j_max = float(np.linalg.eigvalsh(plant_of(case).inertia_main)[-1])
        return [Parameter("coefficient", "N m s", "k_e |B|^2, torque per unit spin rate", j_max / 3000.0, 0.0,
                          j_max / 10.0),
                Parameter("field_azimuth", "rad", "field direction about I z, from I x", 0.0, -2 * np.pi, 2 * np.pi),
                Parameter("field_elevation", "rad", "field direction above the I x-y plane", 0.0, -np.pi / 2, np.pi / 2)]

    def starts(self, specs):
        """Three field directions (elevation 1.2 rad; along I x; along I y) at the typical c.

        Parameters
        ----------
        specs : list of Parameter
            [coefficient, field_azimuth, field_elevation].

        Returns
        -------
        starts : list of (m,) float
            [c (N m s), azimuth (rad), elevation (rad)].
        """
        c = specs[0].typical
        return [np.array([c, 0.0, 1.2]), np.array([c, 0.0, 0.0]), np.array([c, np.pi / 2, 0.0])]

    def add_to_exudyn(self, builder, values, names):
        """The eddy-current torque on the main body (body 0).

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a body torque (N m, body frame).
        values : (m,) float
            [c (N m s), field azimuth (rad), field elevation (rad)], I.
        names : sequence of str
            Parameter names (not used).
        """
        b = np.array(field_direction(values[1], values[2]))
        builder.add_body_torque(lambda t, body, rot, omega: np.array(eddy_torque(omega, rot.T @ b, values[0]))
                                if body == 0 else np.zeros(3))


EFFECT = EddyCurrentDamping()
