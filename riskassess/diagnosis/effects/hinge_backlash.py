"""``hinge_backlash``: free play in the hinge; the torsional spring acts only outside a gap.

.. math:: \\tau_{spring} = -k\\,(\\theta - \\mathrm{clip}(\\theta, -b, b))

i.e. the effect adds :math:`k\\,\\mathrm{clip}(\\theta, -b, b)` to the nominal :math:`-k\\theta`.
Inside the gap (half width b) the appendage swings freely; the period grows as the amplitude
decays towards b.
"""
from __future__ import annotations

from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, E_K, L_TH, X_TH
from riskassess.diagnosis.effects.base import Effect, Parameter, reference_angle
from riskassess.diagnosis.plants.plant import Plant


@njit(cache=True)
def backlash_torque(angle, stiffness, half_gap):
    """Torque (N m) that cancels the spring ``stiffness`` (N m/rad) inside the gap +-``half_gap`` (rad).

    Parameters
    ----------
    angle : float
        Hinge angle (rad).
    stiffness : float
        The case's torsional spring k (N m/rad).
    half_gap : float
        Half width b of the free-play band (rad).

    Returns
    -------
    torque : float
        k clip(angle, -b, b), on the appendage about the hinge axis (N m).
    """
    return stiffness * min(max(angle, -half_gap), half_gap)


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """Backlash: cancels the hinge spring inside the gap.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (1,) float
        [half gap b (rad)].
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the hinge torque (``L_TH``, N m, about the axis).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the effect declares no ``extra_states``).
    """
    load[L_TH] += backlash_torque(x[X_TH], env[E_K], p[0])


class HingeBacklash(Effect):
    id = "hinge_backlash"
    title = "free play (dead band) of the hinge spring"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def not_applicable(self, case, channels):
        """A hinge without a spring has no free play to see; otherwise as the base class.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case.
        channels : sequence of str
            Measured channel names.
        """
        if case.kind == "hinged_appendage" and case.hinge.torsional_stiffness == 0:
            return "the hinge has no torsional spring: free play changes nothing"
        return super().not_applicable(case, channels)

    def parameter_specs(self, case, channels=None):
        """The half gap (rad), up to 1.5 times the nominal hinge amplitude.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; a hinged appendage; its hinge amplitude sizes the gap.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        angle = reference_angle(Plant.from_case(case))
        return [Parameter("half_gap", "rad", "half width of the free-play band", 0.2 * angle, 0.0, 1.5 * angle)]

    def add_to_exudyn(self, builder, values, names):
        """The backlash torque on the hinge.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a hinge torque (N m, about the axis).
        values : (m,) float
            [half gap b (rad)].
        names : sequence of str
            Parameter names (not used).
        """
        k = builder.plant.stiffness
        builder.add_hinge_torque(lambda t, angle, rate: backlash_torque(angle, k, values[0]))


EFFECT = HingeBacklash()
