"""Full-net towing runs (``simulation.model = "full-net"``): the model of
:mod:`riskassess.models.towing_fullnet` run by Exudyn, its figures and the run folder of
``riskassess tow`` for it (the lower-order files plus ``net.npz``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from multibody.net_towing import run_exudyn
from multibody.towing import run_exudyn as run_lower_order
from multibody.net_wrap import wrap_summary
from riskassess.products import results
from riskassess.models.towing_fullnet import debris_geometry, full_net_model, lower_order_after_switch, wrapped_net
from riskassess.products.towing_figures import run_figures
from riskassess.cases.towing import TowingCase


def momentum_residual(series: dict) -> float:
    """Largest |P(t) - P(t0) - external impulse| over the run (N s): chaser, debris and net together
    exchange momentum only through internal forces (threads, contact, main tether).

    Parameters
    ----------
    series : dict
        Full-net series: ``total_momentum_inertial`` and ``external_impulse_inertial``, (k, 3) N s, inertial.

    Returns
    -------
    float
        (N s).
    """
    p, j = series["total_momentum_inertial"], series["external_impulse_inertial"]
    return float(np.linalg.norm(p - p[0] - (j - j[0]), axis=1).max())


def summarize_full_net(case: TowingCase, result, wrap: dict) -> dict:
    """The figures of every towing run (:func:`riskassess.products.towing_figures.run_figures`) for a full-net run, plus
    the net's: wrapped-state shape, contact, closing-loop tension, momentum balance.

    Parameters
    ----------
    case : TowingCase
        The towing case.
    result : multibody.net_towing.NetTowResult
        The finished full-net run.
    wrap : dict or None
        :func:`multibody.net_wrap.wrap_summary` of the wrapped start (None for the capture start).

    Returns
    -------
    dict
        JSON-ready, SI (tensions in N, momentum residual in N s, times in s).
    """
    series = result.series()
    model = result.model
    return {
        **run_figures(case, series, model), "model": "full-net",
        "net": {"nodes": int(len(model.node_positions)), "wrapped_state": wrap,
                "mean_contacts": float(series["net_contacts"].mean()),
                "closing_thread_peak_tension_N": float(series["closing_thread_peak_tension"].max()),
                "momentum_residual_Ns": momentum_residual(series)},
        "net_step_s": model.step / model.substeps, "wall_time_s": result.wall_time,
        "steps_per_second": model.n_steps / result.wall_time,
    }


def joined_series(full: dict, lower: dict) -> dict:
    """One series across the switch: the full-net samples up to the switch time, then the lower-order
    samples after it (its first sample, the switch state itself, is the full-net run's last one).
    A series only one model has is NaN where the other ran; ``lower_order`` (k,) bool says which ran.

    Parameters
    ----------
    full : dict
        Full-net series (:meth:`multibody.net_towing.NetTowResult.series`, without the net snapshots).
    lower : dict
        Lower-order series (:meth:`multibody.towing.TowResult.series`), starting at the switch.

    Returns
    -------
    dict
        SI, frames in the names.
    """
    k_full, k_lower = len(full["time"]), len(lower["time"]) - 1
    out = {}
    for key in dict.fromkeys([*full, *lower]):
        a = full.get(key)
        b = lower[key][1:] if key in lower else None
        if a is None:
            a = np.full((k_full, *b.shape[1:]), np.nan)
        if b is None:
            b = np.full((k_lower, *a.shape[1:]), np.nan)
        out[key] = np.concatenate([a, b])
    out["lower_order"] = np.r_[np.zeros(k_full, bool), np.ones(k_lower, bool)]
    return out


def full_net_start(case: TowingCase, run_start=None):
    """The full-net model of the case's start (wrapped, capture or an impact run's end state) and the
    wrapped-state summary (None unless wrapped).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.
    run_start : riskassess.models.towing_from_run.RunStart or None
        The impact run's end state (``full_net.start = "run"``).

    Returns
    -------
    model : multibody.net_towing.FullNetModel
    wrap : dict or None
    """
    if case.full_net.start in ("capture", "run"):
        return full_net_model(case, run_start=run_start), None
    net, x_body = wrapped_net(case)
    return full_net_model(case, wrapped=(net, x_body)), wrap_summary(x_body, net, debris_geometry(case))


def run_full_net(case: TowingCase, out: Path, run_start=None) -> tuple[dict, dict]:
    """Run the case's full-net tow, switching to the lower-order model at quasi-steady state when
    ``full_net.switch_to_lower_order`` (:mod:`multibody.tow_switch`); write towing.npz (the joined
    series, :func:`joined_series`), net.npz, towing.json to ``out``. Returns (summary, series).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.
    out : Path
        The claimed run folder.
    run_start : riskassess.models.towing_from_run.RunStart or None
        The impact run's end state (``full_net.start = "run"``).
    """
    model, wrap = full_net_start(case, run_start)
    net = model.net
    result = run_exudyn(model)
    series = result.series()
    summary = summarize_full_net(case, result, wrap)
    if run_start is not None:
        summary["start"] = {"from_run": str(run_start.folder), "time_s": run_start.time}
    net_keys = ("net_time", "net_nodes_inertial")
    written = {k: v for k, v in series.items() if k not in net_keys}
    if model.switch is not None:
        summary["switch"] = None  # never quasi-steady: the full-net model ran to the end
        if result.switch is not None:
            lower, balance = lower_order_after_switch(case, result)
            lower_result = run_lower_order(lower)
            written = joined_series(written, lower_result.series())
            summary = {**summary, **run_figures(case, written, model), "switch": balance,
                       "wall_time_s": result.wall_time + lower_result.wall_time}
    results.atomic_write_npz(out / "towing.npz", written)
    top = net.topology
    results.atomic_write_npz(out / "net.npz", {"time": series["net_time"], "nodes_inertial": series["net_nodes_inertial"],
                                               "threads": top.threads, "rest_lengths": top.rest_lengths,
                                               "stiffness": top.stiffness, "closing_threads": len(net.closing_rest_closed)})
    results.atomic_write_json(out / "towing.json", summary)
    return summary, written
