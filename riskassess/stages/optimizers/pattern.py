"""Pattern search: pymoo's Hooke-Jeeves with seeded exploration and restarts that give every
variable its own step (in place of MATLAB's MADS ``patternsearch``, Boonrath et al. 2024, Sec. 4.3)."""
from __future__ import annotations

import numpy as np
from pymoo.algorithms.soo.nonconvex.pattern import PatternSearch, calc_sign, exploration_move, pattern_move
from pymoo.core.population import Population
from pymoo.core.replacement import is_better
from pymoo.core.termination import Termination
from pymoo.optimize import minimize
from pymoo.termination.collection import TerminationCollection
from pymoo.termination.max_eval import MaximumFunctionCallTermination

NAME = "pattern"
#: First exploration step of a search from the case's s0, as a fraction of each bound range.
FIRST_DELTA = 0.25


def search(problem, x0, settings):
    """:func:`restarted_pattern_search` from ``x0`` with first step :data:`FIRST_DELTA` and
    ``settings.pattern_evaluations`` evaluations.

    Parameters
    ----------
    problem : riskassess.stages.identify.TowingFit
        The bounded pymoo problem (4 variables).
    x0 : (4,) float
        Start point s_0.
    settings : identification.optimizers table
        The case's optimizer settings.

    Returns
    -------
    s : (4,) float
    cost : float
    """
    return restarted_pattern_search(problem, x0, settings, FIRST_DELTA, settings.pattern_evaluations)


class SeededPatternSearch(PatternSearch):
    """pymoo's Hooke-Jeeves (:class:`pymoo.algorithms.soo.nonconvex.pattern.PatternSearch`), unchanged
    except that the random order of each exploration move is drawn from the algorithm's seeded generator:
    pymoo 0.6.2 calls ``exploration_move`` without it, so every exploration drew a fresh unseeded order and
    two runs from the same start could end at different points."""

    def _next(self):
        if not is_better(self._explr, self._center):
            self.n_not_improved += 1
            self._rho = self.init_rho**self.n_not_improved
            self._explr = yield from exploration_move(self.problem, self._center, self._sign, self._delta, self._rho,
                                                      random_state=self.random_state)
        else:
            self._direction = self._explr.X - self._center.X
            self._center = self._explr
            self._trial = yield pattern_move(self.problem, self._center, self._direction, self.step_size)
            self._sign = calc_sign(self._direction)
            self._explr = yield from exploration_move(self.problem, self._trial, self._sign, self._delta, self._rho,
                                                      random_state=self.random_state)
        self.pop = Population.create(self._center, self._explr)


class StepTolerance(Termination):
    """Ends a Hooke-Jeeves leg once its exploration step (:math:`\\rho\\,\\delta`) is below ``tolerance``
    times every variable's bound range: smaller moves do not change s at the precision asked for."""

    def __init__(self, tolerance):
        super().__init__()
        self.tolerance = tolerance

    def _update(self, algorithm):
        if getattr(algorithm, "_delta", None) is None:
            return 0.0
        lower, upper = algorithm.problem.bounds()
        return float(np.all(algorithm._rho * algorithm._delta < self.tolerance * (upper - lower)))


def restarted_pattern_search(problem, x0, settings, first_delta, budget):
    """Hooke-Jeeves (:class:`SeededPatternSearch`) from ``x0`` in legs of at most
    ``settings.restart_evaluations`` evaluations, each restarted from the best point so far.

    Hooke-Jeeves shrinks one step factor for all variables, so in this problem (the cost ~260x flatter
    along s4 than along s1, docs/towing.md) the step along s4 is down to 1e-3 of its range while s1-s3 are
    still being tuned, and s4 then crawls. Each restart therefore gives every variable its own first step
    (a fraction of its bound range): a variable that travelled at least a tenth of its first step in the
    last leg keeps that step (or the distance travelled, if larger, up to ``first_delta``); a settled one
    gets the distance it travelled, at least a tenth of its step (at most tenfold smaller per leg).
    A leg without improvement shrinks all steps tenfold. A leg ends when its step is below
    ``settings.pattern_tolerance`` of every bound range (:class:`StepTolerance`) or after
    ``settings.restart_evaluations``; the search stops after ``budget`` evaluations or when every first step
    is below the tolerance. Returns (best s, best cost).

    Parameters
    ----------
    problem : riskassess.stages.identify.TowingFit
        The bounded pymoo problem (4 variables); its ``evaluations`` count the budget.
    x0 : (4,) float
        Start point.
    settings : identification.optimizers table
        ``restart_evaluations``, ``pattern_tolerance``, ``seed``.
    first_delta : float
        First exploration step, as a fraction of each bound range (-).
    budget : int
        Total evaluations of the problem after which no leg starts.
    """
    span = problem.xu - problem.xl
    x, f, delta = np.asarray(x0, float), np.inf, np.full(problem.n_var, float(first_delta))
    leg = 0
    while len(problem.evaluations) < budget and delta.max() >= settings.pattern_tolerance:
        n = min(settings.restart_evaluations, budget - len(problem.evaluations))
        result = minimize(problem, SeededPatternSearch(x0=x, init_delta=delta), TerminationCollection(
            StepTolerance(settings.pattern_tolerance), MaximumFunctionCallTermination(n)), seed=settings.seed + leg,
            verbose=False)
        leg += 1
        cost, found = float(np.atleast_1d(result.F)[0]), np.asarray(result.X, float).ravel()
        if cost < f:
            moved = np.abs(found - x) / span
            travelling = moved >= 0.1 * delta
            delta = np.where(travelling, np.minimum(np.maximum(moved, delta), first_delta), np.maximum(moved, 0.1 * delta))
            x, f = found, cost
        else:
            delta = 0.1 * delta
    return x, f
