""""None of these": generic alternatives that compete with the catalog's effects.

The BIC weights of the selection compare catalog models only, so a confidence of 1.00 could mean "the
best of a wrong list". The models here stand for effects outside the catalog: generic forms of an
unexplained load, each fitted like any candidate and scored by the same BIC (whose k ln n term is its
penalty for freedom). They are written in the terms every rigid-body load can be expanded in: time,
the body rates, the attitude, and a force on the centre of mass:

* ``none_of_these`` (time): a smooth torque on the main body (3 axes, B) and, for a hinged appendage,
  about the hinge, each a quadratic Legendre series over the record (9 or 12 parameters),

  .. math:: \\tau_j(t) = \\sum_{k=0}^{2} c_{jk} P_k(s),\\qquad s = 2 (t - t_0) / (t_1 - t_0) - 1;

* ``none_of_these_body_torque``: a constant torque fixed in the body (B; 3 parameters: a venting jet or
  a thruster leak fixed on the body);
* ``none_of_these_rate_damping``: a damping of unknown law along the body rates,
  :math:`\\tau = -c\\,(|\\omega| / \\omega_0)^{e - 1}\\,\\omega` (B; 2 parameters: c and the exponent e,
  0 to 4: Coulomb-like, viscous, aerodynamic-like quadratic ...; omega_0 the case's initial rate);
* ``none_of_these_damping_matrix``: the general linear torque in the body rates,
  :math:`\\tau = -D\\,\\omega` (B; D 3 x 3, 9 parameters: anisotropic and gyroscopic-like terms);
* ``none_of_these_inertial_torque``: a constant torque fixed in inertial space (I; 3 parameters:
  solar-pressure-like, a venting jet with a fixed direction in I);
* ``none_of_these_com_force``: a constant force on the centre of mass (I; 3 parameters; only when a
  position channel is measured).

Why several small forms, not one big one: a catalog effect is a *specific structure* (the eddy-current
brake, say, is a linear rate damping whose null direction is a field fixed in inertial space). It is
named only when that structure explains the data decisively better than every generic form (by the
case's ``decisive_delta_bic``, as against a catalog runner-up; :func:`none_of_these`), each penalized for
its own freedom. One large generic model would pay for all its terms at once (21
parameters cost ~170 in BIC on a 40 s record) and lose to any 3-parameter catalog member that happens to
fit; a damping quadratic in the rates, at the nearly constant spin of a 40 s record, acts as a linear
one, which the eddy-current law with its field normal to the spin reproduces exactly: the data then say
"a rate damping", not "eddy currents", and the 2-parameter generic damping ties or wins. Where the
catalog effect's distinctive signature is in the data (the field's null direction seen by a tumbling
body, a damper that keeps the angular momentum, a friction that sticks), no generic form of comparable
freedom reproduces it and the catalog effect wins.

The generic forms are never a cause themselves: they are the "none of these" alternative, listed with
the candidates and included in the confidence (the posterior weight over catalog models and these).
Sensor effects outside the catalog (a scale factor, a misalignment) have no generic form here: they rely
on the adequacy and structure tests. The towing scenario has none.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, L_F, L_TH, L_TM, X_Q, X_W, quaternion_rows, tmtv
from riskassess.diagnosis.effects.base import Effect, Parameter, torque_scale
from riskassess.diagnosis.plants.plant import Plant

#: Legendre terms per torque component (degrees 0-2: a constant, a drift and a curvature over the record).
TERMS = 3
#: The time form's id in the candidate list (never a catalog cause); the other forms' ids start with it.
DISCREPANCY_ID = "none_of_these"

# layout of the law's parameter vector p (every form fills its own slots, the others are zero)
P_T0, P_T1, P_HINGED, P_RATE0 = 0, 1, 2, 3
P_LEGENDRE = 4                  # body torque, Legendre, 3 axes x TERMS (N m, B)
P_HINGE = P_LEGENDRE + 3 * TERMS  # hinge torque, Legendre, TERMS (N m)
P_MATRIX = P_HINGE + TERMS      # D, row-major (N m s): tau = -D omega (B)
P_INERTIAL = P_MATRIX + 9       # constant torque (N m, I)
P_POWER = P_INERTIAL + 3        # c (N m s), exponent (-): tau = -c (|omega| / omega_0)^(e - 1) omega (B)
P_FORCE = P_POWER + 2           # constant force on the CoM (N, I)
P_SIZE = P_FORCE + 3


@njit(cache=True)
def _legendre(t, t0, t1):
    s = 2.0 * (t - t0) / (t1 - t0) - 1.0
    return 1.0, s, 1.5 * s * s - 0.5


@njit(cache=True)
def body_torque(t, rot, omega, p):
    """The generic torque on the main body (N m, B, 3-tuple): every form's terms of ``p``.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    rot : 9-sequence of float
        Rotation B -> I, row-major (-).
    omega : 3-sequence of float
        Inertial angular velocity of the main body, B (rad/s).
    p : (P_SIZE,) float
        The law's parameters (layout ``P_*``).

    Returns
    -------
    torque_body : tuple of 3 float
        Legendre series + (-D omega) + R^T tau_I + power-law damping (N m, B).
    """
    b0, b1, b2 = _legendre(t, p[P_T0], p[P_T1])
    inertial = tmtv(rot, (p[P_INERTIAL], p[P_INERTIAL + 1], p[P_INERTIAL + 2]))
    rate = np.sqrt(omega[0] ** 2 + omega[1] ** 2 + omega[2] ** 2)
    power = 0.0
    if p[P_POWER] != 0.0 and rate > 0.0:
        power = p[P_POWER] * (rate / p[P_RATE0]) ** (p[P_POWER + 1] - 1.0)
    out = [0.0, 0.0, 0.0]
    for axis in range(3):
        k = P_LEGENDRE + TERMS * axis
        m = P_MATRIX + 3 * axis
        out[axis] = (p[k] * b0 + p[k + 1] * b1 + p[k + 2] * b2
                     - (p[m] * omega[0] + p[m + 1] * omega[1] + p[m + 2] * omega[2])
                     + inertial[axis] - power * omega[axis])
    return out[0], out[1], out[2]


@njit(cache=True)
def hinge_torque(t, p):
    """The generic hinge torque (N m): the Legendre series of ``p``.

    Parameters
    ----------
    t : float
        Time (s).
    p : (P_SIZE,) float
        The law's parameters (layout ``P_*``).

    Returns
    -------
    torque : float
        About the hinge axis, on the appendage (N m).
    """
    b0, b1, b2 = _legendre(t, p[P_T0], p[P_T1])
    return p[P_HINGE] * b0 + p[P_HINGE + 1] * b1 + p[P_HINGE + 2] * b2


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """The generic loads of every form (layout ``P_*``).

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (P_SIZE,) float
        t0, t1 (s), hinged flag, omega_0 (rad/s), then the forms' coefficients (layout ``P_*``).
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the torque on the main body (``L_TM``, B, N m), the
        hinge torque (``L_TH``, N m) and the force on the CoM (``L_F``, I, N).
    xe, xe_rate : (0,) float
        The law's own states and their rates: none (the generic forms declare no ``extra_states``).
    """
    torque = body_torque(t, quaternion_rows(x[X_Q:X_Q + 4]), (x[X_W], x[X_W + 1], x[X_W + 2]), p)
    for axis in range(3):
        load[L_TM + axis] += torque[axis]
        load[L_F + axis] += p[P_FORCE + axis]
    if p[P_HINGED] > 0.0:
        load[L_TH] += hinge_torque(t, p)


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


def reference_rate(plant: Plant) -> float:
    """omega_0 of the power-law damping (rad/s): the case's initial body rate, at least 0.01 rad/s.

    Parameters
    ----------
    plant : Plant
        Its initial inertial angular velocity (rad/s, B).

    Returns
    -------
    omega_0 : float
        (rad/s).
    """
    return max(float(np.linalg.norm(plant.omega0)), 0.01)


def _coefficients(names, unit, what, scale):
    return [Parameter(name, unit, what(name), scale, -1e3 * scale, 1e3 * scale) for name in names]


class GenericForm(Effect):
    """Base of the generic forms over the record [t0, t1] (s): each fills its slots of the law's ``p``."""

    id = DISCREPANCY_ID
    title = ""
    scenarios = ("tumbling_rigid", "hinged_appendage")
    law = staticmethod(law)
    #: First slot of the form's coefficients in ``p`` (layout ``P_*``).
    slot = P_LEGENDRE
    #: One line for the answer's ``none_of_these`` entry.
    model = ""

    def __init__(self, t0: float, t1: float):
        self.t0, self.t1 = float(t0), float(t1)

    def law_parameters(self, plant: Plant, values: np.ndarray) -> np.ndarray:
        """[t0, t1, hinged, omega_0] and the form's coefficients in their slots, zero elsewhere.

        Parameters
        ----------
        plant : Plant
            The plant (hinged or not, its initial rate).
        values : (m,) float
            The form's coefficients (units of :meth:`parameter_specs`).

        Returns
        -------
        p : (P_SIZE,) float
            The law's parameters.
        """
        p = np.zeros(P_SIZE)
        p[:4] = self.t0, self.t1, float(plant.hinged), reference_rate(plant)
        values = np.asarray(values, float)
        p[self.slot:self.slot + len(values)] = values
        return p

    def starts(self, specs):
        """One start: the form switched off (zero load; the power law's exponent at 1, viscous).

        Parameters
        ----------
        specs : list of Parameter
            The coefficients.

        Returns
        -------
        starts : list of (m,) float
            Zeros (their units), the exponents at 1.
        """
        return [np.array([1.0 if s.name == "exponent" else 0.0 for s in specs])]

    def add_to_exudyn(self, builder, values, names):
        """The same loads on the Exudyn builder: the main body's torque (B), the hinge torque and the
        CoM's acceleration (I).

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder (its plant).
        values : (m,) float
            The form's coefficients.
        names : sequence of str
            Not used.
        """
        p = self.law_parameters(builder.plant, values)
        builder.add_body_torque(lambda t, k, rot, omega: np.array(body_torque(
            t, np.ascontiguousarray(rot, float).ravel(), np.asarray(omega, float), p)) if k == 0 else np.zeros(3))
        if builder.plant.hinged:
            builder.add_hinge_torque(lambda t, angle, rate: hinge_torque(t, p))
        if np.any(p[P_FORCE:P_FORCE + 3]):
            force = p[P_FORCE:P_FORCE + 3] / builder.plant.total_mass
            builder.add_com_acceleration(lambda t, r: force)


