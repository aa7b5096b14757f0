"""``hinge_stiffness_hardening``: a hinge spring that stiffens with the angle (cubic term).

.. math:: \\tau = -k\\,\\theta - k_3\\,\\theta^3

(the linear part is the case's spring); the oscillation frequency rises with the amplitude.
"""
from __future__ import annotations

from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, L_TH, X_TH
from riskassess.diagnosis.effects.base import Effect, Parameter, reference_angle, torque_scale
from riskassess.diagnosis.plants.plant import Plant


@njit(cache=True)
def hardening_torque(angle, cubic_stiffness):
    """Cubic spring torque (N m) at hinge ``angle`` (rad), ``cubic_stiffness`` (N m/rad^3).

    Parameters
    ----------
    angle : float
        Hinge angle theta (rad).
    cubic_stiffness : float
        k_3 (N m/rad^3).

    Returns
    -------
    torque : float
        -k_3 theta^3, on the appendage about the hinge axis (N m).
    """
    return -cubic_stiffness * angle ** 3


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """The cubic hardening torque on the hinge.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (1,) float
        [k_3 (N m/rad^3)].
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the hinge torque (``L_TH``, N m, about the axis).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the effect declares no ``extra_states``).
    """
    load[L_TH] += hardening_torque(x[X_TH], p[0])


class HingeStiffnessHardening(Effect):
    id = "hinge_stiffness_hardening"
    title = "hinge spring stiffening with the angle (cubic term)"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def parameter_specs(self, case, channels=None):
        """k_3 (N m/rad^3), typical: the hinge torque scale at the nominal amplitude cubed.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; a hinged appendage; its hinge torque scale and amplitude size k_3.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        plant = Plant.from_case(case)
        typical = torque_scale(plant) / reference_angle(plant) ** 3
        return [Parameter("cubic_stiffness", "N m/rad^3", "cubic hardening coefficient k3", typical, 0.0,
                          50.0 * typical)]

    def add_to_exudyn(self, builder, values, names):
        """The cubic torque on the hinge.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a hinge torque (N m, about the axis).
        values : (m,) float
            [k_3 (N m/rad^3)].
        names : sequence of str
            Parameter names (not used).
        """
        builder.add_hinge_torque(lambda t, angle, rate: hardening_torque(angle, values[0]))


EFFECT = HingeStiffnessHardening()
