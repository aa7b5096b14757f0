"""``j2_perturbation``: the differential J2 (Earth oblateness) acceleration of the debris
relative to the chaser, which the nominal Clohessy-Wiltshire motion leaves out.

.. math::
    \\mathbf a_{J2}(\\mathbf r) = -\\frac{3}{2} J_2 \\frac{\\mu R_E^2}{r^5}
    \\left(x(1 - 5z^2/r^2),\\ y(1 - 5z^2/r^2),\\ z(3 - 5z^2/r^2)\\right)

(Vallado, *Fundamentals of Astrodynamics*, eq. 8-30, Earth-centred inertial), applied as
:math:`\\mathbf a_{J2}(\\mathbf R_c + \\boldsymbol\\rho) - \\mathbf a_{J2}(\\mathbf R_c)` with the chaser on
the case's circular orbit (inclination, argument of latitude; right ascension of the node 0).
Parameter: J2 itself, expected at Earth's 1.08263e-3. Towing: the towing model moves every body in
Earth-centred inertial coordinates with two-body gravity (the towing case's frame, z the Earth's
axis); the effect adds J2's acceleration to P, the chaser and the debris.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, E_INC, E_MA, E_MM, E_N, E_RADIUS, E_U0, L_F, X_R
from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE, W_MASSES, W_REFERENCE, body_position, point_position
from multibody.towing_kernel import CHASER, DEBRIS
from multibody.orbit import MU_EARTH, R_EARTH

#: Earth's J2 (-), EGM2008.
J2_EARTH = 1.08262668e-3


@njit(cache=True)
def j2_acceleration(r_eci, j2):
    """J2 acceleration (m/s^2), Earth-centred inertial, at ``r_eci`` (m).

    Parameters
    ----------
    r_eci : (3,) float
        Position from the Earth's centre, ECI (z the Earth's axis) (m).
    j2 : float
        J2 coefficient (-).

    Returns
    -------
    a_eci : (3,) float
        Vallado eq. 8-30, ECI (m/s^2).
    """
    r2 = r_eci @ r_eci
    r = np.sqrt(r2)
    zz = 5.0 * r_eci[2] ** 2 / r2
    factor = -1.5 * j2 * MU_EARTH * R_EARTH ** 2 / r ** 5
    return factor * np.array([r_eci[0] * (1.0 - zz), r_eci[1] * (1.0 - zz), r_eci[2] * (3.0 - zz)])


@njit(cache=True)
def inertial_to_eci(inclination, latitude0):
    """Rotation I (LVLH at t = 0) -> ECI: columns radial, along-track, orbit normal at t = 0.

    Parameters
    ----------
    inclination : float
        Orbit inclination (rad).
    latitude0 : float
        The chaser's argument of latitude at t = 0 (rad), right ascension of the node 0.

    Returns
    -------
    inertial_to_eci : (3, 3) float
        Maps I components to ECI components (-).
    """
    ci, si, cu, su = np.cos(inclination), np.sin(inclination), np.cos(latitude0), np.sin(latitude0)
    out = np.empty((3, 3))
    out[:, 0] = np.array([cu, su * ci, su * si])
    out[:, 1] = np.array([-su, cu * ci, cu * si])
    out[:, 2] = np.array([0.0, -si, ci])
    return out


@njit(cache=True)
def differential_j2(t, rho_inertial, j2, mean_motion, radius, inclination, latitude0):
    """Relative J2 acceleration (m/s^2), I, of a point at ``rho_inertial`` (m, I) from the chaser.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    rho_inertial : (3,) float
        The point minus the chaser's position, I (m).
    j2 : float
        J2 coefficient (-).
    mean_motion : float
        The chaser's circular-orbit mean motion (rad/s).
    radius : float
        The chaser's orbit radius (m).
    inclination, latitude0 : float
        Orbit inclination and argument of latitude at t = 0 (rad).

    Returns
    -------
    a_inertial : (3,) float
        a_J2(R_c + rho) - a_J2(R_c), I (m/s^2).
    """
    to_eci = inertial_to_eci(inclination, latitude0)
    chaser = radius * (to_eci @ np.array([np.cos(mean_motion * t), np.sin(mean_motion * t), 0.0]))
    return to_eci.T @ (j2_acceleration(chaser + to_eci @ rho_inertial, j2) - j2_acceleration(chaser, j2))


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """The differential J2 force on the system CoM.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (1,) float
        [J2 (-)].
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the force on the system CoM (``L_F``, I, N).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the effect declares no ``extra_states``).
    """
    a = differential_j2(t, x[X_R:X_R + 3], p[0], env[E_N], env[E_RADIUS], env[E_INC], env[E_U0])
    load[L_F:L_F + 3] += (env[E_MM] + env[E_MA]) * a


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """J2 on P, chaser and debris of the towing model (Earth-centred inertial, z the Earth's axis).

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
        [J2 (-)].
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (0,) float
        The law's own states: none (the effect declares no ``towing_extra_states``).
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: forces on P, the chaser and the debris (N,
        ECI).
    """
    point, _ = point_position(work)
    for b, base in enumerate((0, CHASER, DEBRIS)):
        r = work[W_REFERENCE:W_REFERENCE + 3] + point if b == 0 else body_position(work, q, base)
        a = j2_acceleration(r, p[0])
        for i in range(3):
            load[base + i] += work[W_MASSES + b] * a[i]


class J2Perturbation(Effect):
    id = "j2_perturbation"
    title = "differential J2 acceleration of the debris relative to the chaser"
    channels = ("rel_x", "rel_y", "rel_z")
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    law = staticmethod(law)
    towing_law = staticmethod(towing_law)
    needs_orbit = "altitude and inclination"

    def parameter_specs(self, case, channels=None):
        """J2 (-), expected at Earth's, bounded by 20 times it.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; not read (J2 is Earth's).
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        return [Parameter("j2", "-", "Earth's oblateness coefficient (expected 1.08263e-3)", J2_EARTH, 0.0,
                          20 * J2_EARTH)]

    def starts(self, specs):
        """One start: Earth's J2.

        Parameters
        ----------
        specs : list of Parameter
            [j2].

        Returns
        -------
        starts : list of (m,) float
            [J2_EARTH] (-).
        """
        return [np.array([J2_EARTH])]

    def add_to_exudyn(self, builder, values, names):
        """The differential J2 acceleration on every body's CoM.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a CoM acceleration (m/s^2, I) at the position r (m, I).
        values : (m,) float
            [J2 (-)].
        names : sequence of str
            Parameter names (not used).
        """
        plant = builder.plant
        builder.add_com_acceleration(lambda t, r: differential_j2(
            t, r, values[0], plant.mean_motion, plant.orbit_radius, plant.inclination, plant.latitude0))


EFFECT = J2Perturbation()
