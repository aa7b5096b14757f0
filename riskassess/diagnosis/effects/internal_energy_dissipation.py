"""``internal_energy_dissipation``: nutation damping by an internal damper; angular momentum conserved.

A spherical viscous damper (Hughes, *Spacecraft Attitude Dynamics*, Sec. 7.3): a rotor of
isotropic inertia J_d at the main body's CoM, coupled to it by a viscous torque. In B:

.. math::
    \\tau_{body} = c\\,(\\omega_d - \\omega),\\qquad
    J_d(\\dot\\omega_d + \\omega\\times\\omega_d) = -c\\,(\\omega_d - \\omega),\\qquad c = J_d / T_d

Body and damper together conserve the angular momentum; the energy decays, the tumble drifts
towards the major axis. Parameters: the damper inertia J_d and its time constant T_d. The rotor's
angular velocity omega_d (B, rad/s) is the effect's own state, three slots in the fast model and in
the towing model, starting with the body's rate (the rotor turns with the body at t = 0).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.maths.linalg3 import cross3
from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, L_TM, X_W
from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.scenario import plant_of
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE
from multibody.towing_kernel import DEBRIS

#: The effect's own states (fast and towing models): the rotor's angular velocity (3, rad/s, body frame).
ROTOR_RATE, STATES = 0, 3


@njit(cache=True)
def damper_torque(omega_body, omega_damper, inertia, time_constant):
    """Torque on the body (N m, B) from the damper rotating at ``omega_damper`` (rad/s, B).

    Parameters
    ----------
    omega_body : (3,) float
        Inertial angular velocity of the body, body frame (rad/s).
    omega_damper : (3,) float
        Inertial angular velocity of the damper rotor, body frame (rad/s).
    inertia : float
        Rotor inertia J_d (kg m^2).
    time_constant : float
        T_d = J_d / c (s), > 0.

    Returns
    -------
    torque_body : (3,) float
        c (omega_d - omega), body frame (N m).
    """
    return inertia / time_constant * (omega_damper - omega_body)


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """The damper's torque on the main body and the damper's angular acceleration.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (2,) float
        [J_d (kg m^2), T_d (s)].
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the torque on the main body (``L_TM``, B, N m).
    xe : (3,) float
        The rotor's angular velocity omega_d (``ROTOR_RATE``, B, rad/s).
    xe_rate : (3,) float
        Its rate (B, rad/s^2), added to in place.
    """
    w = x[X_W:X_W + 3]
    wd = xe[ROTOR_RATE:ROTOR_RATE + 3]
    torque = damper_torque(w, wd, p[0], p[1])
    load[L_TM:L_TM + 3] += torque
    xe_rate[ROTOR_RATE:ROTOR_RATE + 3] += -torque / p[0] - cross3(w, wd) if p[0] > 0 else -cross3(w, wd)


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """The damper in the towed debris; its rate (``ROTOR_RATE``, debris frame) advanced by explicit
    Euler over the step (h / T_d <= 0.05 at the fit's 50 ms limit and T_d >= 1 s).

    Parameters
    ----------
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        Evaluation state, kernel layout (:mod:`multibody.towing_kernel`): P, chaser and debris
        displacements from their reference positions (m, ECI; P's are stale, see
        :func:`~riskassess.diagnosis.plants.towing_dynamics.point_position`) and rotation vectors body -> ECI
        (rad); velocities (m/s, ECI) and angular velocities (rad/s, body frames).
    p : (2,) float
        [J_d (kg m^2), T_d (s)].
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (3,) float
        The effect's own states: the rotor's angular velocity (``ROTOR_RATE``, rad/s, debris frame),
        advanced in place.
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: the torque on the debris (N m, debris body
        frame).
    """
    w = v[DEBRIS + 3:DEBRIS + 6]
    wd = xe[ROTOR_RATE:ROTOR_RATE + 3]
    torque = damper_torque(w, wd, p[0], p[1])
    load[DEBRIS + 3:DEBRIS + 6] += torque
    if h > 0.0 and p[0] > 0.0:
        xe[ROTOR_RATE:ROTOR_RATE + 3] += h * (-torque / p[0] - cross3(w, wd))


class InternalEnergyDissipation(Effect):
    id = "internal_energy_dissipation"
    extra_states = STATES
    towing_extra_states = STATES
    title = "nutation damping by internal energy dissipation (spherical viscous damper)"
    channels = ("omega_x", "omega_y", "omega_z", "q_w")
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    law = staticmethod(law)
    towing_law = staticmethod(towing_law)

    def parameter_specs(self, case, channels=None):
        """J_d (kg m^2, up to 0.2 J_min) and T_d (s, 1 to 3000).

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; the smallest principal inertia of its main body (kg m^2) sizes J_d.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        j_min = float(np.linalg.eigvalsh(plant_of(case).inertia_main)[0])
        return [Parameter("damper_inertia", "kg m^2", "inertia of the damper rotor", 0.01 * j_min, 0.0, 0.2 * j_min),
                Parameter("time_constant", "s", "damper time constant J_d / c", 30.0, 1.0, 3000.0)]

    def initial_extra_states(self, plant):
        """The rotor turns with the main body at t = 0.

        Parameters
        ----------
        plant : Plant
            The plant (its omega_B at t = 0, rad/s).

        Returns
        -------
        xe0 : (3,) float
            omega_d = omega_B (rad/s, B).
        """
        return np.array(plant.omega0, float)

    def initial_towing_states(self, model):
        """The rotor turns with the debris at t = 0.

        Parameters
        ----------
        model : TowingModel
            The built towing model (its debris angular velocity at t = 0, ``omega_body[1]``, rad/s, D).

        Returns
        -------
        xe0 : (3,) float
            omega_d (rad/s, D).
        """
        return np.array(model.omega_body[1], float)

    def starts(self, specs):
        """Two starts at the typical J_d: T_d = 10 s and 100 s.

        Parameters
        ----------
        specs : list of Parameter
            [damper_inertia, time_constant].

        Returns
        -------
        starts : list of (m,) float
            [J_d (kg m^2), T_d (s)].
        """
        return [np.array([specs[0].typical, 10.0]), np.array([specs[0].typical, 100.0])]

    def stiffness_rate(self, plant, specs):
        """1 / T_d at its lower bound (1/s): the damper's fastest relaxation.

        Parameters
        ----------
        plant : Plant
            Not used.
        specs : list of Parameter
            [damper_inertia, time_constant]; the lower bound of T_d (s) sets the rate.

        Returns
        -------
        rate : float
            (1/s).
        """
        return 1.0 / specs[1].lower

    def add_to_exudyn(self, builder, values, names):
        """A rotor body of inertia J_d coupled to the main body by a rotational damper c = J_d / T_d.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder (its damper hook: J_d (kg m^2), c (N m s)).
        values : (m,) float
            [J_d (kg m^2), T_d (s)]; J_d = 0 adds nothing.
        names : sequence of str
            Parameter names (not used).
        """
        if values[0] > 0:
            builder.add_damper(values[0], values[0] / values[1])


EFFECT = InternalEnergyDissipation()