class Discrepancy(GenericForm):
    """A smooth torque in time on the main body (B) and the hinge: quadratic Legendre series."""

    id = DISCREPANCY_ID
    title = "none of these: a smooth torque on the body (and hinge) that no catalog effect explains"
    model = "a smooth torque on the body (and hinge), quadratic in time"

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
        specs = _coefficients([f"body_torque_{axis}_P{k}" for axis in "xyz" for k in range(TERMS)], "N m",
                              lambda n: f"Legendre term {n[-1]} of the body torque about {n[-4]} (body frame)",
                              body_torque_scale(plant))
        if plant.hinged:
            specs += _coefficients([f"hinge_torque_P{k}" for k in range(TERMS)], "N m",
                                   lambda n: f"Legendre term {n[-1]} of the hinge torque", torque_scale(plant))
        return specs


class BodyTorque(GenericForm):
    """A constant torque fixed in the main body (B): the time series' constant terms alone."""

    id = f"{DISCREPANCY_ID}_body_torque"
    title = "none of these: a constant torque fixed in the body"
    model = "a constant torque fixed in the body"

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """The torque's B components (N m).

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case; its plant sizes the torque.
        channels : sequence of str, optional
            Not used.
        """
        return _coefficients([f"body_torque_{a}" for a in "xyz"], "N m", lambda n: f"torque along B {n[-1]}",
                             body_torque_scale(Plant.from_case(case)))

    def law_parameters(self, plant: Plant, values: np.ndarray) -> np.ndarray:
        """The components as the Legendre series' P0 terms, the other terms zero.

        Parameters
        ----------
        plant : Plant
            The plant.
        values : (3,) float
            The torque (N m, B).

        Returns
        -------
        p : (P_SIZE,) float
            The law's parameters.
        """
        series = np.zeros(3 * TERMS)
        series[::TERMS] = np.asarray(values, float)
        return super().law_parameters(plant, series)


