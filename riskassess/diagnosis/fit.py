"""Fit of the nominal uncertain parameters plus one effect's parameters to the training data.

Noise-weighted least squares (:func:`scipy.optimize.least_squares`, trust region reflective,
bounds from the effect's parameters): residuals are (model - measured) / sigma of every
training sample plus (theta - theta_case) / sigma_prior of each uncertain nominal parameter
(Gaussian prior from the case's ``[uncertain]`` table). Parameters are scaled (prior sigma,
effect's typical size) so that the optimizer sees unit-sized steps; an effect parameter marked
``log`` is fitted as ln(value / typical) (a product of two parameters that the data see better
than its factors is then a straight valley, which Gauss-Newton steps follow, not a hyperbola).
The fit runs first on the first part of the training span, then on all of it (a long tumble's
phase error has many local minima when it is seen at once), from each of the effect's starting
points; a towing candidate instead starts from the best of its starting points scored by one run
each (:meth:`CandidateFit.fit`; Broyden Jacobians, a coarser difference step and a Gauss-Newton
stopping rule for that model: its chi^2 is piecewise smooth, docs/diagnosis.md).
The parameter covariance is (J^T J)^-1 at the optimum, scaled by chi^2 / dof when that exceeds 1.
"""
from __future__ import annotations

import time as clock
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from riskassess.diagnosis.effects.base import Effect, Parameter, switched_off
from riskassess.diagnosis.model import max_step, predict
from riskassess.diagnosis.plants.channels import QUATERNION
from riskassess.diagnosis.observation import scenario_channels
from riskassess.diagnosis.plants.plant import (NOMINAL_PARAMETERS, Plant, is_towing, nominal_parameter_names, nominal_vector,
                                        prior_sigmas, with_nominal)
from riskassess.diagnosis.residuals import aligned_quaternion
from riskassess.diagnosis.plants.scenario import plant_of

#: Share of the training span fitted first (continuation).
FIRST_SPAN = 0.35
#: least_squares tolerances: relative change of the cost and of the (scaled) parameters.
TOLERANCE = 1e-8
#: Model evaluations per stage before the optimizer stops: the right model converges in about ten
#: iterations; a wrong one is not worth more (its BIC is far off anyway).
MAX_EVALUATIONS = 30
#: Forward-difference step of the Jacobian, scaled parameters (1 = a prior sigma or a typical size);
#: the RK4 model is smooth and deterministic to ~1e-13, so 1e-6 leaves ~1e-7 relative error.
DIFFERENCE_STEP = 1e-6
#: The same for the towing model: it integrates Earth-centred positions (~7e6 m, round-off ~1e-9 m) and
#: the tension's damper term takes differences of 7.5 km/s velocities, so its channels carry round-off
#: noise that a small step amplifies: against 1e-3, the columns at 1e-6 were 50-800 % off, at 1e-5
#: 10-90 %, at 1e-4 1-8 % (the error falls as 1/step: noise); at 1e-2 some were 100 % off the other way
#: (the tension-only tethers' kinks). Measured on the sample record's first 80 s (docs/diagnosis.md).
TOWING_DIFFERENCE_STEP = 1e-3
#: Largest discretization error of the towing model (RMS, in noise sigmas) the fit accepts (resolved_step).
STEP_ERROR_SIGMA = 0.2
#: Broyden updates between two finite-difference Jacobians (towing model only, see CandidateFit.jacobian).
BROYDEN_REFRESH = 3
#: Stopping rule of the towing fits (CandidateFit._refine): converged when one Gauss-Newton step from a fresh
#: finite-difference Jacobian predicts a chi^2 decrease below this: the parameters are then within about
#: sqrt(0.25) = 0.5 of their standard deviations of the minimum, the BIC within 0.25 (the decisive margin is 10).
CONVERGED_CHI2 = 0.25
#: Further legs from a fresh Jacobian when the rule is not met: one. The towing model's chi^2 is only piecewise
#: smooth (a tether that snaps taut within one step or the next changes that sample's tension by c e', up to
#: 30 sigma: jumps of ~1000 in chi^2 a millimetre apart in the initial position, docs/diagnosis.md), so the
#: rule often cannot be met; a second further leg gained < 10 in chi^2 on the sample record.
MAX_LEGS = 1
#: Towing candidates: starting points fitted on the early span first (:func:`early_starts`): those whose chi^2
#: there is within this factor of the best start's, at most ``EARLY_FITS`` of them, each for at most
#: ``EARLY_EVALUATIONS`` (it only has to find the basin: the fit on the training span follows; three fits of 30
#: evaluations made the whole-catalog bench 77 s instead of 56 s).
EARLY_TIE = 2.0
EARLY_FITS = 2
EARLY_EVALUATIONS = 15
#: Nominal parameters whose effect on the residuals is linear (the CoM's initial position and
#: velocity in the linear relative orbit): their Jacobian columns are computed once per fit.
LINEAR_NOMINAL = ("position", "velocity")


