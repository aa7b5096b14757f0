"""`riskassess identify CASE` (without --benchmark): sub-tether identification against full-net runs
(Boonrath, Singh & Botta 2024, Sec. 4.1, 4.4).

1. Full-net runs (:mod:`riskassess.stages.tow_fullnet`, wrapped or capture start) at the training and
   validation spin rates of Table 3 (``full_net.identification_training_runs`` / ``_validation_runs`` take
   the first k), in parallel worker processes, each cached in ``OUT/fullnet/rate_<deg_s>_end_<s>[_capture].npz``
   (a re-run reuses them); the compared series from ``simulation.start_time`` on.
2. The lower-order runs start from the full-net state at the start time, as the paper does (Sec. 4.1):
   debris and chaser states, P at the net node the main tether holds. With the wrapped start the debris
   has the case's Table 2 state, so this is the case with the chaser moved where the full-net run
   starts it and ``sub_tethers.connection_point_start_inertial`` at the central node
   (:func:`lower_order_case`); P's velocity is the debris' rigid motion there, as the node's. With the
   capture start every run has its own state at the start time (the net's capture moved chaser and
   debris): it is kept with the run (:func:`start_state`) and each lower-order run starts from it
   (:func:`riskassess.models.towing_fullnet.lower_order_from_net`, the switch's start state).
3. s is identified on the training runs by each optimizer of ``identification.searches`` (PSO, then the
   pattern-search polish, and/or the pattern search; :func:`riskassess.stages.identify.run_optimizers`) on the
   case's cost, f1 or f2 (eqs. 18, 20), and each identified model is compared with the training runs and
   the unseen validation runs: RMSE per channel (r_D/C, omega_C, omega_D, T_MT, eqs. 19, 21) and both
   costs, per run and summed (the paper's Tables 7, 8 and 10).

A full-net run whose debris was not held (its separation from the chaser beyond what the tether chain,
the net and the debris can span together: :func:`held_reach`) is left out of the identification and
named in the answer's ``excluded_runs``: the lower-order model is a captured debris by construction, so
such a run would only teach it a failed capture (from the capture start at 28.25 and 29.01 deg/s the
debris left to 3.9 km and these two runs made 97.5 % of the training cost: docs/towing.md).
"""
from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

import numpy as np

from riskassess.products import results
from riskassess.cases.impact import CaseError
from riskassess.stages.identify import (COSTS, angular_velocity, axial_and_transverse, claim_identify_folder,
                                        has_attitudes, rmse, simulate, symmetry_axis_body)
from riskassess.products.outfolder import OutputFolder
from riskassess.cases.towing import TowingCase
from multibody.net_towing import run_exudyn
from riskassess.models.towing_fullnet import full_net_model, net_start_state
from riskassess.models.towing_fullnet import wrapped_net
from riskassess.stages.identify import run_optimizers
from riskassess.products.towing_plots import plot_convergence

CHANNELS = ("relative_position", "chaser_omega_body", "debris_omega_body", "main_tether_tension")


#: Attitude series stored with every full-net run since 2026-11-27: rotation matrices body -> Earth-centred
#: inertial, (k, 3, 3), the samples of the compared series (runs cached before then lack them:
#: :func:`riskassess.stages.identify.omega_inertial` names what is missing).
ATTITUDES = ("chaser_to_inertial", "debris_to_inertial")

#: Prefix of the start-state entries of a cached capture-start run (:func:`start_state`).
START = "start_"


def _run_full_net(task):
    """One full-net run in a worker: (case, wrapped net, rate, end) -> compared series from
    ``simulation.start_time`` on (+ start state; the capture start's full state there, prefixed ``start_``)."""
    case, wrapped, rate, end = task
    model = full_net_model(case, rate, wrapped=wrapped, end_time=end)
    capture = case.full_net.start == "capture"
    if capture:
        model.state_at = case.simulation.start_time   # the lower-order runs start there (Sec. 4.1)
    result = run_exudyn(model)
    series = full_net_compared(result.series(), case.simulation.start_time)
    start = {START + k: v for k, v in net_start_state(model, result.state_at).items()} if capture else {}
    return {**series, **start, "rate_deg_s": rate, "chaser_start_inertial": model.positions[0],
            "node_start_inertial": model.node_positions[model.net.central], "wall_s": result.wall_time}


