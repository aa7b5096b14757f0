"""Diagnosis of a net capture: which impact-model parameter, if any, explains a record of the debris'
motion after the capture (docs/diagnosis.md, "Impact scenario").

Every model evaluation is the coupled impact simulation itself (:mod:`riskassess.diagnosis.impact_plant`).

1. **Chaos as model error.** The capture is sensitive to its initial state (late node strikes,
   docs/structures.md): the nominal case is run ``fit.ensemble`` more times with the launch speed
   perturbed by +-k x ``fit.perturbation`` (relative). Their standard deviation s(t) per channel and
   window, widened to the maximum over the window and its two neighbours, is the run-to-run spread a
   simulation cannot predict; a model and the record are two such draws, so each window's sigma is
   sqrt(noise^2 + 2 s^2 + floor^2) (``floor``: :data:`NUMERICAL_FLOOR` of the channel's RMS, the
   simulation's own step error). Windows where the capture is chaotic thus weigh little, the
   deterministic momentum exchange much.
2. **One-parameter fits.** Each catalog effect's parameter is fitted alone (the rest at the case's
   values): ``fit.grid`` simulations across its range, two at half the spacing around the best, then
   one at the vertex of a parabola through the points near the best; the effects still in contention
   (best chi^2 within the decisive threshold of the best effect's) then get two more points at 1/4,
   1/8 and 1/16 of the spacing around their best (:data:`NARROWING`). chi^2 is not smooth in the
   parameter (each run is one chaotic draw): the effect's value and chi^2 are its best run's, its
   1-sigma the half-width over which the parabola through the best point and its neighbours rises by
   the larger of 1 and the scatter of chi^2 between draws. The nominal model's chi^2 is its
   unperturbed run's; since an effect's best of ~8 draws beats the nominal draw by chance alone, the
   decisive BIC difference is widened by 3 scatters (:func:`decisive_threshold`).
3. **Selection** by the shared rules (:func:`riskassess.diagnosis.selection.decide`: BIC decisive
   against the nominal and the runner-up, adequacy, no structure left, material gain) on the
   normalized window values (each divided by its sigma, so that the RMS and whiteness tests read in
   sigmas); a channel whose sigma is mostly chaos is not tested for whiteness (:func:`chaos_share`). The runs of every effect's points go to the worker processes together (three rounds, then
   up to three narrowing rounds).
"""
from __future__ import annotations

import multiprocessing
import resource
import time as clock
from dataclasses import dataclass

import numpy as np

from riskassess.diagnosis.fit import FitResult, Problem
from riskassess.diagnosis.impact_effects import IMPACT_CATALOG
from riskassess.diagnosis.impact_plant import (FIT_CHANNELS, ImpactRun, run_spec, simulate, window_edges,
                                               window_statistics)
from riskassess.diagnosis.selection import decide, gain_percent, score
from riskassess.diagnosis.threads import single_threaded_blas

#: Worker processes (the issue's 2-core machine).
WORKERS = 2
#: Smallest sigma of a window value, relative to the channel's RMS over the record (-): the
#: simulation's own discretization error at the case's step (docs/model.md: energy closed to 1 %);
#: without it a noise-free record's deterministic windows would weigh without limit.
NUMERICAL_FLOOR = 1e-3
#: Scatters of chi^2 between chaotic draws added to the decisive BIC difference (decisive_threshold).
CHAOS_SIGMAS = 3.0
#: Further rounds for the contending effects: two points at these fractions of the grid spacing around
#: the best point so far (after the refinement at 1/2 and the parabola's vertex).
NARROWING = (0.25, 0.125, 0.0625)
#: Points of an effect's fit added around the best grid point, at this fraction of the grid spacing.
REFINE_FRACTION = 0.5


