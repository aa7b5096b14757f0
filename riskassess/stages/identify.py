"""`riskassess identify`: sub-tether parameters of the lower-order towing model (Boonrath, Singh &
Botta 2024, Sec. 3).

Decision vector :math:`s = [\\log_{10} k_{ST}, l_{ST,0}, \\log_{10} c_{ST}, m_P/m_{net}]` (eq. 22) within
the bounds of eq. (24). For each candidate, one lower-order run per spin rate of the data set
(the compiled twin of the Exudyn model, :func:`multibody.towing.run_twin`) is compared with the
data by

* :func:`cost_f1`: :math:`\\sum_j w_1 RMSE_{r,j} + w_2 (RMSE_{\\omega_D,j} + RMSE_{\\omega_C,j})`, eqs. (17)-(19);
* :func:`cost_f1_inertial`: the same with both angular velocities compared in inertial components (eq. 17e
  does not say in which frame's components its difference is taken; docs/towing.md);
* :func:`cost_f2`: :math:`\\sum_j RMSE_{T,j}` of the main-tether tension, eqs. (20)-(21).

Two maintained optimizers of pymoo minimize it: particle swarm (:class:`pymoo.algorithms.soo.nonconvex.pso.PSO`,
the paper's ``particleswarm``) and pattern search (:class:`pymoo.algorithms.soo.nonconvex.pattern.PatternSearch`,
Hooke-Jeeves, in place of MATLAB's MADS ``patternsearch``). A population's runs are spread over
worker processes (:class:`multiprocessing.Pool`; each worker holds the case and the data).

The benchmark of Sec. 4.3 (:func:`benchmark`) takes as data the model's own runs with
``identification.benchmark_truth`` at the training rates, so the minimum is known: cost 0 at s_true.
"""
from __future__ import annotations

import multiprocessing
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymoo.core.problem import Problem
from scipy.spatial.transform import Rotation

from multibody.towing import run_twin
from multibody.towing_kernel import MT_TENSION
from riskassess.products import results
from riskassess.products.outfolder import OutputFolder, claim
from riskassess.models.towing import towing_model
from riskassess.models.towing_fullnet import lower_order_from_net
from riskassess.cases.towing import TowingCase
from riskassess.cases.impact import load_model
from riskassess.products.towing_plots import plot_convergence
from riskassess.stages.optimizers import OPTIMIZERS

#: The quantities the costs compare, from :meth:`multibody.towing.TowResult.series`.
COMPARED = ("relative_position", "chaser_omega_body", "debris_omega_body", "main_tether_tension")

#: Per body, its body-frame angular velocity and its attitude (rotation matrices body -> Earth-centred inertial,
#: (k, 3, 3)) in a compared series: ``omega_inertial = attitude @ omega_body`` (:func:`angular_velocity`).
ATTITUDE_OF = {"chaser_omega_body": "chaser_to_inertial", "debris_omega_body": "debris_to_inertial"}

#: The frames eq. (19b, 19c) can compare the angular velocities in (:func:`angular_velocity`).
FRAMES = ("body", "inertial")


class MissingAttitude(ValueError):
    """A compared series lacks the attitude an inertial-frame comparison needs (a full-net run cached before
    the attitudes were stored with every run); a ValueError, so the CLI reports it as bad input (exit 2).
    :func:`identify` checks the data before any run, so a worker never turns it into an infinite cost."""


