"""Fit of the nominal uncertain parameters plus one effect's parameters to the training data.

Noise-weighted least squares (:func:`scipy.optimize.least_squares`, trust region reflective,
bounds from the effect's parameters): residuals are (model - measured) / sigma of every
training sample plus (theta - theta_case) / sigma_prior of each uncertain nominal parameter
(Gaussian prior from the case's ``[uncertain]`` table). Parameters are scaled (prior sigma,
effect's typical size) so that the optimizer sees unit-sized steps. The fit runs first on the
first part of the training span, then on all of it (a long tumble's phase error has many
local minima when it is seen at once), from each of the effect's starting points.
The parameter covariance is (J^T J)^-1 at the optimum, scaled by chi^2 / dof when that exceeds 1.
"""
from __future__ import annotations

import time as clock
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from diagnosis.effects.base import Effect, Parameter
from diagnosis.model import max_step, predict
from diagnosis.observation import QUATERNION, scenario_channels
from diagnosis.plant import (NOMINAL_PARAMETERS, Plant, is_towing, nominal_parameter_names, nominal_vector, plant_of,
                             prior_sigmas, with_nominal)
from diagnosis.residuals import aligned_quaternion

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
#: Largest discretization error of the towing model (RMS, in noise sigmas) the fit accepts (resolved_step).
STEP_ERROR_SIGMA = 0.2
#: Broyden updates between two finite-difference Jacobians (towing model only, see CandidateFit.jacobian).
BROYDEN_REFRESH = 3
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