@dataclass
class Problem:
    """What every candidate is fitted to: the case's plant, the measured channels the scenario
    predicts, the noise, the training samples and the nominal uncertain parameters."""

    case: object
    plant: Plant
    time: np.ndarray
    values: dict
    noise: dict
    train: np.ndarray                 # (k,) bool, samples used by the fit
    nominal_names: list
    nominal_center: np.ndarray
    nominal_sigma: np.ndarray

    @classmethod
    def build(cls, case, measured, holdout_fraction: float) -> "Problem":
        """The problem of a case and its measured record: the channels the scenario predicts, their noise,
        the training samples (all but the last ``holdout_fraction`` of the record) and the uncertain
        nominal parameters (towing: the fit step resolved against the noise, :func:`resolved_step`).

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case.
        measured : MeasuredData
            The record (:func:`riskassess.diagnosis.measured.read_measured`): times (s), channels (SI),
            noise 1-sigma (channel units).
        holdout_fraction : float
            Share of the record's duration held out of the fit (-), in (0, 1).

        Returns
        -------
        problem : Problem
        """
        plant = plant_of(case)
        used = [c for c in measured.values if c in scenario_channels(plant)]
        time = measured.time
        split = time[0] + (1.0 - holdout_fraction) * (time[-1] - time[0])
        names = nominal_parameter_names(case, used)
        noise = {c: measured.noise[c] for c in used}
        if is_towing(plant):
            plant = plant.replace(fit_step=resolved_step(plant, time, noise))
        return cls(case, plant, time, {c: measured.values[c] for c in used}, noise, time <= split, names,
                   nominal_vector(plant, names), prior_sigmas(case, names))

    @property
    def channels(self) -> list[str]:
        return list(self.values)

    @property
    def split_time(self) -> float:
        return float(self.time[self.train][-1])


@dataclass
class FitResult:
    """One fitted model (``id`` "nominal" or an effect id)."""

    id: str
    names: list
    units: list
    values: np.ndarray
    std: np.ndarray
    nominal_count: int
    chi2_data: float
    chi2_prior: float
    n_data: int
    seconds: float
    evaluations: int
    message: str
    effect_values: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_parameters(self) -> int:
        return len(self.names)

    @property
    def bic(self) -> float:
        """Schwarz (1978): -2 ln L + k ln n, with the Gaussian noise model (constants dropped)."""
        return self.chi2_data + self.chi2_prior + self.n_parameters * np.log(self.n_data)


#: Residual (sigmas) of a sample the model failed to predict (not finite) where a measurement
#: exists: a diverged model must lose the fit, never look perfect (issue 20: a NaN residual used
#: to count as 0).
DIVERGED_RESIDUAL_SIGMA = 1e6


def sample_residuals(model, measured, sigma) -> np.ndarray:
    """(model - measured) / sigma per sample: 0 where the measurement is missing (NaN), and
    :data:`DIVERGED_RESIDUAL_SIGMA` where it exists but the model's value is not finite.

    Parameters
    ----------
    model : (k,) float
        Predicted channel (channel unit).
    measured : (k,) float
        Measured channel (channel unit), NaN where missing.
    sigma : float
        The channel's 1-sigma noise (channel unit).

    Returns
    -------
    r : (k,) float
        Normalized residuals (-).
    """
    model, measured = np.asarray(model, float), np.asarray(measured, float)
    present = np.isfinite(measured)
    r = np.where(np.isfinite(model), (model - np.where(present, measured, 0.0)) / sigma, DIVERGED_RESIDUAL_SIGMA)
    return np.where(present, r, 0.0)


