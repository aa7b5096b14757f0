"""Mesh Adaptive Direct Search by NOMAD 4 (PyNomadBBO), the MADS of Boonrath, Singh & Botta 2024
(Sec. 4.3, MATLAB ``patternsearch`` with ``nups-mads``): at most ``optimizers.mads_iterations``
iterations (the paper's 250) or until the mesh is finer than ``optimizers.mads_mesh_tolerance``
(the paper's 1e-6), within ``optimizers.mads_evaluations`` evaluations.

NOMAD hands a block of up to 2n trial points at a time (the poll's directions), which the problem
evaluates together, in parallel on its worker pool, as it does a PSO generation. A run whose cost
is not finite (a diverged twin run) is reported to NOMAD as a failed evaluation, never as a value.
"""
from __future__ import annotations

import numpy as np
import PyNomad

NAME = "mads"


def _evaluate_block(problem, block) -> list[bool]:
    """Costs of a NOMAD block of trial points, written back into it; False marks a failed run."""
    n = problem.n_var
    points = [block.get_x(k) for k in range(block.size())]
    x = np.array([[p.get_coord(i) for i in range(n)] for p in points])
    costs = np.ravel(problem.evaluate(x, return_values_of=["F"]))
    ok = []
    for point, cost in zip(points, costs):
        if np.isfinite(cost):
            point.setBBO(repr(float(cost)).encode("utf-8"))
        ok.append(bool(np.isfinite(cost)))
    return ok


def search(problem, x0, settings):
    """MADS from ``x0`` within the problem's bounds; returns (best s, best cost). An error inside an
    evaluation stops the search and is raised here (NOMAD's C++ side cannot carry it).

    Parameters
    ----------
    problem : riskassess.stages.identify.TowingFit
        The bounded pymoo problem (4 variables).
    x0 : (4,) float
        Start point s_0, inside the bounds.
    settings : identification.optimizers table
        ``mads_evaluations``, ``mads_iterations``, ``mads_mesh_tolerance``, ``seed``.

    Returns
    -------
    s : (4,) float
    cost : float
    """
    params = ["BB_OUTPUT_TYPE OBJ", f"MAX_BB_EVAL {settings.mads_evaluations}",
              f"MAX_ITERATIONS {settings.mads_iterations}", f"MIN_MESH_SIZE * {settings.mads_mesh_tolerance:g}",
              f"BB_MAX_BLOCK_SIZE {2 * problem.n_var}", f"SEED {settings.seed}", "DISPLAY_DEGREE 0"]
    x0 = np.asarray(x0, float)
    if np.any(x0 < problem.xl) or np.any(x0 > problem.xu):   # NOMAD would abort the process
        raise ValueError(f"MADS: the start {x0.tolist()} lies outside the bounds {problem.xl.tolist()} - "
                         f"{problem.xu.tolist()} (identification.initial_guess, lower_bounds, upper_bounds)")
    errors = []

    def blackbox(block):
        if errors:                         # stop evaluating after the first error
            return [False] * block.size()
        try:
            return _evaluate_block(problem, block)
        except Exception as exc:           # noqa: BLE001 - carried out of NOMAD and raised below
            errors.append(exc)
            return [False] * block.size()

    PyNomad.setSeed(settings.seed)         # the generator is global to the process: reseed every search
    PyNomad.resetRandomNumberGenerator()
    result = PyNomad.optimize(blackbox, list(map(float, x0)), list(map(float, problem.xl)),
                              list(map(float, problem.xu)), params)
    if errors:
        raise errors[0]
    if not result.get("x_single_best"):
        raise RuntimeError(f"MADS found no point with a finite cost (NOMAD: {result.get('stop_reason')})")
    return np.asarray(result["x_single_best"], float), float(result["f_single_best"])
