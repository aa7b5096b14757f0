"""Full-net towing runs (``simulation.model = "full-net"``): the model of
:mod:`riskassess.models.towing_fullnet` run by Exudyn, its figures and the run folder of
``riskassess tow`` for it (the lower-order files plus ``net.npz``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from multibody.net_towing import run_exudyn
from multibody.net_wrap import wrap_summary
from riskassess.products import results
from riskassess.models.towing_fullnet import debris_geometry, full_net_model, wrapped_net
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


def run_full_net(case: TowingCase, out: Path) -> tuple[dict, dict]:
    """Run the case's full-net tow; write towing.npz, net.npz, towing.json to ``out``. Returns
    (summary, series).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.
    out : Path
        The claimed run folder.
    """
    if case.full_net.start == "capture":
        model = full_net_model(case)
        net, wrap = model.net, None
    else:
        net, x_body = wrapped_net(case)
        model = full_net_model(case, wrapped=(net, x_body))
        wrap = wrap_summary(x_body, net, debris_geometry(case))
    result = run_exudyn(model)
    series = result.series()
    summary = summarize_full_net(case, result, wrap)
    net_keys = ("net_time", "net_nodes_inertial")
    results.atomic_write_npz(out / "towing.npz", {k: v for k, v in series.items() if k not in net_keys})
    top = net.topology
    results.atomic_write_npz(out / "net.npz", {"time": series["net_time"], "nodes_inertial": series["net_nodes_inertial"],
                                               "threads": top.threads, "rest_lengths": top.rest_lengths,
                                               "stiffness": top.stiffness, "closing_threads": len(net.closing_rest_closed)})
    results.atomic_write_json(out / "towing.json", summary)
    return summary, series
