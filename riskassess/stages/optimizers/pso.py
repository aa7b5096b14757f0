"""Particle swarm (:class:`pymoo.algorithms.soo.nonconvex.pso.PSO`), the paper's ``particleswarm``
(Boonrath, Singh & Botta 2024, Sec. 4.3): swarm size, tolerance, stall and generation limits from
``identification.optimizers``."""
from __future__ import annotations

import numpy as np
from pymoo.algorithms.soo.nonconvex.pso import PSO
from pymoo.optimize import minimize
from pymoo.termination.default import DefaultSingleObjectiveTermination

NAME = "pso"


def search(problem, x0, settings):
    """PSO over the problem's bounds (``x0`` is not used: the swarm starts spread over them).

    Parameters
    ----------
    problem : riskassess.stages.identify.TowingFit
        The bounded pymoo problem (4 variables).
    x0 : (4,) float
        Not used.
    settings : identification.optimizers table
        ``swarm_size``, ``pso_tolerance``, ``stall_generations``, ``pso_generations``, ``seed``.

    Returns
    -------
    s : (4,) float
    cost : float
    """
    result = minimize(problem, PSO(pop_size=settings.swarm_size), DefaultSingleObjectiveTermination(
        ftol=settings.pso_tolerance, period=settings.stall_generations, n_max_gen=settings.pso_generations),
        seed=settings.seed, verbose=False)
    return np.asarray(result.X, float).ravel(), float(np.atleast_1d(result.F)[0])
