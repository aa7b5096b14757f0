""""None of these": a flexible discrepancy model that competes with the catalog's effects.

The BIC weights of the selection compare catalog models only, so a confidence of 1.00 could mean "the
best of a wrong list". This model stands for effects outside the catalog: a smooth, otherwise
unexplained torque on the main body (3 axes, body frame) and, for a hinged appendage, about the hinge,
each a quadratic Legendre series over the record,

.. math:: \\tau_j(t) = \\sum_{k=0}^{2} c_{jk} P_k(s),\\qquad s = 2 (t - t_0) / (t_1 - t_0) - 1,

(9 or 12 parameters), fitted like any candidate and scored by the same BIC, whose k ln n term is its
penalty for being flexible. A catalog cause is named only when its BIC is lower than this model's
(:func:`none_of_these`): an effect whose form the catalog holds explains the data with a few
parameters where the discrepancy needs many and still misses the state dependence (a friction torque
follows the hinge rate, a damper the nutation), while an effect outside the catalog that acts as a
slowly varying torque is fitted better by the discrepancy than by any catalog member. The model is
never a cause itself: it is the "none of these" alternative, listed with the candidates and included
in the confidence (the posterior weight over catalog models and this one).

Only torques: a discrepancy in the translation channels (the CoM in the orbit) or in the sensors is not
represented, so effects outside the catalog of those kinds still rely on the adequacy and structure
tests. The towing scenario has none (its tension channel's effects are not smooth torques).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.dynamics import LAW_SIGNATURE, L_TH, L_TM
from riskassess.diagnosis.effects.base import Effect, Parameter, torque_scale
from riskassess.diagnosis.plant import Plant

#: Legendre terms per torque component (degrees 0-2: a constant, a drift and a curvature over the record).
TERMS = 3
#: The discrepancy's id in the candidate list (never a catalog cause).
DISCREPANCY_ID = "none_of_these"


@njit(cache=True)
def _legendre(t, t0, t1):
    s = 2.0 * (t - t0) / (t1 - t0) - 1.0
    return 1.0, s, 1.5 * s * s - 0.5


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """``p`` = [t0, t1, hinged (0/1), body torque coefficients (3 axes x 3, B), hinge torque (3)].

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (3 + 3 TERMS [+ TERMS],) float
        t0, t1 (s), hinged flag, Legendre coefficients of the body torque (N m, B) and of the hinge
        torque (N m).
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the torque on the main body (``L_TM``, B, N m) and the
        hinge torque (``L_TH``, N m).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the effect declares no ``extra_states``).
    """
    b0, b1, b2 = _legendre(t, p[0], p[1])
    for axis in range(3):
        k = 3 + TERMS * axis
        load[L_TM + axis] += p[k] * b0 + p[k + 1] * b1 + p[k + 2] * b2
    if p[2] > 0.0:
        k = 3 + TERMS * 3
        load[L_TH] += p[k] * b0 + p[k + 1] * b1 + p[k + 2] * b2


def body_torque_scale(plant: Plant) -> float:
    """Size of a body torque that matters (N m): one that changes the tumble's rate by 1 % per radian.

    Parameters
    ----------
    plant : Plant
        Its largest principal inertia (kg m^2) and fastest rate (rad/s).

    Returns
    -------
    scale : float
        0.01 J_max omega^2 (N m), at least 1e-9.
    """
    inertia = float(np.max(np.linalg.eigvalsh(np.asarray(plant.inertia_main, float))))
    return max(0.01 * inertia * plant.rate_scale() ** 2, 1e-9)


class Discrepancy(Effect):
    """The flexible "none of these" model over the record [t0, t1] (s)."""

    id = DISCREPANCY_ID
    title = "none of these: a smooth torque on the body (and hinge) that no catalog effect explains"
    scenarios = ("tumbling_rigid", "hinged_appendage")
    law = staticmethod(law)

    def __init__(self, t0: float, t1: float):
        self.t0, self.t1 = float(t0), float(t1)

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """Three Legendre coefficients (N m) per body axis (B) and, hinged, for the hinge torque.

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case; its plant sizes the torques.
        channels : sequence of str, optional
            Not used.
        """
        plant = Plant.from_case(case)
        specs = []
        for axis in "xyz":
            scale = body_torque_scale(plant)
            specs += [Parameter(f"body_torque_{axis}_P{k}", "N m", f"Legendre term {k} of the body torque about "
                                f"{axis} (body frame)", scale, -1e3 * scale, 1e3 * scale) for k in range(TERMS)]
        if plant.hinged:
            scale = torque_scale(plant)
            specs += [Parameter(f"hinge_torque_P{k}", "N m", f"Legendre term {k} of the hinge torque", scale,
                                -1e3 * scale, 1e3 * scale) for k in range(TERMS)]
        return specs

    def law_parameters(self, plant: Plant, values: np.ndarray) -> np.ndarray:
        """[t0, t1, hinged] followed by the coefficients.

        Parameters
        ----------
        plant : Plant
            The plant (hinged or not).
        values : (9,) or (12,) float
            Legendre coefficients (N m): body torque about B x, y, z, then the hinge torque.

        Returns
        -------
        p : (12,) or (15,) float
            The law's parameters.
        """
        return np.r_[self.t0, self.t1, float(plant.hinged), np.asarray(values, float)]

    def starts(self, specs):
        """One start: no torque.

        Parameters
        ----------
        specs : list of Parameter
            The coefficients.

        Returns
        -------
        starts : list of (m,) float
            Zeros (N m).
        """
        return [np.zeros(len(specs))]

    def add_to_exudyn(self, builder, values, names):
        """The series torques on the main body (B) and the hinge.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a body torque (N m, body frame) and a hinge torque (N m).
        values : (9,) or (12,) float
            Legendre coefficients (N m).
        names : sequence of str
            Not used.
        """
        values = np.asarray(values, float)
        t0, t1 = self.t0, self.t1

        def series(t, coefficients):
            return float(np.dot(_legendre(t, t0, t1), coefficients))

        body = values[:3 * TERMS].reshape(3, TERMS)
        builder.add_body_torque(lambda t, k, rot, omega: np.array([series(t, c) for c in body]) if k == 0
                                else np.zeros(3))
        if len(values) > 3 * TERMS:
            builder.add_hinge_torque(lambda t, angle, rate: series(t, values[3 * TERMS:]))


def none_of_these(decision: dict, fits: dict, weights: dict) -> dict:
    """The decision with the "none of these" alternative: a named cause whose BIC is not lower than
    the discrepancy model's becomes "unexplained"; the confidence is the cause's posterior weight
    among every model including the discrepancy (``weights``).

    Parameters
    ----------
    decision : dict
        :func:`riskassess.diagnosis.selection.decide`'s answer over the catalog models.
    fits : dict of str to FitResult
        Fitted models by id, the discrepancy's among them.
    weights : dict of str to float
        Posterior weights over every model including the discrepancy (-).

    Returns
    -------
    decision : dict
        The answer, its cause, confidence (-) and reason revised.
    """
    if DISCREPANCY_ID not in fits:
        return decision
    cause = decision["cause"]
    if cause in ("none", "unexplained"):
        if cause == "none" and decision["confidence"] is not None:
            return {**decision, "confidence": weights.get("nominal", decision["confidence"])}
        return decision
    margin = fits[DISCREPANCY_ID].bic - fits[cause].bic
    if margin <= 0.0:
        return {**decision, "cause": "unexplained", "confidence": None,
                "reason": f"{cause} is the best catalog candidate, but a flexible torque outside the catalog "
                          f"('none of these') explains the data better (BIC lower by {-margin:.1f}): the cause "
                          f"is likely not in the catalog. {decision['reason']}"}
    return {**decision, "confidence": weights[cause],
            "reason": decision["reason"] + f"; better than a flexible torque outside the catalog by {margin:.1f} in BIC"}