def first_unpredicted_time(times, model: dict, measured: dict) -> float | None:
    """Time (s) of the first measured sample a model prediction leaves non-finite, or None.

    Parameters
    ----------
    times : (k,) float
        Sample times (s).
    model : dict of str to (k,) float
        Predicted channels.
    measured : dict of str to (k,) float
        Measured channels, NaN where missing.

    Returns
    -------
    time : float or None
        (s).
    """
    bad = np.zeros(len(times), bool)
    for c, values in measured.items():
        if c in model:
            bad |= np.isfinite(values) & ~np.isfinite(np.asarray(model[c], float))
    return float(np.asarray(times)[np.argmax(bad)]) if bad.any() else None


class CandidateFit:
    """Fit of the nominal model (``effect`` None) or nominal + one effect to a :class:`Problem`."""

    def __init__(self, problem: Problem, effect: Effect | None = None, columns=None):
        """``columns``: None, or a function (list of parameter vectors z, sample mask) -> their residual
        vectors (:meth:`residuals` of this problem and effect, e.g. in worker processes) that computes the
        finite-difference columns of a Jacobian together."""
        self.problem = problem
        self.effect = effect
        self.columns = columns
        self.specs: list[Parameter] = effect.parameter_specs(problem.case, problem.channels) if effect else []
        self.log = np.array([p.log for p in self.specs], bool)
        self.scale = np.array([p.typical if p.log else max(abs(p.typical), (p.upper - p.lower) / 20.0)
                               for p in self.specs])
        self.step = max_step(problem.plant, effect.stiffness_rate(problem.plant, self.specs) if effect else 0.0)
        # (towing: the tether couples the debris' position to everything, nothing is linear)
        linear_nominal = [n in LINEAR_NOMINAL and not is_towing(problem.plant) for n in _expanded(problem.nominal_names)]
        self.broyden = is_towing(problem.plant)
        self.difference_step = TOWING_DIFFERENCE_STEP if self.broyden else DIFFERENCE_STEP
        self.linear = np.r_[np.array(linear_nominal, bool),
                            np.full(len(self.specs), bool(effect is not None and getattr(effect, "linear", False)))]
        self._cache = {}

    # -- parameter vector ------------------------------------------------------------------
    def unpack(self, z):
        """The nominal parameters and the effect's parameters (SI) of the fit variables ``z``.

        Parameters
        ----------
        z : (n_nominal + m,) float
            Fit variables: the nominal parameters as (value - case value) / prior sigma (-), then the
            effect's scaled parameters (:meth:`scaled`, -).

        Returns
        -------
        nominal : (n_nominal,) float
            Nominal parameter values (units and frames of :func:`riskassess.diagnosis.plants.plant.nominal_vector`).
        values : (m,) float
            The effect's physical parameters (SI).
        """
        n = len(self.problem.nominal_center)
        nominal = self.problem.nominal_center + self.problem.nominal_sigma * z[:n]
        return nominal, self.physical(z[n:])

    def physical(self, z_effect) -> np.ndarray:
        """The effect's parameters (SI) from their fit variables: value / scale, or ln(value / typical)
        for a ``log`` parameter.

        Parameters
        ----------
        z_effect : (m,) float
            The effect's fit variables (-).

        Returns
        -------
        values : (m,) float
            Physical values, each in its parameter's unit.
        """
        return self.scale * np.where(self.log, np.exp(np.where(self.log, z_effect, 0.0)), z_effect)

    def scaled(self, values) -> np.ndarray:
        """The fit variables of the effect's parameters ``values`` (SI): the inverse of :meth:`physical`.

        Parameters
        ----------
        values : (m,) float
            Physical values, each in its parameter's unit.

        Returns
        -------
        z_effect : (m,) float
            Fit variables (-).
        """
        values = np.asarray(values, float)
        ratio = values / self.scale
        return np.where(self.log, np.log(np.where(self.log, np.maximum(ratio, 1e-300), 1.0)), ratio)

    def _bounds(self):
        p = self.problem
        low = np.full(len(p.nominal_center), -np.inf)
        for k, name in enumerate(_expanded(p.nominal_names)):
            if name in ("torsional_stiffness", "torsional_damping"):
                low[k] = -p.nominal_center[k] / p.nominal_sigma[k]
        low = np.r_[low, self.scaled([s.lower for s in self.specs])]
        high = np.r_[np.full(len(p.nominal_center), np.inf), self.scaled([s.upper for s in self.specs])]
        return low, high

    def null(self) -> np.ndarray:
        """The effect's parameters at zero, clipped into their bounds (SI): the effect switched off."""
        return switched_off(self.specs)

    # -- model ---------------------------------------------------------------------------
    def predict(self, z, times) -> dict:
        """Channels of the model at the fit variables ``z``.

        Parameters
        ----------
        z : (n_nominal + m,) float
            Fit variables: the nominal parameters as (value - case value) / prior sigma (-), then the
            effect's scaled parameters (:meth:`scaled`, -).
        times : (k,) float
            Sample times (s).

        Returns
        -------
        channels : dict of str to (k,) float
            Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
        """
        nominal, values = self.unpack(z)
        plant = with_nominal(self.problem.plant, self.problem.nominal_names, nominal)
        return predict(plant, times, self.effect, values, [s.name for s in self.specs], self.step)

    def residuals(self, z, use) -> np.ndarray:
        """The least-squares residual vector: normalized data residuals of the ``use`` samples, channel
        after channel, then the nominal parameters' prior residuals.

        Parameters
        ----------
        z : (n_nominal + m,) float
            Fit variables: the nominal parameters as (value - case value) / prior sigma (-), then the
            effect's scaled parameters (:meth:`scaled`, -).
        use : (k,) bool
            Mask of the problem's samples to use.

        Returns
        -------
        f : (n_channels * k_use + n_nominal,) float
            (model - measured) / sigma, then (value - case value) / prior sigma (-).
        """
        p = self.problem
        model = aligned_quaternion(self.predict(z, p.time[use]), {c: v[use] for c, v in p.values.items()})
        r = np.concatenate([sample_residuals(model[c], v[use], p.noise[c]) for c, v in p.values.items()])
        return np.r_[r, z[:len(p.nominal_center)]]

    def _fun(self, z, use):
        f = self.residuals(z, use)
        self._cache["last"] = (z.copy(), f)
        return f

    def jacobian(self, z, use):
        """Forward differences (:meth:`difference_jacobian`); for the towing model, whose runs cost
        ~0.1 s, only every ``BROYDEN_REFRESH + 1``-th call, Broyden's rank-one update of the last one
        in between (Broyden 1965; the linear parameters' columns stay exact).

        Parameters
        ----------
        z : (n_nominal + m,) float
            Fit variables: the nominal parameters as (value - case value) / prior sigma (-), then the
            effect's scaled parameters (:meth:`scaled`, -).
        use : (k,) bool
            Mask of the problem's samples to use.

        Returns
        -------
        jac : (len(f), len(z)) float
            d residuals / d z (-).
        """
        if not self.broyden:
            return self.difference_jacobian(z, use)
        z_last, f0 = self._cache.get("last", (None, None))
        if z_last is None or not np.array_equal(z_last, z):
            f0 = self.residuals(z, use)
        key = ("broyden", use.tobytes())
        state = self._cache.get(key)
        if state is None or state["age"] >= BROYDEN_REFRESH:
            jac, age = self.difference_jacobian(z, use), 0
        else:
            dz, jac = z - state["z"], state["jac"].copy()
            if dz @ dz > 0:
                jac += np.outer(f0 - state["f"] - jac @ dz, dz) / (dz @ dz)
            linear = self._cache.get(("linear", use.tobytes()), {})
            for i, column in linear.items():
                jac[:, i] = column
            age = state["age"] + 1
        self._cache[key] = {"z": z.copy(), "f": f0.copy(), "jac": jac, "age": age}
        return jac

    def difference_jacobian(self, z, use):
        """Forward differences, one column per parameter (together through ``columns`` when given);
        the columns of linear parameters are computed once per sample set and reused.

        Parameters
        ----------
        z : (n_nominal + m,) float
            Fit variables: the nominal parameters as (value - case value) / prior sigma (-), then the
            effect's scaled parameters (:meth:`scaled`, -).
        use : (k,) bool
            Mask of the problem's samples to use.

        Returns
        -------
        jac : (len(f), len(z)) float
            d residuals / d z (-).
        """
        z_last, f0 = self._cache.get("last", (None, None))
        if z_last is None or not np.array_equal(z_last, z):
            f0 = self.residuals(z, use)
        key = ("linear", use.tobytes())
        jac = np.empty((f0.size, z.size))
        _, high = self._bounds()
        todo, shifted, steps = [], [], []
        for i in range(z.size):
            if self.linear[i] and key in self._cache:
                jac[:, i] = self._cache[key][i]
                continue
            step = self.difference_step
            h = step * max(1.0, abs(z[i])) * (-1.0 if z[i] + 2 * step > high[i] else 1.0)
            todo.append(i)
            steps.append(h)
            shifted.append(z.copy())
            shifted[-1][i] += h
        values = self.columns(shifted, use) if self.columns else [self.residuals(zi, use) for zi in shifted]
        for i, h, f in zip(todo, steps, values):
            jac[:, i] = (f - f0) / h
        if key not in self._cache:
            self._cache[key] = {i: jac[:, i].copy() for i in np.flatnonzero(self.linear)}
        return jac

    # -- fitting -------------------------------------------------------------------------
    def _solve(self, z0, use, evaluations=MAX_EVALUATIONS):
        low, high = self._bounds()
        z0 = np.clip(z0, low + 1e-12 * (high - low > 0), high)
        return least_squares(self._fun, z0, jac=self.jacobian, args=(use,), bounds=(low, high), method="trf",
                             ftol=TOLERANCE, xtol=TOLERANCE, gtol=TOLERANCE, max_nfev=evaluations)

    def fit(self, nominal_start: FitResult | None = None) -> FitResult:
        """Fit from the case values, or from the nominal parameters of ``nominal_start`` (the nominal
        model's fit: a candidate then starts where the nominal model ended).

        Parameters
        ----------
        nominal_start : FitResult, optional
            The nominal model's fit of the same problem.

        Returns
        -------
        result : FitResult
            Values (SI, nominal then effect), their standard deviations, chi^2 and BIC.
        """
        start = clock.perf_counter()
        p = self.problem
        t_train = p.time[p.train]
        first = p.train & (p.time <= t_train[0] + FIRST_SPAN * (t_train[-1] - t_train[0]))
        n_nominal = len(p.nominal_center)
        z_nominal = np.zeros(n_nominal) if nominal_start is None else \
            (nominal_start.values[:n_nominal] - p.nominal_center) / p.nominal_sigma
        starts = [np.r_[z_nominal, self.scaled(s)] for s in
                  (self.effect.starts(self.specs) if self.effect else [np.zeros(0)])]
        low, high = self._bounds()
        if nominal_start is not None and self.broyden:
            # towing candidate: no continuation on the early span from every start (the nominal fit it
            # starts from has the motion's phase already; that cost a third of the fits and left the
            # same minima on the sample record, docs/diagnosis.md); the fit starts from the best, on the
            # training span, of the effect's starting points and the effect switched off (its parameters
            # at zero, clipped into their bounds: the nominal model for every catalog effect), so that a
            # candidate never ends worse than the nominal model it contains. The starting points are
            # also tried from the case's own state: the nominal fit's state absorbs part of an effect
            # the nominal model lacks, and the towing model's chi^2 is too rough (piecewise smooth) for
            # the candidate's fit to walk back from there (a 12000 N/m, 80 s viscoelastic tether ended
            # 1060 above the truth's chi^2 from the nominal fit's state)
            case_state = [np.r_[np.zeros(n_nominal), z[n_nominal:]] for z in starts]
            candidates = [np.clip(z, low, high) for z in starts + case_state]
            # ... and fits on the early span from the starts that predict it best (:func:`early_starts`)
            stage1 = [self._solve(z, first, EARLY_EVALUATIONS)
                      for z in early_starts(candidates, lambda z: self.residuals(z, first))]
            options = candidates + [r.x for r in stage1] + [np.r_[z_nominal, self.scaled(self.null())]]
        else:
            stage1 = [self._solve(z0, first) for z0 in starts]
            options = [min(stage1, key=lambda r: r.cost).x]
        z2 = min(options, key=lambda z: float(np.sum(self.residuals(z, p.train) ** 2)))
        result = self._solve(z2, p.train)
        evaluations = sum(r.nfev for r in stage1) + result.nfev
        jac = None
        if self.broyden:
            result, jac, more = self._refine(result)
            evaluations += more
        return self._result(result, evaluations, clock.perf_counter() - start, jac)

    def _refine(self, result):
        """Towing (Broyden Jacobians): the stopping rule. A fresh finite-difference Jacobian at the end of
        a leg (the one the uncertainties need anyway) tells how much one Gauss-Newton step would still
        lower chi^2 (:func:`predicted_decrease`); above ``CONVERGED_CHI2`` another leg starts from it (at
        most ``MAX_LEGS``): Broyden's secant updates stop early, short of the minimum, along a valley.
        Returns the result, the Jacobian at its optimum and the further evaluations."""
        p = self.problem
        low, high = self._bounds()
        evaluations = 0
        for leg in range(MAX_LEGS + 1):
            jac = self.difference_jacobian(result.x, p.train)
            if leg == MAX_LEGS or predicted_decrease(jac, result.fun, result.x, low, high) <= CONVERGED_CHI2:
                break
            self._cache[("broyden", p.train.tobytes())] = {"z": result.x.copy(), "f": result.fun.copy(),
                                                           "jac": jac, "age": 0}
            more = self._solve(result.x, p.train)
            evaluations += more.nfev
            if more.cost >= result.cost:
                break
            result = more
        return result, jac, evaluations

    def _result(self, result, evaluations, seconds, jac=None) -> FitResult:
        p = self.problem
        n_nominal = len(p.nominal_center)
        chi2_prior = float(result.x[:n_nominal] @ result.x[:n_nominal])
        chi2_data = float(2.0 * result.cost - chi2_prior)
        n_data = int(sum(np.isfinite(v[p.train]).sum() for v in p.values.values()))
        if jac is None:      # the optimizer's own Jacobian: a finite-difference one, exact at the optimum
            jac = result.jac
        dof = max(n_data - len(result.x), 1)
        cov_z = np.linalg.pinv(jac.T @ jac) * max(1.0, chi2_data / dof)
        nominal, values = self.unpack(result.x)
        scale = np.r_[p.nominal_sigma, np.where(self.log, np.abs(values), self.scale)]   # d value / d z
        names = _expanded(p.nominal_names) + [s.name for s in self.specs]
        units = _expanded_units(p.nominal_names) + [s.unit for s in self.specs]
        return FitResult(self.effect.id if self.effect else "nominal", names, units, np.r_[nominal, values],
                         scale * np.sqrt(np.clip(np.diag(cov_z), 0.0, None)), n_nominal, chi2_data, chi2_prior,
                         n_data, seconds, evaluations, result.message, values)