def full_net_compared(series: dict, start_time: float) -> dict:
    """What a cached full-net run keeps of its series (:meth:`multibody.net_towing.NetTowResult.series`): the
    channels of :func:`riskassess.stages.identify.compared_series` and the attitudes (:data:`ATTITUDES`), from
    ``start_time`` on.

    Parameters
    ----------
    series : dict
        The full-net run's series.
    start_time : float
        First compared time (s; ``simulation.start_time``, Sec. 4.1).

    Returns
    -------
    dict
        ``relative_position`` (k, 3) m, inertial; ``chaser_omega_body``, ``debris_omega_body`` (k, 3) rad/s, body
        frames; ``main_tether_tension`` (k,) N; ``chaser_to_inertial``, ``debris_to_inertial`` (k, 3, 3).
    """
    keep = series["time"] >= start_time - 1e-9
    compared = {"relative_position": series["debris_com_inertial"] - series["chaser_com_inertial"],
                "chaser_omega_body": series["chaser_omega_body"], "debris_omega_body": series["debris_omega_body"],
                "main_tether_tension": series["main_tether_tension"],
                # omega in inertial components needs each body's attitude (eq. 17d, 17e; identify.angular_velocity)
                **{key: series[key] for key in ATTITUDES}}
    return {key: value[keep] for key, value in compared.items()}


def start_state(run: dict) -> dict | None:
    """The full-net start state of a cached capture-start run (None for the wrapped start).

    Parameters
    ----------
    run : dict
        A cached full-net run (:func:`full_net_runs`).

    Returns
    -------
    dict or None
        :func:`riskassess.models.towing_fullnet.net_start_state`.
    """
    state = {k[len(START):]: v for k, v in run.items() if k.startswith(START)}
    return state or None


def full_net_runs(case: TowingCase, rates, out: Path, end, workers, record=None) -> list[dict]:
    """Full-net runs at ``rates`` (deg/s), read from ``out``'s cache where present (same end time);
    ``record(relative path)`` is told of each new cache file (the output folder lists it).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table (wrapped start).
    rates : sequence of float
        Debris spin rates (deg/s).
    out : Path
        The output folder; runs are cached in ``out/fullnet``.
    end : float
        End of each run (s).
    workers : int
        Most worker processes.
    record : callable or None
        ``record(relative path)`` for each new cache file.

    Returns
    -------
    list of dict
        Per rate: compared series (r_D/C (k, 3) m inertial, angular velocities (k, 3) rad/s body
        frames, main-tether tension (k,) N; the attitudes body -> inertial (k, 3, 3), :data:`ATTITUDES`, in runs
        cached since 2026-11-27, absent from older ones), ``rate_deg_s``, ``chaser_start_inertial`` and
        ``node_start_inertial`` (3,) m, ``wall_s`` (s).
    """
    cache = out / "fullnet"
    cache.mkdir(parents=True, exist_ok=True)
    tag = "" if case.full_net.start == "wrapped" else f"_{case.full_net.start}"
    path = {rate: cache / f"rate_{rate:.2f}_end_{end:g}{tag}.npz" for rate in rates}
    missing = [rate for rate in rates if not path[rate].exists()]
    if missing:
        wrapped = wrapped_net(case) if case.full_net.start == "wrapped" else None
        with multiprocessing.get_context("fork").Pool(min(workers, len(missing))) as pool:
            # each run cached as soon as it is done: an interrupted call keeps the finished ones
            for run in pool.imap_unordered(_run_full_net, [(case, wrapped, r, end) for r in missing]):
                results.atomic_write_npz(path[run["rate_deg_s"]], run)
                if record:
                    record(path[run["rate_deg_s"]].relative_to(out).as_posix())
    runs = [{k: (float(v) if v.ndim == 0 else v) for k, v in np.load(path[rate]).items()} for rate in rates]
    for run in runs:
        run["start"] = start_state(run)   # None: the wrapped start (the case's own start state)
    return runs