@dataclass
class ImpactProblem:
    """The record as the fit sees it: window edges (s), the measured window values and their
    noise-only sigmas (channel units), the training mask and the simulation spec."""

    case: object
    run: ImpactRun
    edges: np.ndarray
    measured: dict
    noise: dict
    train: np.ndarray
    sources: dict

    @property
    def centers(self) -> np.ndarray:
        return 0.5 * (self.edges[:-1] + self.edges[1:])

    @property
    def channels(self) -> list[str]:
        return [c for c in FIT_CHANNELS if np.isfinite(self.measured[c]).any()]


def build_problem(case, measured) -> ImpactProblem:
    """The impact problem of a diagnosis case and a measured record.

    Parameters
    ----------
    case : ImpactDiagnosisCase
        The validated case (its ``fit`` and ``diagnosis`` tables, its impact case).
    measured : MeasuredData
        The record (:func:`riskassess.diagnosis.measured.read_measured`), times from the impact's t = 0.

    Returns
    -------
    ImpactProblem
    """
    edges = window_edges(measured.time, case.fit.window)
    means, sigmas = window_statistics(measured.time, measured.values, edges, measured.noise)
    if not any(np.isfinite(means[c]).any() for c in FIT_CHANNELS):
        raise ValueError(f"{measured.path}: the impact scenario needs the main body's velocity (vel_x..z) or "
                         f"position (rel_x..z), and its body rates (omega_x..z) or attitude (q_w..q_z); "
                         f"the record has {', '.join(measured.channels)}")
    centers = 0.5 * (edges[:-1] + edges[1:])
    split = centers[0] + (1.0 - case.diagnosis.holdout_fraction) * (centers[-1] - centers[0])
    end_time = edges[-1] + 1.0 / 50.0
    sources = {c: "window means of the record's column" if c in measured.values else
               "window slopes of the record's poses (rel_x..z, q_w..q_z)" for c in FIT_CHANNELS}
    return ImpactProblem(case, run_spec(case.impact_path, end_time, edges), edges, means, sigmas, centers <= split,
                         sources)


def base_overrides(case) -> dict:
    """The impact-case changes of the diagnosis case's own ``[[effects]]`` (an extended case).

    Parameters
    ----------
    case : ImpactDiagnosisCase
        The validated case.

    Returns
    -------
    dict of str to object
        Dotted impact-case key -> value.
    """
    out = {}
    for entry in case.effects:
        effect = IMPACT_CATALOG[entry.id]
        out.update(effect.overrides(case.impact_case, entry.parameters[effect.parameter(case.impact_case).name]))
    return out


# -- simulations in worker processes --------------------------------------------------------------------
_RUN: ImpactRun | None = None       # inherited by the forked workers


def _simulate(overrides):
    return simulate(_RUN, overrides)


def simulate_all(run: ImpactRun, overrides: list[dict], workers: int = WORKERS, progress=None, done=0,
                 total=None) -> list:
    """Window means of every override set (:func:`riskassess.diagnosis.impact_plant.simulate`), in
    ``workers`` forked processes; order kept.

    Parameters
    ----------
    run : ImpactRun
        The case and windows.
    overrides : list of dict
        One impact-case override set per run.
    workers : int
        Processes (1: in this process).
    progress : callable or None
        ``progress("simulating", done, total)`` after each run.
    done, total : int
        Runs done before and in all (for progress).

    Returns
    -------
    list of dict or None
    """
    global _RUN
    _RUN = run
    total = total or len(overrides)
    out = []
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        for o in overrides:
            out.append(simulate(run, o))
            if progress:
                progress("simulating", done + len(out), total)
        return out
    with multiprocessing.get_context("fork").Pool(workers, initializer=single_threaded_blas) as pool:
        for result in pool.imap(_simulate, overrides):
            out.append(result)
            if progress:
                progress("simulating", done + len(out), total)
    return out


# -- sigma and chi^2 ------------------------------------------------------------------------------------
def ensemble_spread(runs: list[dict], channels) -> dict:
    """Per channel and window: the standard deviation over the runs, widened to the maximum over the
    window and its two neighbours (five draws say little about one window alone).

    Parameters
    ----------
    runs : list of dict
        Window values of the nominal model's perturbed runs (failed runs left out).
    channels : sequence of str

    Returns
    -------
    spread : dict of str to (w,) float
    """
    out = {}
    for c in channels:
        s = np.nanstd(np.array([r[c] for r in runs]), axis=0, ddof=1)
        padded = np.pad(s, 1, mode="edge")
        out[c] = np.nanmax(np.vstack([padded[:-2], padded[1:-1], padded[2:]]), axis=0)
    return out