class CandidateFit:
    """Fit of the nominal model (``effect`` None) or nominal + one effect to a :class:`Problem`."""

    def __init__(self, problem: Problem, effect: Effect | None = None):
        self.problem = problem
        self.effect = effect
        self.specs: list[Parameter] = effect.parameter_specs(problem.case, problem.channels) if effect else []
        self.scale = np.array([max(abs(p.typical), (p.upper - p.lower) / 20.0) for p in self.specs])
        self.step = max_step(problem.plant, effect.stiffness_rate(problem.plant, self.specs) if effect else 0.0)
        # (towing: the tether couples the debris' position to everything, nothing is linear)
        linear_nominal = [n in LINEAR_NOMINAL and not is_towing(problem.plant) for n in _expanded(problem.nominal_names)]
        self.broyden = is_towing(problem.plant)
        self.linear = np.r_[np.array(linear_nominal, bool),
                            np.full(len(self.specs), bool(effect is not None and getattr(effect, "linear", False)))]
        self._cache = {}

    # -- parameter vector ------------------------------------------------------------------
    def unpack(self, z):
        n = len(self.problem.nominal_center)
        nominal = self.problem.nominal_center + self.problem.nominal_sigma * z[:n]
        return nominal, self.scale * z[n:]

    def _bounds(self):
        p = self.problem
        low = np.full(len(p.nominal_center), -np.inf)
        for k, name in enumerate(_expanded(p.nominal_names)):
            if name in ("torsional_stiffness", "torsional_damping"):
                low[k] = -p.nominal_center[k] / p.nominal_sigma[k]
        low = np.r_[low, [s.lower for s in self.specs] / self.scale]
        high = np.r_[np.full(len(p.nominal_center), np.inf), [s.upper for s in self.specs] / self.scale]
        return low, high

    # -- model ---------------------------------------------------------------------------
    def predict(self, z, times) -> dict:
        nominal, values = self.unpack(z)
        plant = with_nominal(self.problem.plant, self.problem.nominal_names, nominal)
        return predict(plant, times, self.effect, values, [s.name for s in self.specs], self.step)

    def residuals(self, z, use) -> np.ndarray:
        p = self.problem
        model = aligned_quaternion(self.predict(z, p.time[use]), {c: v[use] for c, v in p.values.items()})
        parts = [((model[c] - v[use]) / p.noise[c]) for c, v in p.values.items()]
        r = np.concatenate(parts)
        return np.r_[np.where(np.isfinite(r), r, 0.0), z[:len(p.nominal_center)]]

    def _fun(self, z, use):
        f = self.residuals(z, use)
        self._cache["last"] = (z.copy(), f)
        return f

    def jacobian(self, z, use):
        """Forward differences (:meth:`difference_jacobian`); for the towing model, whose runs cost
        ~0.1 s, only every ``BROYDEN_REFRESH + 1``-th call, Broyden's rank-one update of the last one
        in between (Broyden 1965; the linear parameters' columns stay exact)."""
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
        """Forward differences, one column per parameter; the columns of linear parameters are
        computed once per sample set and reused."""
        z_last, f0 = self._cache.get("last", (None, None))
        if z_last is None or not np.array_equal(z_last, z):
            f0 = self.residuals(z, use)
        key = ("linear", use.tobytes())
        jac = np.empty((f0.size, z.size))
        _, high = self._bounds()
        for i in range(z.size):
            if self.linear[i] and key in self._cache:
                jac[:, i] = self._cache[key][i]
                continue
            h = DIFFERENCE_STEP * max(1.0, abs(z[i])) * (-1.0 if z[i] + 2 * DIFFERENCE_STEP > high[i] else 1.0)
            shifted = z.copy()
            shifted[i] += h
            jac[:, i] = (self.residuals(shifted, use) - f0) / h
        if key not in self._cache:
            self._cache[key] = {i: jac[:, i].copy() for i in np.flatnonzero(self.linear)}
        return jac

    # -- fitting -------------------------------------------------------------------------
    def _solve(self, z0, use):
        low, high = self._bounds()
        z0 = np.clip(z0, low + 1e-12 * (high - low > 0), high)
        return least_squares(self._fun, z0, jac=self.jacobian, args=(use,), bounds=(low, high), method="trf",
                             ftol=TOLERANCE, xtol=TOLERANCE, gtol=TOLERANCE, max_nfev=MAX_EVALUATIONS)

    def fit(self, nominal_start: FitResult | None = None) -> FitResult:
        """Fit from the case values, or from the nominal parameters of ``nominal_start`` (the nominal
        model's fit: a candidate then starts where the nominal model ended)."""
        start = clock.perf_counter()
        p = self.problem
        t_train = p.time[p.train]
        first = p.train & (p.time <= t_train[0] + FIRST_SPAN * (t_train[-1] - t_train[0]))
        n_nominal = len(p.nominal_center)
        z_nominal = np.zeros(n_nominal) if nominal_start is None else \
            (nominal_start.values[:n_nominal] - p.nominal_center) / p.nominal_sigma
        starts = [np.r_[z_nominal, s / self.scale] for s in
                  (self.effect.starts(self.specs) if self.effect else [np.zeros(0)])]
        stage1 = [self._solve(z0, first) for z0 in starts]
        best = min(stage1, key=lambda r: r.cost)
        # towing: the second stage starts from the better, on the whole training span, of the first
        # stage's best and (for a candidate) the nominal fit with the effect at its first start: with the
        # Broyden Jacobians a first stage that wandered off on the early span left candidates worse than
        # the nominal model (the free scenarios keep the plain continuation their slow test validated)
        low, high = self._bounds()
        options = [best.x] + ([np.clip(starts[0], low, high)] if nominal_start is not None and self.broyden else [])
        z2 = min(options, key=lambda z: float(np.sum(self.residuals(z, p.train) ** 2)))
        result = self._solve(z2, p.train)
        evaluations = sum(r.nfev for r in stage1) + result.nfev
        if self.broyden and result.status == 0:
            # towing: the budget ran out on Broyden Jacobians (a long valley, e.g. k_m against tau_m of a
            # viscoelastic tether): one more leg from a fresh finite-difference Jacobian
            self._cache.pop(("broyden", p.train.tobytes()), None)
            more = self._solve(result.x, p.train)
            evaluations += more.nfev
            result = more if more.cost <= result.cost else result
        return self._result(result, evaluations, clock.perf_counter() - start)

    def _result(self, result, evaluations, seconds) -> FitResult:
        p = self.problem
        n_nominal = len(p.nominal_center)
        chi2_prior = float(result.x[:n_nominal] @ result.x[:n_nominal])
        chi2_data = float(2.0 * result.cost - chi2_prior)
        n_data = int(sum(np.isfinite(v[p.train]).sum() for v in p.values.values()))
        jac = self.difference_jacobian(result.x, p.train) if self.broyden else result.jac    # exact at the optimum
        dof = max(n_data - len(result.x), 1)
        cov_z = np.linalg.pinv(jac.T @ jac) * max(1.0, chi2_data / dof)
        scale = np.r_[p.nominal_sigma, self.scale]
        nominal, values = self.unpack(result.x)
        names = _expanded(p.nominal_names) + [s.name for s in self.specs]
        units = _expanded_units(p.nominal_names) + [s.unit for s in self.specs]
        return FitResult(self.effect.id if self.effect else "nominal", names, units, np.r_[nominal, values],
                         scale * np.sqrt(np.clip(np.diag(cov_z), 0.0, None)), n_nominal, chi2_data, chi2_prior,
                         n_data, seconds, evaluations, result.message, values)


def resolved_step(plant, times, noise: dict, halvings: int = 3) -> float:
    """The towing model's step (s): the case's ``fit_step``, halved until the nominal model's
    discretization error, estimated by the step-doubling difference |y(h) - y(h/2)| (RMS per
    channel), is below ``STEP_ERROR_SIGMA`` of each channel's noise (at most ``halvings`` times): quiet
    sensors must not see the fit model's step as a discrepancy."""
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


def prediction(problem: Problem, effect: Effect | None, fit: FitResult, times) -> dict:
    """Channels of a fitted model at ``times`` (s)."""
    candidate = CandidateFit(problem, effect)
    z = np.r_[(fit.values[:fit.nominal_count] - problem.nominal_center) / problem.nominal_sigma,
              fit.effect_values / candidate.scale]
    return candidate.predict(z, times)


__all__ = ["CandidateFit", "FitResult", "Problem", "prediction", "QUATERNION"]