def held_reach(case: TowingCase) -> float:
    """Largest chaser-debris CoM separation (m) at which the debris can still be held: the main tether's
    and a sub-tether's natural lengths, the net's side and the debris' length end to end (the tethers
    stretch by a few per cent at most under the tow's loads; the captured runs stay below 60 % of it).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.

    Returns
    -------
    float
        Separation (m).
    """
    return (case.main_tether.natural_length + case.sub_tethers.natural_length + case.full_net.side_length
            + case.debris.length)


def not_held(run: dict, reach: float) -> dict | None:
    """Why a full-net run's debris was not held, or None when it was.

    Parameters
    ----------
    run : dict
        A full-net run (:func:`full_net_runs`): ``relative_position`` (k, 3) m, ``rate_deg_s``.
    reach : float
        :func:`held_reach` (m).

    Returns
    -------
    dict or None
        ``rate_deg_s``, ``largest_separation_m``, ``reach_m`` and ``reason`` when the separation ever
        passed ``reach``.
    """
    largest = float(np.max(np.linalg.norm(np.asarray(run["relative_position"], float), axis=1)))
    if largest <= reach:
        return None
    return {"rate_deg_s": float(run["rate_deg_s"]), "largest_separation_m": largest, "reach_m": float(reach),
            "reason": f"debris not held: separation reached {largest:.1f} m, beyond the {reach:.1f} m the tethers, "
                      f"the net and the debris can span (a failed capture)"}


def held_runs(case: TowingCase, data: list[dict], n_training: int) -> tuple[list[dict], list[dict], list[dict]]:
    """The training and validation runs whose debris was held (:func:`not_held`), and why each other run was
    left out.

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.
    data : list of dict
        The full-net runs (:func:`full_net_runs`), the training runs first.
    n_training : int
        How many of ``data`` are training runs.

    Returns
    -------
    training, validation, excluded : list of dict
        The held training and validation runs, and :func:`not_held`'s answer for every run left out.

    Raises
    ------
    CaseError
        When no training run is left, naming every left-out rate and why.
    """
    reach = held_reach(case)
    excluded = [why for why in (not_held(run, reach) for run in data) if why is not None]
    left_out = {why["rate_deg_s"] for why in excluded}
    train = [run for run in data[:n_training] if float(run["rate_deg_s"]) not in left_out]
    valid = [run for run in data[n_training:] if float(run["rate_deg_s"]) not in left_out]
    if not train:
        raise CaseError(f"{case.name}: every training run's debris was not held, nothing to identify on: "
                        + "; ".join(f"{w['rate_deg_s']:g} deg/s: {w['reason']}" for w in excluded))
    return train, valid, excluded


def lower_order_case(case: TowingCase, run: dict) -> TowingCase:
    """The case whose lower-order runs start from the full-net start state (module doc, item 2).

    Parameters
    ----------
    case : TowingCase
        The towing case.
    run : dict
        A full-net run (:func:`full_net_runs`): ``chaser_start_inertial`` and ``node_start_inertial``
        (3,) m, inertial.

    Returns
    -------
    TowingCase
        A copy with the chaser position and ``sub_tethers.connection_point_start_inertial`` replaced.
    """
    chaser = case.chaser.model_copy(update={"position_inertial": list(map(float, run["chaser_start_inertial"]))})
    tethers = case.sub_tethers.model_copy(
        update={"connection_point_start_inertial": list(map(float, run["node_start_inertial"]))})
    return case.model_copy(update={"chaser": chaser, "sub_tethers": tethers})