def window_sigmas(problem: ImpactProblem, spread: dict) -> dict:
    """Per channel and window: sqrt(noise^2 + 2 spread^2 + floor^2) (module doc, step 1).

    Parameters
    ----------
    problem : ImpactProblem
    spread : dict of str to (w,) float
        :func:`ensemble_spread` (channel units).

    Returns
    -------
    sigma : dict of str to (w,) float
    """
    out = {}
    for c in problem.channels:
        measured = problem.measured[c]
        floor = NUMERICAL_FLOOR * np.sqrt(np.nanmean(measured ** 2))
        noise = np.nan_to_num(problem.noise[c])
        out[c] = np.sqrt(noise ** 2 + 2.0 * spread[c] ** 2 + floor ** 2)
    return out


def normalized(values: dict | None, sigma: dict) -> dict | None:
    """Window values divided by their sigmas (None stays None)."""
    return None if values is None else {c: np.asarray(values[c], float) / s for c, s in sigma.items()}


def chi2(model: dict | None, measured: dict, mask) -> float:
    """Sum of squared normalized residuals over the ``mask`` windows (inf for a failed run).

    Parameters
    ----------
    model, measured : dict of str to (w,) float
        Normalized window values.
    mask : (w,) bool

    Returns
    -------
    chi2 : float
    """
    if model is None:
        return np.inf
    total = 0.0
    for c, m in measured.items():
        r = (np.asarray(model[c]) - m)[mask]
        ok = np.isfinite(m[mask])
        if not np.all(np.isfinite(r[ok])):
            return np.inf
        total += float(np.sum(r[ok] ** 2))
    return total


