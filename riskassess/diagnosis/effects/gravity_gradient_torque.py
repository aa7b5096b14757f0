"""``gravity_gradient_torque``: the tidal torque of Earth's gravity on each extended body.

.. math:: \\boldsymbol\\tau = 3 n^2\\, \\hat r \\times (\\mathbf J \\hat r)

(Hughes, *Spacecraft Attitude Dynamics*, eq. 8.1.13) with r the radial direction (LVLH x) in
the body's frame and J its inertia about its CoM; applied to the main body and the appendage.
The nominal model already moves every body's CoM in the orbit's tidal field (Clohessy-Wiltshire);
this adds the bodies' own inertia. Parameter: the mean motion n, expected at the case orbit's.
Towing: on the chaser and the debris, r their CoM's direction from the Earth's centre (the towing
model's two-body gravity acts on the CoMs only); n expected at the chaser's initial orbit radius.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.plants.dynamics import (LAW_SIGNATURE, E_AXIS, E_HINGED, E_JA, E_JM, E_N, L_TA, L_TM, X_Q, X_TH, axis_rows,
                                quaternion_rows, radial_inertial, sandwich, tcross, tmtv, tmv)
from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE, W_INERTIA, body_position
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.towing_kernel import CHASER, DEBRIS
from riskassess.diagnosis.plants.scenario import plant_of


@njit(cache=True)
def gravity_gradient(radial_body, inertia_times_radial, mean_motion):
    """Gravity-gradient torque (N m, 3-tuple) in the frame of ``radial_body`` (unit, -), given the
    inertia times it, J r (kg m^2).

    Parameters
    ----------
    radial_body : (3,) float
        Unit radial direction (away from the Earth's centre), body frame (-).
    inertia_times_radial : (3,) float
        J r, the body's inertia about its CoM times ``radial_body``, body frame (kg m^2).
    mean_motion : float
        n (rad/s).

    Returns
    -------
    torque_body : tuple of 3 float
        3 n^2 r x (J r), body frame (N m).
    """
    c = tcross(radial_body, inertia_times_radial)
    k = 3.0 * mean_motion ** 2
    return (k * c[0], k * c[1], k * c[2])


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """Gravity-gradient torque on the main body and, hinged, on the appendage.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (1,) float
        [n (rad/s)], the mean motion the torque sees.
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: torques on the main body (``L_TM``) and the appendage
        (``L_TA``), B (N m).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the effect declares no ``extra_states``).
    """
    n = env[E_N]
    r_b = tmtv(quaternion_rows(x[X_Q:X_Q + 4]), (np.cos(n * t), np.sin(n * t), 0.0))
    main = gravity_gradient(r_b, tmv(env[E_JM:E_JM + 9], r_b), p[0])
    for i in range(3):
        load[L_TM + i] += main[i]
    if env[E_HINGED] != 0.0:
        ra = axis_rows((env[E_AXIS], env[E_AXIS + 1], env[E_AXIS + 2]), x[X_TH])
        appendage = gravity_gradient(r_b, sandwich(ra, env[E_JA:E_JA + 9], r_b), p[0])
        for i in range(3):
            load[L_TA + i] += appendage[i]


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """On chaser and debris of the towing model: r from the Earth's centre to each CoM (ECI).

    Parameters
    ----------
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        Evaluation state, kernel layout (:mod:`multibody.towing_kernel`): P, chaser and debris
        displacements from their reference positions (m, ECI; P's are stale, see
        :func:`~riskassess.diagnosis.plants.towing_dynamics.point_position`) and rotation vectors body -> ECI
        (rad); velocities (m/s, ECI) and angular velocities (rad/s, body frames).
    p : (1,) float
        [n (rad/s)].
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (0,) float
        The law's own states: none (the effect declares no ``towing_extra_states``).
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: torques on chaser and debris (N m, their
        body frames).
    """
    for b, base in enumerate((CHASER, DEBRIS)):
        r = body_position(work, q, base)
        rot = rotation_matrix_from_rotation_vector(q[base + 3:base + 6])
        r_b = rot.T @ (r / np.sqrt(r @ r))
        inertia = work[W_INERTIA + 9 * b:W_INERTIA + 9 * b + 9]
        torque = gravity_gradient((r_b[0], r_b[1], r_b[2]), tmv(inertia, (r_b[0], r_b[1], r_b[2])), p[0])
        for i in range(3):
            load[base + 3 + i] += torque[i]


class GravityGradientTorque(Effect):
    id = "gravity_gradient_torque"
    title = "gravity-gradient torque on the bodies' inertia"
    channels = ("omega_x", "omega_y", "omega_z", "q_w", "hinge_angle", "hinge_rate")
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    law = staticmethod(law)
    towing_law = staticmethod(towing_law)
    needs_orbit = "its altitude"

    def parameter_specs(self, case, channels=None):
        """The mean motion n (rad/s), expected at the case orbit's, bounded by 10 n.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; its orbit (or the towing chaser's radius) gives n.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        n = plant_of(case).mean_motion
        return [Parameter("mean_motion", "rad/s", "orbit mean motion seen by the torque (the case orbit's: "
                          f"{n:.4g})", n, 0.0, 10.0 * n)]

    def starts(self, specs):
        """One start: the case orbit's n.

        Parameters
        ----------
        specs : list of Parameter
            [mean_motion].

        Returns
        -------
        starts : list of (m,) float
            [n] (rad/s).
        """
        return [np.array([specs[0].typical])]

    def add_to_exudyn(self, builder, values, names):
        """The torque on every body (main and appendage), r the radial direction at the plant's n.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a body torque (N m, body frame) per body.
        values : (m,) float
            [n (rad/s)].
        names : sequence of str
            Parameter names (not used).
        """
        n_orbit = builder.plant.mean_motion
        def torque(t, body, rot, omega):
            r_b = rot.T @ radial_inertial(n_orbit, t)
            return np.array(gravity_gradient(r_b, builder.inertia_body(body) @ r_b, values[0]))
        builder.add_body_torque(torque)


EFFECT = GravityGradientTorque()