def comparison_rows(case: TowingCase, s, data: list[dict], end) -> list[dict]:
    """Per run of ``data``: RMSE of each channel and both costs (eqs. 18-21) of the lower-order model with ``s``.

    Parameters
    ----------
    case : TowingCase
        The lower-order case (:func:`lower_order_case`).
    s : (4,) float
        Sub-tether decision vector (eq. 22).
    data : list of dict
        Full-net runs (:func:`full_net_runs`).
    end : float
        End of each run (s).

    Returns
    -------
    list of dict
        Per run: ``rate_deg_s``, ``rmse_<channel>`` (m, rad/s or N) and the costs ``f1``, ``f2``; for a debris
        symmetric about a body axis also ``rmse_debris_omega_free_roll`` and ``f1_free_roll``, eq. (18) with
        omega_D compared blind to a roll about that axis (:func:`riskassess.stages.identify.rmse_free_roll`;
        the paper's omega_D is the rate relative to the inertial frame, the frame it is compared in is not
        stated; docs/towing.md: our full-net debris rolls slowly about its axis and the body-frame f1 counts it);
        and the rates compared in inertial components (:func:`inertial_rows`: ``rmse_chaser_omega_inertial``,
        ``rmse_debris_omega_inertial``, ``f1_inertial``, or ``inertial_missing`` for a run cached without attitudes).
    """
    axis = symmetry_axis_body(case.debris.principal_inertia)
    rows = []
    for run in data:
        model = simulate(case, run["rate_deg_s"], s, end, run.get("start"))
        row = {"rate_deg_s": run["rate_deg_s"], **{f"rmse_{c}": rmse(model[c], run[c]) for c in CHANNELS},
               "f1": COSTS["f1"](model, run, case.identification.weights), "f2": COSTS["f2"](model, run)}
        row.update(inertial_rows(model, run, case.identification.weights))
        if axis is not None:
            # eq. (18) itself on omega_D's roll-blind components (their RMSE is rmse_free_roll's)
            blind_model = {**model, "debris_omega_body": axial_and_transverse(model["debris_omega_body"], axis)}
            blind_run = {**run, "debris_omega_body": axial_and_transverse(run["debris_omega_body"], axis)}
            row.update(rmse_debris_omega_free_roll=rmse(blind_model["debris_omega_body"], blind_run["debris_omega_body"]),
                       f1_free_roll=COSTS["f1"](blind_model, blind_run, case.identification.weights))
        rows.append(row)
    return rows


def inertial_rows(model: dict, run: dict, weights) -> dict:
    """The angular-velocity RMSEs and f1 with the rates compared in inertial components (eq. 18 read in the
    inertial frame, :func:`riskassess.stages.identify.cost_f1_inertial`), or what is missing for them.

    Parameters
    ----------
    model : dict
        The lower-order run's compared series (with its attitudes).
    run : dict
        A cached full-net run.
    weights : (2,) float
        w_1 (1/m), w_2 (s/rad).

    Returns
    -------
    dict
        ``rmse_chaser_omega_inertial``, ``rmse_debris_omega_inertial`` (rad/s) and ``f1_inertial``; or, for a run
        cached without attitudes, ``inertial_missing``: why they are not given.
    """
    if not has_attitudes(run):
        return {"inertial_missing": f"the full-net run stores no attitudes ({', '.join(ATTITUDES)}): "
                                    f"cached before 2026-11-27"}
    return {**{f"rmse_{c.replace('_body', '_inertial')}": rmse(angular_velocity(model, c, "inertial"),
                                                               angular_velocity(run, c, "inertial"))
               for c in ("chaser_omega_body", "debris_omega_body")},
            "f1_inertial": COSTS["f1_inertial"](model, run, weights)}


def _totals(rows: list[dict]) -> dict | None:
    """Sums of f1 and f2 over the runs (eqs. 18, 20) and the mean RMSE of each channel; None without runs
    (every validation run left out as not held: no score, rather than a sum of 0 that reads as perfect)."""
    if not rows:
        return None
    totals = {"f1": sum(r["f1"] for r in rows), "f2": sum(r["f2"] for r in rows),
              **{f"mean_rmse_{c}": float(np.mean([r[f"rmse_{c}"] for r in rows])) for c in CHANNELS}}
    for key in ("f1_free_roll", "f1_inertial"):
        if all(key in r for r in rows):
            totals[key] = sum(r[key] for r in rows)
    return totals