# -- one effect -----------------------------------------------------------------------------------------
class EffectScan:
    """The one-parameter fit of an impact effect (module doc, step 2) on the fit variable u:
    ln(value) for a ``log`` parameter, the value itself otherwise."""

    def __init__(self, effect, impact_case, grid: int):
        self.effect = effect
        self.impact_case = impact_case
        self.spec = effect.parameter(impact_case)
        self.low, self.high = self._u(self.spec.lower), self._u(self.spec.upper)
        self.u = list(np.linspace(self.low, self.high, grid))
        self.spacing = (self.high - self.low) / (grid - 1)
        self.chi2: list[float] = []
        self.runs: list = []

    def _u(self, value):
        return float(np.log(value)) if self.spec.log else float(value)

    def value(self, u) -> float:
        """The physical value (the parameter's unit) of the fit variable ``u``."""
        return float(np.exp(u)) if self.spec.log else float(u)

    def overrides(self, u, base: dict) -> dict:
        """Impact-case overrides at ``u`` on top of ``base``."""
        return {**base, **self.effect.overrides(self.impact_case, self.value(u))}

    def add(self, runs, chi2s) -> None:
        """Record the window values and chi^2 of the points just evaluated (the last ones of ``u``)."""
        self.runs += list(runs)
        self.chi2 += list(chi2s)

    def refine_points(self) -> list[float]:
        """Two points at half the spacing on each side of the best point so far (inside the range)."""
        best = self.u[int(np.argmin(self.chi2))]
        h = REFINE_FRACTION * self.spacing
        return [u for u in (best - h, best + h) if self.low <= u <= self.high]

    def bracket(self):
        """The best finite point and its nearest finite neighbour on each side (the three nearest at a
        bound), with any other point inside them: (u, chi^2) arrays, or None with fewer than 3."""
        u, c = np.array(self.u), np.array(self.chi2)
        ok = np.isfinite(c)
        u, c = u[ok], c[ok]
        if len(np.unique(u)) < 3:
            return None
        order = np.argsort(u)
        u, c = u[order], c[order]
        best = int(np.argmin(c))
        lo, hi = max(0, min(best - 1, len(u) - 3)), min(len(u), max(best + 2, 3))
        return u[lo:hi], c[lo:hi]

    def parabola(self):
        """Least-squares parabola chi^2(u) = a (u - u0)^2 + c0 through :meth:`bracket`; (a, u0, c0), or
        None when there is no bracket or a <= 0 (no minimum inside the range)."""
        points = self.bracket()
        if points is None:
            return None
        p2, p1, p0 = np.polyfit(points[0], points[1], 2)
        if p2 <= 0:
            return None
        return p2, -p1 / (2.0 * p2), p0 - p1 ** 2 / (4.0 * p2)

    def narrowing_points(self, fraction: float) -> list[float]:
        """Two points at ``fraction`` of the grid spacing on each side of the best point so far (inside the
        range), leaving out any within a quarter of that of an evaluated point."""
        best = self.u[int(np.argmin(self.chi2))]
        h = fraction * self.spacing
        return [u for u in (best - h, best + h)
                if self.low <= u <= self.high and np.min(np.abs(np.array(self.u) - u)) > 0.25 * h]

    def vertex_point(self) -> list[float]:
        """The parabola's vertex, kept inside the bracket; none when it is already evaluated."""
        fitted = self.parabola()
        if fitted is None:
            return []
        u, _ = self.bracket()
        vertex = float(np.clip(fitted[1], u.min(), u.max()))
        return [] if np.min(np.abs(np.array(self.u) - vertex)) < 1e-6 * self.spacing else [vertex]

    def result(self, n_data: int, seconds: float, chi2_scatter: float) -> tuple[FitResult, int]:
        """The fit (module doc, step 2): the best evaluated point's value and chi^2; its 1-sigma the
        half-width over which the parabola rises by max(1, ``chi2_scatter``) (the chaotic draws' own
        scatter of chi^2: a narrower interval would be read from chaos); the index of that point's run.

        Parameters
        ----------
        n_data : int
            Data values in the fit (windows x channels).
        seconds : float
            Wall time of the fit (s).
        chi2_scatter : float
            Standard deviation of chi^2 between two draws of one model (-).

        Returns
        -------
        fit : FitResult
        index : int
        """
        chi2s = np.array(self.chi2)
        best = int(np.argmin(chi2s))
        fitted = self.parabola()
        if fitted is not None:
            sigma_u = float(np.sqrt(max(1.0, chi2_scatter) / fitted[0]))
            message = f"best of {len(self.u)} runs; 1-sigma from the parabola through it and its neighbours"
        else:
            sigma_u = np.inf
            message = f"best of {len(self.u)} runs; no minimum inside the range (at a bound, or not seen)"
        value = self.value(self.u[best])
        std = value * sigma_u if self.spec.log else sigma_u
        fit = FitResult(self.effect.id, [self.spec.name], [self.spec.unit], np.array([value]), np.array([std]), 0,
                        float(chi2s[best]), 0.0, n_data, seconds, len(self.u), message, np.array([value]))
        return fit, best