def early_starts(starts, residuals) -> list:
    """The starting points (towing candidates) fitted on the early span first: those whose chi^2 there
    (``residuals(z)``, one run each) is within ``EARLY_TIE`` times the best's, at most ``EARLY_FITS``.

    An effect that builds up (eddy-current braking) is absorbed by the nominal fit's state over the
    training span, so that every start from that state looks worse than the nominal model, while the
    case's state predicts the early span ten times better (slow towing seed 1: 5e7 against 9e8). Among
    starts that differ only where the early span sees little (two field directions both normal to the
    spin: 4.914e7 and 4.915e7) one run cannot tell which leads to the truth (the first ended at chi^2
    2.6e7 on the training span, the second at 1.2e5, the truth has 2.3e4), so the near-ties are all fitted.

    Parameters
    ----------
    starts : list of (n,) float
        Starting fit variables z (-).
    residuals : callable
        z -> normalized residual vector on the early span (-).

    Returns
    -------
    chosen : list of (n,) float
        The starts to fit, best first.
    """
    early = sorted((float(np.sum(residuals(z) ** 2)), k) for k, z in enumerate(starts))
    return [starts[k] for chi2, k in early[:EARLY_FITS] if chi2 <= EARLY_TIE * early[0][0]]


def predicted_decrease(jac, f, z, low, high) -> float:
    """Decrease of chi^2 = |f|^2 that a Gauss-Newton step from ``z`` (residuals ``f``, Jacobian ``jac``)
    predicts, |J d|^2 with d the least-squares solution of J d = -f; a variable at a bound that the
    gradient pushes outwards is held. Near a minimum the parameters are then about sqrt(decrease)
    standard deviations from it (the quadratic model).

    Parameters
    ----------
    jac : (r, n) float
        d f / d z (-).
    f : (r,) float
        Normalized residuals (-).
    z : (n,) float
        Fit variables (-).
    low, high : (n,) float
        Their bounds (-).

    Returns
    -------
    decrease : float
        Predicted chi^2 decrease (-).
    """
    g = jac.T @ f
    held = ((z <= low + 1e-10) & (g > 0)) | ((z >= high - 1e-10) & (g < 0))
    free = jac[:, ~held]
    step = np.linalg.lstsq(free, -f, rcond=None)[0]
    return float(np.sum((free @ step) ** 2))