def _entry(case: TowingCase, found, training: list[dict], validation: list[dict], end) -> dict:
    """One optimizer's answer: s, its training cost and history, and the identified model against the
    training and the unseen validation runs (per run and totals)."""
    train_rows, valid_rows = comparison_rows(case, found.s, training, end), comparison_rows(case, found.s, validation, end)
    return {"s": found.s.tolist(), "cost": found.cost, "optimizer": found.optimizer, "evaluations": found.evaluations,
            "wall_s": found.wall_s, "history": found.history, "training_totals": _totals(train_rows),
            "validation_totals": _totals(valid_rows), "training": train_rows, "validation": valid_rows}


def identify_full_net(case_path, out_dir, case: TowingCase, optimizers=None, overwrite: bool = False) -> dict:
    """Steps 1-3 of the module doc with ``optimizers`` (default ``identification.searches``) on the case's
    cost; writes ``identification.json`` (every optimizer's run), ``convergence.png`` and a manifest to
    ``out_dir`` (claimed by :func:`riskassess.products.outfolder.claim`; with ``overwrite`` the cached full-net runs
    are kept when the folder's ``case.toml`` is the same file, byte for byte). Returns the answer with the
    best run's ``s``, ``cost`` and ``optimizer`` on top.

    Parameters
    ----------
    case_path : str or Path
        The towing case file.
    out_dir : str or Path
        The output folder.
    case : TowingCase
        The validated case; it needs a ``[full_net]`` table with the wrapped start.
    optimizers : list of str or None
        Optimizer names.
    overwrite : bool
        Replace an earlier identification in ``out_dir``.

    Returns
    -------
    dict
    """
    fn = case.full_net
    if fn is None:
        raise CaseError(f"{case_path}: identification against full-net runs needs a [full_net] section")
    if fn.start == "run":
        raise CaseError(f"{case_path}: full_net.start = 'run' is not supported by 'riskassess identify': every "
                         f"training and validation rate would need its own impact run; use 'capture' (the capture "
                         f"simulated by the towing model) or 'wrapped'")
    folder = claim_identify_folder(out_dir, case_path, case.name, overwrite)
    with folder.recording():
        answer = _identify(case, folder, optimizers)
    folder.finish("complete")
    return answer


def _identify(case: TowingCase, folder: OutputFolder, optimizers) -> dict:
    """Steps 1-3 into the claimed ``folder``; returns the answer."""
    fn, out = case.full_net, folder.path
    end = fn.identification_end_time or case.simulation.end_time
    training = case.rates.training_deg_s[:fn.identification_training_runs]
    validation = case.rates.validation_deg_s[:fn.identification_validation_runs]
    start = time.perf_counter()
    data = full_net_runs(case, list(training) + list(validation), out, end, case.identification.workers,
                         record=folder.add_files)
    data_wall = time.perf_counter() - start
    train, valid, excluded = held_runs(case, data, len(training))
    lower = lower_order_case(case, train[0])
    runs = {name: _entry(lower, found, train, valid, end)
            for name, found in run_optimizers(lower, train, optimizers, end_time=end).items()}
    best = min(runs.values(), key=lambda r: r["cost"])
    answer = {"case": case.name, "s": best["s"], "cost": best["cost"], "optimizer": best["optimizer"],
              "cost_function": case.identification.cost, "wall_s": time.perf_counter() - start, "end_time_s": end,
              "training_rates_deg_s": list(training), "validation_rates_deg_s": list(validation),
              "full_net_runs_wall_s": data_wall, "excluded_runs": excluded, "runs": runs}
    results.atomic_write_json(out / "identification.json", answer)
    plot_convergence({name: (np.arange(1, len(r["history"]) + 1), np.asarray(r["history"])) for name, r in runs.items()},
                     out / "convergence.png", f"{case.name}: against full-net runs, cost {case.identification.cost}")
    folder.add_files("identification.json", "convergence.png")
    return answer