class RateDamping(GenericForm):
    """A damping of the body rates with a free power law: -c (|omega| / omega_0)^(e - 1) omega (B)."""

    id = f"{DISCREPANCY_ID}_rate_damping"
    title = "none of these: a damping of the body rates with a free power law"
    model = "a damping of the body rates, -c (|omega|/omega_0)^(e-1) omega, e free (0-4)"
    slot = P_POWER

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """c (N m s, either sign) and the exponent e (-, 0 to 4).

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case; its plant sizes c.
        channels : sequence of str, optional
            Not used.
        """
        plant = Plant.from_case(case)
        scale = body_torque_scale(plant) / reference_rate(plant)
        return [Parameter("coefficient", "N m s", "torque per unit body rate at omega_0", scale, -1e3 * scale,
                          1e3 * scale),
                Parameter("exponent", "-", "power of the rate in the torque's magnitude", 1.0, 0.0, 4.0)]


class DampingMatrix(GenericForm):
    """The general linear torque in the body rates: -D omega (B), D 3 x 3."""

    id = f"{DISCREPANCY_ID}_damping_matrix"
    title = "none of these: a torque linear in the body rates"
    model = "a torque linear in the body rates, -D omega (D 3 x 3, body frame)"
    slot = P_MATRIX

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """D row-major (N m s).

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case; its plant sizes D.
        channels : sequence of str, optional
            Not used.
        """
        plant = Plant.from_case(case)
        return _coefficients([f"damping_{a}{b}" for a in "xyz" for b in "xyz"], "N m s",
                             lambda n: f"torque about {n[-2]} per unit rate about {n[-1]} (body frame)",
                             body_torque_scale(plant) / reference_rate(plant))