def compared_series(result) -> dict:
    """r_D/C (m, inertial), both angular velocities (rad/s, body frames) and the MT tension (N) of a run:
    the entries of :meth:`multibody.towing.TowResult.series`, bit for bit, taken straight from the samples
    (``series`` also forms two rotation matrices per sample, a fifth of an identification run's time).

    Parameters
    ----------
    result : multibody.towing.TowResult
        A lower-order run (its generalized coordinates ``q``, velocities ``v`` and diagnostics).

    Returns
    -------
    dict
        ``relative_position`` (k, 3) m, inertial; ``chaser_omega_body`` and ``debris_omega_body``
        (k, 3) rad/s, each body's frame; ``main_tether_tension`` (k,) N; ``chaser_to_inertial`` and
        ``debris_to_inertial`` (k, 3, 3), the attitudes (body -> inertial) from the rotation vectors
        (``series``' matrices to round-off: one vectorized Rodrigues here instead of a compiled call per sample).
    """
    m, q, v = result.model, result.q, result.v
    return {"relative_position": (m.positions[2] + q[:, 9:12]) - (m.positions[1] + q[:, 3:6]),
            "chaser_omega_body": v[:, 6:9], "debris_omega_body": v[:, 12:15],
            "main_tether_tension": result.diag[:, MT_TENSION],
            "chaser_to_inertial": Rotation.from_rotvec(q[:, 6:9]).as_matrix(),
            "debris_to_inertial": Rotation.from_rotvec(q[:, 12:15]).as_matrix()}


def angular_velocity(series: dict, channel: str, frame: str = "body") -> np.ndarray:
    """A compared angular velocity in body or in Earth-centred inertial components.

    Both are the body's rate relative to the inertial frame (the paper's :math:`{}^{O}\\omega^D`, eq. 17e);
    ``frame`` picks the components: ``"body"`` as integrated, ``"inertial"`` turned by the body's own attitude.
    (The RMSE of eq. 19 compares norms of differences, so any frame both models share at each sample, LVLH
    included, gives the inertial figure: a common rotation leaves the norm unchanged.)

    Parameters
    ----------
    series : dict
        A compared series (:func:`compared_series`, or a cached full-net run).
    channel : str
        ``"chaser_omega_body"`` or ``"debris_omega_body"``.
    frame : str
        ``"body"`` or ``"inertial"``.

    Returns
    -------
    (k, 3) float
        Angular velocity (rad/s) in the frame asked for.

    Raises
    ------
    MissingAttitude
        ``frame="inertial"`` on a series without the body's attitude, naming what is missing.
    """
    if frame not in FRAMES:
        raise ValueError(f"unknown frame {frame!r}; the known frames are: {', '.join(FRAMES)}")
    omega_body = np.asarray(series[channel], float)
    if frame == "body":
        return omega_body
    key = ATTITUDE_OF[channel]
    if key not in series:
        rate = series.get("rate_deg_s")
        raise MissingAttitude(f"{channel} in inertial components needs '{key}' (rotation body -> inertial per "
                              f"sample), which this run{'' if rate is None else f' ({float(rate):g} deg/s)'} does "
                              f"not store (full-net runs cached before 2026-11-27 keep only body-frame rates and "
                              f"the start state: run them again)")
    return np.einsum("kij,kj->ki", np.asarray(series[key], float), omega_body)


def has_attitudes(series: dict) -> bool:
    """Whether ``series`` stores both bodies' attitudes (:data:`ATTITUDE_OF`).

    Parameters
    ----------
    series : dict
        A compared series.

    Returns
    -------
    bool
    """
    return all(key in series for key in ATTITUDE_OF.values())


def rmse(model, data) -> float:
    r""":math:`\sqrt{\sum_g \|x^L_g - x^H_g\|^2 / N_t}` over the samples, eqs. (19), (21).

    Parameters
    ----------
    model : (k,) or (k, d) float
        The lower-order model's series (any unit).
    data : (k,) or (k, d) float
        The data series, same unit and frame.

    Returns
    -------
    float
        RMSE of the vector norm, in the series' unit.
    """
    diff = (np.asarray(model) - np.asarray(data)).reshape(len(data), -1)
    return float(np.sqrt(np.mean(np.sum(diff**2, axis=1))))


def rmse_free_roll(model_omega_body, data_omega_body, axis_body) -> float:
    r"""RMSE of a body-frame angular velocity, blind to a turn of the body about ``axis_body``: the axial
    component and the norm of the transverse part are compared, not the transverse direction.

    For a debris symmetric about ``axis_body`` (two equal principal moments) a slow roll about that axis turns
    its body-frame angular velocity within the transverse plane without changing its spin about inertial space;
    eq. (19b) read in the body frame counts it in full. This is the smallest eq. (19b) over every such turn at
    each sample: a diagnostic beside f1, not a cost.

    Parameters
    ----------
    model_omega_body, data_omega_body : (k, 3) float
        Angular velocities in each one's own body frame (rad/s).
    axis_body : (3,) float
        The symmetry axis, body frame (any length).

    Returns
    -------
    float
        RMSE (rad/s).
    """
    return rmse(axial_and_transverse(model_omega_body, axis_body), axial_and_transverse(data_omega_body, axis_body))