def resolved_step(plant, times, noise: dict, halvings: int = 3) -> float:
    """The towing model's step (s): the case's ``fit_step``, halved until the nominal model's
    discretization error, estimated by the step-doubling difference |y(h) - y(h/2)| (RMS per
    channel), is below ``STEP_ERROR_SIGMA`` of each channel's noise (at most ``halvings`` times): quiet
    sensors must not see the fit model's step as a discrepancy.

    Parameters
    ----------
    plant : TowingPlant
        The towing plant (its ``fit_step``, s).
    times : (k,) float
        Sample times (s).
    noise : dict of str to float
        1-sigma noise per channel (channel units).
    halvings : int
        Most halvings.

    Returns
    -------
    step : float
        (s).
    """
    step = plant.fit_step
    coarse = predict(plant, times, step=step)
    for _ in range(halvings):
        fine = predict(plant, times, step=step / 2)
        error = max(np.sqrt(np.mean((coarse[c] - fine[c]) ** 2)) / sigma for c, sigma in noise.items() if c in fine)
        if error <= STEP_ERROR_SIGMA:
            break
        step, coarse = step / 2, fine
    return step


def _expanded(names) -> list[str]:
    out = []
    for name in names:
        size = NOMINAL_PARAMETERS[name][0]
        out += [name] if size == 1 else [f"{name}_{a}" for a in "xyz"]
    return out