class InertialTorque(GenericForm):
    """A constant torque fixed in inertial space (I)."""

    id = f"{DISCREPANCY_ID}_inertial_torque"
    title = "none of these: a constant torque fixed in inertial space"
    model = "a constant torque fixed in inertial space"
    slot = P_INERTIAL

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """The torque's I components (N m).

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case; its plant sizes the torque.
        channels : sequence of str, optional
            Not used.
        """
        return _coefficients([f"inertial_torque_{a}" for a in "xyz"], "N m",
                             lambda n: f"torque along I {n[-1]}", body_torque_scale(Plant.from_case(case)))


class ComForce(GenericForm):
    """A constant force on the centre of mass (I)."""

    id = f"{DISCREPANCY_ID}_com_force"
    title = "none of these: a constant force on the centre of mass"
    model = "a constant force on the centre of mass, fixed in inertial space"
    channels = ("rel_x", "rel_y", "rel_z")
    slot = P_FORCE

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """The force's I components (N), sized as 1 mm/s per 100 s.

        Parameters
        ----------
        case : TumblingRigidCase or HingedAppendageCase
            Validated diagnosis case; its mass sizes the force.
        channels : sequence of str, optional
            Not used.
        """
        scale = 1e-5 * Plant.from_case(case).total_mass
        return _coefficients([f"force_{a}" for a in "xyz"], "N", lambda n: f"force along I {n[-1]}", scale)


#: The generic forms, in the order they are fitted.
FORMS = (Discrepancy, BodyTorque, RateDamping, DampingMatrix, InertialTorque, ComForce)


def generic_forms(t0: float, t1: float) -> list[GenericForm]:
    """Every generic form over the record [t0, t1] (s).

    Parameters
    ----------
    t0, t1 : float
        The record's first and last time (s).

    Returns
    -------
    forms : list of GenericForm
    """
    return [form(t0, t1) for form in FORMS]


def is_generic(model_id: str) -> bool:
    """Whether ``model_id`` is one of the generic forms (never a cause).

    Parameters
    ----------
    model_id : str
        A model id.

    Returns
    -------
    generic : bool
    """
    return model_id == DISCREPANCY_ID or model_id.startswith(DISCREPANCY_ID + "_")


def none_of_these(decision: dict, fits: dict, weights: dict, decisive: float = 0.0) -> dict:
    """The decision with the "none of these" alternative: a named cause whose BIC is not lower than
    every generic form's by more than ``decisive`` becomes "unexplained" (the data do not single out its
    own structure: the same rule as against a catalog runner-up); the confidence is the cause's posterior
    weight among every model including the generic forms (``weights``).

    Parameters
    ----------
    decision : dict
        :func:`riskassess.diagnosis.selection.decide`'s answer over the catalog models.
    fits : dict of str to FitResult
        Fitted models by id, the generic forms' among them.
    weights : dict of str to float
        Posterior weights over every model including the generic forms (-).
    decisive : float
        BIC margin the cause needs over the best generic form (-; the case's ``decisive_delta_bic``).

    Returns
    -------
    decision : dict
        The answer, its cause, confidence (-) and reason revised.
    """
    generic = [k for k in fits if is_generic(k)]
    if not generic:
        return decision
    cause = decision["cause"]
    if cause in ("none", "unexplained"):
        if cause == "none" and decision["confidence"] is not None:
            return {**decision, "confidence": weights.get("nominal", decision["confidence"])}
        return decision
    best = min(generic, key=lambda k: fits[k].bic)
    margin = fits[best].bic - fits[cause].bic
    what = f"a generic alternative outside the catalog ('{best}', {len(fits[best].names) - fits[best].nominal_count} " \
           f"parameters)"
    if margin <= decisive:
        how = f"better (BIC lower by {-margin:.1f})" if margin <= 0 else \
            f"about as well (BIC higher by only {margin:.1f}, not more than {decisive:g})"
        return {**decision, "cause": "unexplained", "confidence": None,
                "reason": f"{cause} is the best catalog candidate, but {what} explains the data {how}: the data do "
                          f"not single out {cause}'s own structure, the cause may be outside the catalog. "
                          f"{decision['reason']}"}
    return {**decision, "confidence": weights[cause],
            "reason": decision["reason"] + f"; better than the best generic alternative outside the catalog "
                                           f"({best}) by {margin:.1f} in BIC"}