def axial_and_transverse(omega_body, axis_body) -> np.ndarray:
    """A body-frame angular velocity's component along ``axis_body`` and the norm of the rest: what a turn of
    the body about that axis leaves unchanged (:func:`rmse_free_roll`).

    Parameters
    ----------
    omega_body : (k, 3) float
        Angular velocity (rad/s), body frame.
    axis_body : (3,) float
        The axis, body frame (any length).

    Returns
    -------
    (k, 2) float
        Axial component and transverse norm (rad/s).
    """
    axis = np.asarray(axis_body, float) / np.linalg.norm(axis_body)
    omega_body = np.asarray(omega_body, float)
    axial = omega_body @ axis
    return np.column_stack([axial, np.linalg.norm(omega_body - np.outer(axial, axis), axis=1)])


def symmetry_axis_body(principal_inertia, rtol: float = 1e-9):
    """The body axis a body with two equal principal moments is symmetric about, or None.

    Parameters
    ----------
    principal_inertia : (3,) float
        Principal moments about the body axes (kg m^2).
    rtol : float
        Relative tolerance for "equal".

    Returns
    -------
    (3,) float or None
        The unit body axis of the distinct moment (None when no two moments, or all three, are equal).
    """
    j = np.asarray(principal_inertia, float)
    for k in range(3):
        a, b = (j[m] for m in range(3) if m != k)
        if abs(a - b) <= rtol * max(a, b) and abs(j[k] - a) > rtol * max(a, j[k]):
            return np.eye(3)[k]
    return None


def cost_f1(model: dict, data: dict, weights, frame: str = "body") -> float:
    r"""One run's term of eq. (18): :math:`w_1 RMSE_r + w_2 (RMSE_{\omega_D} + RMSE_{\omega_C})`.

    Parameters
    ----------
    model, data : dict
        Compared series (:func:`compared_series`): r_D/C (m, inertial), angular velocities (rad/s, body) and,
        for ``frame="inertial"``, the attitudes.
    weights : (2,) float
        w_1 (1/m) and w_2 (s/rad), ``identification.weights``; the cost is dimensionless.
    frame : str
        Components the angular velocities are compared in (:func:`angular_velocity`).

    Returns
    -------
    float
    """
    def omega_rmse(channel):
        return rmse(angular_velocity(model, channel, frame), angular_velocity(data, channel, frame))

    return weights[0] * rmse(model["relative_position"], data["relative_position"]) + weights[1] * (
        omega_rmse("debris_omega_body") + omega_rmse("chaser_omega_body"))


def cost_f1_inertial(model: dict, data: dict, weights) -> float:
    """Eq. (18) with both angular velocities compared in inertial components (:func:`cost_f1`,
    ``frame="inertial"``): the reading of eq. (17d, 17e) in which a turn of a body about its own spin axis
    that leaves its rate in inertial space unchanged costs nothing (docs/towing.md).

    Parameters
    ----------
    model, data : dict
        Compared series with the attitudes (:func:`compared_series`).
    weights : (2,) float
        w_1 (1/m) and w_2 (s/rad).

    Returns
    -------
    float
    """
    return cost_f1(model, data, weights, frame="inertial")


def cost_f2(model: dict, data: dict, weights=None) -> float:
    """One run's term of eq. (20): the RMSE of the main-tether tension.

    Parameters
    ----------
    model, data : dict
        Compared series (:func:`compared_series`); ``main_tether_tension`` (k,) N.
    weights : None
        Not used (same signature as :func:`cost_f1`).

    Returns
    -------
    float
        RMSE of the tension (N).
    """
    return rmse(model["main_tether_tension"], data["main_tether_tension"])


COSTS = {"f1": cost_f1, "f1_inertial": cost_f1_inertial, "f2": cost_f2}