# -- the diagnosis ----------------------------------------------------------------------------------------
def perturbed_overrides(case, base: dict) -> list[dict]:
    """The ensemble's override sets: launch speed x (1 + k perturbation), k = +1, -1, +2, -2, ...

    Parameters
    ----------
    case : ImpactDiagnosisCase
    base : dict
        The case's own overrides (:func:`base_overrides`).

    Returns
    -------
    list of dict
    """
    speed = float(base.get("launch.velocity", case.impact_case.launch.velocity))
    factors = [(1 if k % 2 == 0 else -1) * (k // 2 + 1) for k in range(case.fit.ensemble)]
    return [{**base, "launch.velocity": speed * (1.0 + f * case.fit.perturbation)} for f in factors]


def diagnose_impact(case, measured, workers: int = WORKERS, progress=None, candidates=None) -> tuple[dict, dict]:
    """Fit every impact effect, select, and report (module doc).

    Parameters
    ----------
    case : ImpactDiagnosisCase
        The validated case.
    measured : MeasuredData
        The record.
    workers : int
        Worker processes.
    progress : callable or None
        ``progress(stage, done, total)``.
    candidates : list of str or None
        Effect ids to fit (default: the whole impact catalog).

    Returns
    -------
    answer : dict
        Cause, confidence, statement, fitted parameter (SI) with its 1-sigma, candidates, chaos spread,
        wall time (s).
    arrays : dict of str to numpy.ndarray
        Window times and values behind it (measured, nominal, chosen, sigma).
    """
    wall = clock.perf_counter(), cpu_seconds()
    problem = build_problem(case, measured)
    base = base_overrides(case)
    ids = [k for k in IMPACT_CATALOG if candidates is None or k in candidates]
    scans = {k: EffectScan(IMPACT_CATALOG[k], case.impact_case, case.fit.grid) for k in ids}
    ensemble = perturbed_overrides(case, base)
    total = 1 + len(ensemble) + sum(len(s.u) + 3 for s in scans.values())
    first = [base] + ensemble + [s.overrides(u, base) for s in scans.values() for u in s.u]
    runs = simulate_all(problem.run, first, workers, progress, 0, total)
    nominal_runs = [r for r in runs[:1 + len(ensemble)] if r is not None]
    if runs[0] is None:
        raise RuntimeError(f"{case.impact_path}: the nominal impact simulation failed its health checks")
    spread = ensemble_spread(nominal_runs, problem.channels)
    sigma = window_sigmas(problem, spread)
    measured_n = normalized({c: problem.measured[c] for c in problem.channels}, sigma)
    chi2s = [chi2(normalized(r, sigma), measured_n, problem.train) for r in runs]
    k = 1 + len(ensemble)
    for s in scans.values():
        s.add(runs[k:k + len(s.u)], chi2s[k:k + len(s.u)])
        k += len(s.u)
    done = len(first)
    for stage in ("refine_points", "vertex_point"):
        points = {key: getattr(s, stage)() for key, s in scans.items()}
        done = _scan_points(points, scans, base, problem, sigma, measured_n, workers, progress, done, total)
    nominal_chi2 = [c for c in chi2s[:1 + len(ensemble)] if np.isfinite(c)]
    scatter = chi2_scatter(nominal_chi2)
    threshold = decisive_threshold(case.diagnosis.decisive_delta_bic, scatter)
    for fraction in NARROWING:
        # the contenders only (best chi^2 within the decisive threshold of the best effect's): a coarse
        # grid point next to the truth can mispredict the held-out windows of a well-determined parameter
        lowest = min(min(s.chi2) for s in scans.values())
        points = {key: s.narrowing_points(fraction) for key, s in scans.items() if min(s.chi2) <= lowest + threshold}
        n_points = sum(len(us) for us in points.values())
        if not n_points:
            break
        done = _scan_points(points, scans, base, problem, sigma, measured_n, workers, progress, done,
                            done + n_points)
    n_data = int(sum(np.isfinite(measured_n[c][problem.train]).sum() for c in problem.channels))
    seconds = clock.perf_counter() - wall[0]
    fits = {"nominal": FitResult("nominal", [], [], np.zeros(0), np.zeros(0), 0, float(chi2s[0]), 0.0, n_data,
                                 seconds, 1, "the unperturbed nominal run")}
    predictions = {"nominal": normalized(runs[0], sigma)}
    diverged = {}
    for key, s in scans.items():
        if not np.isfinite(s.chi2).any():
            diverged[key] = "every simulation of its range failed the health checks"
            continue
        fits[key], index = s.result(n_data, seconds, scatter)
        predictions[key] = normalized(s.runs[index], sigma)
    return _answer(case, problem, fits, predictions, diverged, scans, sigma, spread, nominal_chi2, measured_n, wall)


def _scan_points(points, scans, base, problem, sigma, measured_n, workers, progress, done, total) -> int:
    """Simulate each effect's new parameter values ``points`` (effect id -> list of u) and add the runs
    and their chi^2 to its :class:`EffectScan`; returns the number of simulations done so far.

    Parameters
    ----------
    points : dict of str to list of float
        New values of each effect's parameter (its fit variable u).
    scans : dict of str to EffectScan
        The effects' scans, extended in place.
    base : dict
        The nominal run's overrides.
    problem : ImpactProblem
    sigma, measured_n : dict
        Window sigmas and the normalized measured windows (:func:`normalized`).
    workers : int
        Worker processes.
    progress : callable or None
        ``progress(stage, done, total)``.
    done, total : int
        Simulations done before this batch, and the total announced to ``progress``.
    """
    batch = [scans[key].overrides(u, base) for key, us in points.items() for u in us]
    results = simulate_all(problem.run, batch, workers, progress, done, total)
    k = 0
    for key, us in points.items():
        scans[key].u += us
        scans[key].add(results[k:k + len(us)], [chi2(normalized(r, sigma), measured_n, problem.train)
                                                for r in results[k:k + len(us)]])
        k += len(us)
    return done + len(batch)


def chaos_share(problem: ImpactProblem, sigma: dict, spread: dict) -> dict:
    """Per channel: the RMS over the training windows of the chaotic part of the normalized residual's
    sigma, sqrt(2) s / sigma (-, at most 1). The selection takes it as the model's own structured error
    (its ``step_error_sigma``, :mod:`riskassess.diagnosis.selection`): a channel where it is above 0.5
    sigma is not tested for structure (two chaotic draws differ smoothly from window to window, not as
    white noise), and its adequacy bound widens to sqrt(adequate_rms^2 + share^2).

    Parameters
    ----------
    problem : ImpactProblem
    sigma, spread : dict of str to (w,) float
        Window sigmas and ensemble spreads (channel units).

    Returns
    -------
    share : dict of str to float
    """
    return {c: float(np.sqrt(np.mean((np.sqrt(2.0) * spread[c] / sigma[c])[problem.train] ** 2)))
            for c in problem.channels}


def cpu_seconds() -> float:
    """CPU time (s) of this process and its finished children (the worker processes): the wall time
    the diagnosis would take on idle cores is about this over the workers, whatever the machine's load.

    Returns
    -------
    seconds : float
    """
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def chi2_scatter(ensemble_chi2) -> float:
    """Standard deviation of chi^2 between two chaotic draws of the same model (-): sqrt(2) times the
    ensemble's (each draw's chi^2 scatters by the ensemble's standard deviation).

    Parameters
    ----------
    ensemble_chi2 : sequence of float
        chi^2 of the nominal model's draws (the unperturbed run and the ensemble).

    Returns
    -------
    scatter : float
    """
    return float(np.sqrt(2.0) * np.std(ensemble_chi2, ddof=1)) if len(ensemble_chi2) > 1 else 0.0


def decisive_threshold(decisive: float, scatter: float) -> float:
    """The BIC difference counted as decisive with chaotic draws: the case's ``decisive_delta_bic`` plus
    :data:`CHAOS_SIGMAS` times the chi^2 scatter between draws (the best of an effect's ~8 draws is
    ~1.4 scatters below a typical one by chance alone; 3 keeps a no-change record's answer "none").

    Parameters
    ----------
    decisive : float
        The case's threshold (-).
    scatter : float
        :func:`chi2_scatter` (-).

    Returns
    -------
    threshold : float
    """
    return decisive + CHAOS_SIGMAS * scatter


def _answer(case, problem, fits, predictions, diverged, scans, sigma, spread, nominal_chi2, measured_n, wall):
    """The decision and the answer dict (keys shared with the other scenarios where they mean the same)."""
    scoring = Problem(case, None, problem.centers, measured_n, {c: 1.0 for c in problem.channels}, problem.train,
                      [], np.zeros(0), np.zeros(0))
    share = chaos_share(problem, sigma, spread)
    scores = score(scoring, predictions, {k: share for k in predictions})
    threshold = decisive_threshold(case.diagnosis.decisive_delta_bic, chi2_scatter(nominal_chi2))
    # the confidence on the decision's scale: BIC differences counted in units of the chaos-widened threshold
    decision = decide(fits, scores, threshold, case.diagnosis.adequate_rms, scoring,
                      temper=min(1.0, case.diagnosis.decisive_delta_bic / threshold))
    chosen = decision["model"]
    nominal = fits["nominal"]
    rows = [{"id": k, "delta_bic": float(nominal.bic - fits[k].bic), "weight": decision["weights"][k],
             "parameters": _parameters(fits[k]), "train_rms_sigma": scores[k]["train_rms_sigma"],
             "holdout_rms_sigma": scores[k]["holdout_rms_sigma"], "adequate": bool(decision["adequate"][k]),
             "evaluations": fits[k].evaluations, "fit": fits[k].message,
             "points": [{"value": scans[k].value(u), "chi2": float(c)} for u, c in
                        sorted(zip(scans[k].u, scans[k].chi2))]} for k in decision["ranked"]]
    answer = {
        "case": case.name, "scenario": "impact", "impact_case": str(case.impact_path), "cause": decision["cause"],
        "effects": [decision["cause"]] if decision["cause"] not in ("none", "unexplained") else [],
        "confidence": decision["confidence"], "statement": decision["reason"], "model": chosen,
        "parameters": _parameters(fits[chosen]) if chosen != "nominal" else {},
        "candidates": rows, "diverged": diverged,
        "nominal": {"bic": nominal.bic, "chi2_ensemble": [float(c) for c in nominal_chi2],
                    "train_rms_sigma": scores["nominal"]["train_rms_sigma"],
                    "holdout_rms_sigma": scores["nominal"]["holdout_rms_sigma"]},
        "gain_percent": {"overall": gain_percent(scores["nominal"]["holdout_rms_sigma"],
                                                 scores[chosen]["holdout_rms_sigma"])},
        "channels": {"fitted": problem.channels, "formed_from": {c: problem.sources[c] for c in problem.channels},
                     "not_fitted": "rel_x..z and q_w..q_z are integrals of the fitted channels and carry the chaotic "
                                   "phase of the capture; they are used only to form velocities and rates when "
                                   "those are not in the record"},
        "windows": {"length_s": float(problem.edges[1] - problem.edges[0]), "count": int(len(problem.centers)),
                    "split_time_s": float(problem.centers[problem.train][-1])},
        "chaos": {"ensemble_runs": case.fit.ensemble, "perturbation": case.fit.perturbation,
                  "spread_median": {c: float(np.median(spread[c])) for c in problem.channels},
                  "sigma_median": {c: float(np.median(sigma[c])) for c in problem.channels},
                  "share_of_sigma": share},
        "decisive_delta_bic": case.diagnosis.decisive_delta_bic, "decisive_with_chaos": threshold,
        "chi2_scatter": chi2_scatter(nominal_chi2), "adequate_rms": case.diagnosis.adequate_rms,
        "simulations": int(sum(len(s.u) for s in scans.values()) + 1 + case.fit.ensemble),
        "wall_s": clock.perf_counter() - wall[0], "cpu_s": cpu_seconds() - wall[1],
    }
    arrays = {"time": problem.centers, "train": problem.train, "channels": np.array(problem.channels)}
    for c in problem.channels:
        arrays[f"measured/{c}"] = problem.measured[c]
        arrays[f"sigma/{c}"] = sigma[c]
        arrays[f"spread/{c}"] = spread[c]
        arrays[f"nominal/{c}"] = predictions["nominal"][c] * sigma[c]
        arrays[f"chosen/{c}"] = predictions[chosen][c] * sigma[c]
    return answer, arrays


def _parameters(fit: FitResult) -> dict:
    return {n: {"value": float(v), "std": float(s), "unit": u}
            for n, v, s, u in zip(fit.names, fit.values, fit.std, fit.units)}