def _expanded_units(names) -> list[str]:
    return [NOMINAL_PARAMETERS[n][1] for n in names for _ in range(NOMINAL_PARAMETERS[n][0])]


def _fitted(problem: Problem, effect: Effect | None, fit: FitResult):
    """(the candidate of ``effect``, the fit variables z of ``fit``)."""
    candidate = CandidateFit(problem, effect)
    z = np.r_[(fit.values[:fit.nominal_count] - problem.nominal_center) / problem.nominal_sigma,
              candidate.scaled(fit.effect_values)]
    return candidate, z


def prediction(problem: Problem, effect: Effect | None, fit: FitResult, times) -> dict:
    """Channels of a fitted model at ``times`` (s).

    Parameters
    ----------
    problem : Problem
        The problem the model was fitted to.
    effect : Effect or None
        The candidate's effect; None: the nominal model.
    fit : FitResult
        Its fit.
    times : (k,) float
        Sample times (s).

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    candidate, z = _fitted(problem, effect, fit)
    return candidate.predict(z, times)


def step_error_sigma(problem: Problem, effect: Effect | None, fit: FitResult, predicted: dict) -> dict:
    """Per channel: the fitted model's own discretization error on the training part (RMS, noise sigmas),
    estimated as 2 |y(h) - y(h/2)| (the error of y(h) for a first-order scheme: the tension-only tethers'
    kinks make the towing scheme's convergence no better than first order); ``predicted``: y(h) over the
    whole record (:func:`prediction`), so that only y(h/2) is run here.

    Parameters
    ----------
    problem : Problem
        The problem the model was fitted to.
    effect : Effect or None
        The candidate's effect; None: the nominal model.
    fit : FitResult
        Its fit.
    predicted : dict of str to (k,) float
        The fitted model's channels at every sample of the record.

    Returns
    -------
    errors : dict of str to float
        Per channel, in noise sigmas (-).
    """
    candidate, z = _fitted(problem, effect, fit)
    candidate.step /= 2.0
    fine = candidate.predict(z, problem.time[problem.train])
    return {c: float(2.0 * np.sqrt(np.mean((predicted[c][problem.train] - fine[c]) ** 2)) / problem.noise[c])
            for c in problem.values}


__all__ = ["CandidateFit", "FitResult", "Problem", "prediction", "step_error_sigma", "QUATERNION"]