def simulate(case: TowingCase, rate_deg_s: float, s, end_time=None, start=None) -> dict:
    """The compared series of one lower-order run (twin, step ``identification.step``) at spin rate
    ``rate_deg_s`` with sub-tethers ``s``, from the case's start state or from the full-net state ``start``.

    Parameters
    ----------
    case : TowingCase
        A validated towing case.
    rate_deg_s : float
        Debris spin rate (deg/s).
    s : (4,) float
        Sub-tether decision vector [log10 k_ST, l_ST0 (m), log10 c_ST, m_P/m_net] (eq. 22).
    end_time : float or None
        End of the run (s); default the case's.
    start : dict or None
        A full-net state (:func:`riskassess.models.towing_fullnet.net_start_state`): the run starts there
        (the capture-start identification, Sec. 4.1).

    Returns
    -------
    dict
        :func:`compared_series` of the run.
    """
    if start is not None:
        model = lower_order_from_net(case, start, rate_deg_s, s, end_time=end_time, step=case.identification.step)[0]
        return compared_series(run_twin(model))
    return compared_series(run_twin(towing_model(case, rate_deg_s, s, step=case.identification.step,
                                                  end_time=end_time)))


# ------------------------------------------------------------------ parallel evaluation
_WORKER = {}


def _init_worker(case, data, cost, weights, end_time):
    _WORKER.update(case=case, data=data, cost=COSTS[cost], weights=weights, end_time=end_time)


def _run_term(task) -> float:
    """Cost term of one (candidate, rate index) pair, in a worker; a run that fails or diverges (a
    non-finite cost: the twin's state went NaN) scores inf, so it is never the identified answer."""
    s, j = task
    w = _WORKER
    rate = w["data"][j]["rate_deg_s"]
    try:
        term = w["cost"](simulate(w["case"], rate, s, w["end_time"], w["data"][j].get("start")), w["data"][j],
                         w["weights"])
    except (ValueError, ZeroDivisionError, FloatingPointError):
        return np.inf
    return term if np.isfinite(term) else np.inf


class TowingFit(Problem):
    """pymoo problem: minimize ``cost`` of the lower-order runs against ``data`` over s in the bounds;
    each population is evaluated as (candidates x rates) runs on ``pool``."""

    def __init__(self, pool, n_runs, lower, upper):
        super().__init__(n_var=4, n_obj=1, xl=np.asarray(lower, float), xu=np.asarray(upper, float))
        self.pool, self.n_runs = pool, n_runs
        self.evaluations, self.best = [], []

    def _evaluate(self, x, out, *args, **kwargs):
        tasks = [(np.array(s), j) for s in x for j in range(self.n_runs)]
        terms = np.array(self.pool.map(_run_term, tasks, chunksize=max(1, len(tasks) // (4 * self.pool._processes))))
        costs = terms.reshape(len(x), self.n_runs).sum(axis=1)
        out["F"] = costs
        for c in costs:
            self.evaluations.append(len(self.evaluations) + 1)
            self.best.append(min(c, self.best[-1]) if self.best else c)


@dataclass
class Identified:
    """Result of one optimizer run: s (4,), cost, optimizer name, evaluations, wall time (s) and
    the best cost after each evaluation."""

    s: np.ndarray
    cost: float
    optimizer: str
    evaluations: int
    wall_s: float
    history: list


def identify(case: TowingCase, data: list[dict], optimizer: str, end_time=None, workers=None,
             initial_guess=None) -> Identified:
    """Minimize the case's cost (``identification.cost``) against ``data`` (one dict per run: the
    compared series and ``rate_deg_s``) with ``optimizer``, a name of
    :data:`riskassess.stages.optimizers.OPTIMIZERS` ('pso', 'pattern', 'polish', 'mads'; one file each), from
    ``initial_guess`` (default the case's s0). ``ValueError`` listing the known names for another.

    Parameters
    ----------
    case : TowingCase
        A validated towing case (bounds, cost, weights, optimizer settings).
    data : list of dict
        Per run: :func:`compared_series` entries and ``rate_deg_s`` (deg/s).
    optimizer : str
        Optimizer name.
    end_time : float or None
        End of each run (s); default the case's.
    workers : int or None
        Worker processes; default ``identification.workers``.
    initial_guess : (4,) float or None
        Start s_0.

    Returns
    -------
    Identified
    """
    search = OPTIMIZERS[optimizer].search        # an unknown name fails here, before any run
    ident = case.identification
    if ident.cost == "f1_inertial":
        lacking = [f"{float(run['rate_deg_s']):g}" for run in data if not has_attitudes(run)]
        if lacking:   # before any run, not as an infinite cost in every worker
            raise MissingAttitude(f"cost f1_inertial compares angular velocities in inertial components; the runs at "
                                  f"{', '.join(lacking)} deg/s store no attitudes (cached before 2026-11-27: run them "
                                  f"again, or use cost f1)")
    settings = ident.optimizers
    x0 = ident.initial_guess if initial_guess is None else initial_guess
    start = time.perf_counter()
    with multiprocessing.get_context("fork").Pool(
            workers or ident.workers, _init_worker, (case, data, ident.cost, ident.weights, end_time)) as pool:
        problem = TowingFit(pool, len(data), ident.lower_bounds, ident.upper_bounds)
        s, cost = search(problem, x0, settings)
    return Identified(s, cost, optimizer, len(problem.evaluations), time.perf_counter() - start, problem.best)


def training_data(case: TowingCase, s, rates, end_time=None) -> list[dict]:
    """Lower-order runs with sub-tethers ``s`` at ``rates`` (deg/s): the benchmark's data (Sec. 4.3).

    Parameters
    ----------
    case : TowingCase
        A validated towing case.
    s : (4,) float
        Sub-tether decision vector (eq. 22).
    rates : sequence of float
        Debris spin rates (deg/s).
    end_time : float or None
        End of each run (s).

    Returns
    -------
    list of dict
        Per rate, :func:`compared_series` and ``rate_deg_s``.
    """
    return [{**simulate(case, rate, s, end_time), "rate_deg_s": rate} for rate in rates]


def _entry(found: Identified, truth) -> dict:
    return {"s": found.s.tolist(), "cost": found.cost, "optimizer": found.optimizer,
            "relative_error": (np.abs(found.s - truth) / np.abs(truth)).tolist(),
            "evaluations": found.evaluations, "wall_s": found.wall_s, "history": found.history}


def run_optimizers(case: TowingCase, data: list[dict], optimizers=None, end_time=None, workers=None) -> dict:
    """Each of ``optimizers`` (default ``identification.searches``: 'pso' and/or 'pattern') on ``data``
    with :func:`identify`; with ``optimizers.polish_evaluations`` > 0 the PSO's best is polished by a
    pattern search, reported as 'pso+pattern' (evaluations and wall time include the PSO's).
    Returns {name: :class:`Identified`} in the order run.

    Parameters
    ----------
    case : TowingCase
        A validated towing case.
    data : list of dict
        Per run: compared series and ``rate_deg_s`` (deg/s).
    optimizers : list of str or None
        Optimizer names.
    end_time : float or None
        End of each run (s).
    workers : int or None
        Worker processes.
    """
    found = {}
    for name in case.identification.searches if optimizers is None else optimizers:
        found[name] = identify(case, data, name, end_time, workers)
        if name == "pso" and case.identification.optimizers.polish_evaluations > 0:
            swarm = found[name]
            polish = identify(case, data, "polish", end_time, workers, initial_guess=swarm.s)
            found["pso+pattern"] = Identified(polish.s, polish.cost, "pso+pattern", swarm.evaluations + polish.evaluations,
                                              swarm.wall_s + polish.wall_s,
                                              swarm.history + [min(swarm.cost, c) for c in polish.history])
    return found


def benchmark(case: TowingCase, optimizers=None, rates=None, end_time=None, workers=None) -> dict:
    """Sec. 4.3: data from ``benchmark_truth`` at the training rates (same model and step as the
    fit), identified by each optimizer (:func:`run_optimizers`). Returns per optimizer s, cost,
    relative error against the truth, evaluations and wall time.

    Parameters
    ----------
    case : TowingCase
        A towing case with ``identification.benchmark_truth``.
    optimizers : list of str or None
        Optimizer names; default ``identification.searches``.
    rates : sequence of float or None
        Spin rates of the data (deg/s); default ``rates.training_deg_s``.
    end_time : float or None
        End of each run (s).
    workers : int or None
        Worker processes.

    Returns
    -------
    dict
        ``truth``, ``cost_function``, ``rates_deg_s``, ``data_wall_s`` (s) and ``runs`` per optimizer.
    """
    truth = np.asarray(case.identification.benchmark_truth, float)
    rates = case.rates.training_deg_s if rates is None else rates
    start = time.perf_counter()
    data = training_data(case, truth, rates, end_time)
    out = {"truth": truth.tolist(), "cost_function": case.identification.cost, "rates_deg_s": list(rates),
           "data_wall_s": time.perf_counter() - start, "runs": {}}
    for name, found in run_optimizers(case, data, optimizers, end_time, workers).items():
        out["runs"][name] = _entry(found, truth)
    return out


def benchmark_case(case_path, out_dir, case: TowingCase | None = None, end_time=None,
                   overwrite: bool = False) -> dict:
    """`riskassess identify CASE --benchmark`: run :func:`benchmark` and write ``identification.json``
    (every run, history included), ``convergence.png`` and a manifest to ``out_dir`` (claimed by
    :func:`riskassess.products.outfolder.claim`); returns the answer with the best run's ``s``, ``cost``,
    ``optimizer`` and ``wall_s`` on top.

    Parameters
    ----------
    case_path : str or Path
        The towing case file (copied into the folder as ``case.toml``).
    out_dir : str or Path
        The output folder.
    case : TowingCase or None
        The already validated case; read from ``case_path`` when None.
    end_time : float or None
        End of each run (s).
    overwrite : bool
        Replace an earlier identification in ``out_dir``.

    Returns
    -------
    dict
    """
    case = case or load_model(case_path, TowingCase)
    folder = claim_identify_folder(out_dir, case_path, case.name, overwrite)
    with folder.recording():
        answer = _benchmark_into(case, folder, end_time)
    folder.finish("complete")
    return answer


def claim_identify_folder(out_dir, case_path, case_name: str, overwrite: bool) -> OutputFolder:
    """Claim the folder of `riskassess identify` and copy the case into it; on ``overwrite`` the cached
    full-net runs (``fullnet/``) stay when the folder's ``case.toml`` is byte-identical to the case file.

    Parameters
    ----------
    out_dir : str or Path
        The output folder.
    case_path : str or Path
        The towing case file.
    case_name : str
        The case's ``name`` (recorded in the manifest).
    overwrite : bool
        Replace an earlier identification in ``out_dir``.

    Returns
    -------
    OutputFolder
        The claimed folder, status ``running``.
    """
    out, case_path = Path(out_dir), Path(case_path)
    same_case = (out / "case.toml").is_file() and (out / "case.toml").read_bytes() == case_path.read_bytes()
    folder = claim(out, case_name, "identify", overwrite, stage="identify",
                   keep=(lambda name: name.startswith("fullnet/")) if same_case else None)
    with folder.recording():
        results.atomic_write_bytes(folder.path / "case.toml", case_path.read_bytes())
        folder.add_files("case.toml")
    return folder


def _benchmark_into(case: TowingCase, folder: OutputFolder, end_time) -> dict:
    out = folder.path
    start = time.perf_counter()
    answer = benchmark(case, end_time=end_time)
    best = min(answer["runs"].values(), key=lambda r: r["cost"])
    answer = {"case": case.name, "s": best["s"], "cost": best["cost"], "optimizer": best["optimizer"],
              "wall_s": time.perf_counter() - start, **answer}
    results.atomic_write_json(out / "identification.json", answer)
    plot_convergence({name: (np.arange(1, len(r["history"]) + 1), np.maximum(r["history"], 1e-12))
                      for name, r in answer["runs"].items()}, out / "convergence.png",
                     f"{case.name}: Sec. 4.3 benchmark, cost {answer['cost_function']}")
    folder.add_files("identification.json", "convergence.png")
    return answer
