"""Report sections of a sweep: the safe envelope (statement, plots) and the table of runs."""
from __future__ import annotations

from collections import defaultdict

import numpy as np
from matplotlib.figure import Figure as MplFigure

from riskassess.cases.doc import key_unit
from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.plotting import WIDTH_IN, legend, panels, plain
from riskassess.products.envelope import (UNKNOWN, envelope, envelope_statement, is_probabilistic, run_status,
                                          utilization_sensitivity)
from structures.verdict import DEBRIS, NO_DEBRIS

#: How the runs table shows a run's outcome.
STATUS_TEXT = {DEBRIS: "YES", NO_DEBRIS: "no", "indeterminate": "INDETERMINATE", "failed": "-", "pending": "-",
               "unassessed": "-"}


def _by_value(rows: list[dict], key: str) -> dict[float, list[dict]]:
    """Records of the runs with a known verdict (debris or no debris), by value of ``key``."""
    groups = defaultdict(list)
    for r in rows:
        if run_status(r) in (DEBRIS, NO_DEBRIS):
            groups[r["overrides"][key]].append(r["result"])
    return dict(sorted(groups.items()))


def _band(ax, x, values_per_x, label, color=None, scale=1.0):
    """Max over the runs at each x (line) and the min-max band over Monte Carlo samples."""
    high = np.array([max(v) for v in values_per_x]) * scale
    low = np.array([min(v) for v in values_per_x]) * scale
    line, = ax.plot(x, high, marker="o", ms=3, color=color, label=plain(label))
    if (high > low).any():
        ax.fill_between(x, low, high, color=line.get_color(), alpha=0.15, lw=0)


def envelope_figure(rows: list[dict], env: dict, figure_id: str = "fig-envelope") -> Figure:
    """Utilization, peak stresses and breakup likelihood of the runs against the envelope's key.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store (:meth:`riskassess.sweep.store.ResultStore.rows`).
    env : dict
        The envelope (:func:`riskassess.products.envelope.envelope`); its ``key`` is the x axis,
        in the key's SI unit.
    figure_id : str
        HTML id of the figure.

    Returns
    -------
    Figure
    """
    key = env["key"]
    groups = _by_value(rows, key)
    x = np.array(list(groups))
    locations = sorted({name for results in groups.values() for r in results for name in r["locations"]})
    stressed = [n for n in locations if any("normal_stress" in r["locations"][n]["peaks"]
                                            for results in groups.values() for r in results)]
    fig, (ax_u, ax_s, ax_b) = panels(3, 1.9)
    for name in locations:
        _band(ax_u, x, [[r["locations"][name]["utilization"] for r in results] for results in groups.values()], name)
    ax_u.axhline(1.0, color="tab:red", ls="--", lw=1.0, label="decisive allowable")
    ax_u.set_ylabel("demand / allowable (-)")
    ax_u.set_title("utilization: peak demand over decisive allowable (largest criterion)")
    legend(ax_u)
    for name in stressed:
        for crit, style in (("normal_stress", "-"), ("shear_stress", ":")):
            values = [[r["locations"][name]["peaks"][crit] for r in results] for results in groups.values()]
            _band(ax_s, x, values, f"{name} {crit.split('_')[0]}", scale=1e-6)
    if stressed:
        ax_s.set_yscale("log")
    ax_s.set_ylabel("peak stress (MPa)")
    ax_s.set_title("peak normal and shear stress at the sections")
    if stressed:
        legend(ax_s)
    else:
        ax_s.text(0.5, 0.5, "no section with a material", ha="center", transform=ax_s.transAxes)
    _band(ax_b, x, [[r["breakup_likelihood"] for r in results] for results in groups.values()],
          "breakup likelihood (range allowables)")
    ax_b.plot(x, [np.mean([r["secondary_debris"] for r in results]) for results in groups.values()], "s--",
              ms=3, color="tab:red", label="fraction of runs with secondary debris")
    ax_b.set_ylim(-0.03, 1.03)
    ax_b.set_ylabel("probability (-)")
    ax_b.set_title("breakup")
    legend(ax_b)
    unit = key_unit(key)
    ax_b.set_xlabel(plain(f"{key} ({unit})" if unit else key))
    return Figure.from_matplotlib(figure_id, f"Envelope against {key}: lines are the largest value over "
                                  f"the runs at each {key}, bands the spread over those runs (Monte Carlo samples and the values "
                                  f"of any other varied key).", fig)


def envelope_section(rows: list[dict], env: dict, other_keys=()) -> Section:
    """The envelope against ``env['key']``, plus one figure against each other varied key.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store.
    env : dict
        The envelope (:func:`riskassess.products.envelope.envelope`).
    other_keys : sequence of str
        Further varied case keys, one figure each.

    Returns
    -------
    Section
    """
    blocks = [Note(envelope_statement(env), "info" if env["deterministic_safe_limit"] is not None else "alarm")]
    if any(p["runs"] for p in env["points"]):
        blocks.append(envelope_figure(rows, env))
        for k, key in enumerate(other_keys):
            blocks.append(envelope_figure(rows, envelope(rows, key, env["confidence"], env["reliability"]),
                                          f"fig-envelope-{k + 2}"))
    if env["points"]:
        blocks.append(Table(
            [env["key"], "runs", "with debris", "failed", "indeterminate", "pending",
             f"P(no debris) lower bound ({env['confidence']:.0%})", "safe", "max utilization",
             "max breakup likelihood"],
            [[f"{p['value']:.4g}", str(p["runs"]), str(p["with_debris"]), str(p["failed_runs"]),
              str(p["indeterminate_runs"]), str(p["pending_runs"]), f"{p['no_debris_lower_bound']:.3f}",
              "yes" if (p["safe"] if is_probabilistic(env) else p["deterministic_safe"]) else "NO",
              _number(p["max_utilization"]), _number(p["max_breakup_likelihood"])] for p in env["points"]],
            "Envelope points (failed, indeterminate and pending runs count as runs with debris)",
            alarm_rows={k for k, p in enumerate(env["points"]) if p["with_debris"] or p["unknown_runs"]}))
    if any(env[f"{what}_runs"] for what in UNKNOWN):
        blocks.append(Note(f"{env['failed_runs']} failed ({env['diverged_runs']} diverged), "
                           f"{env['indeterminate_runs']} indeterminate and {env['pending_runs']} pending runs are "
                           f"unknown: the envelope counts each as a run with secondary debris, never as safe (see "
                           f"the runs table; --retry-failed re-runs failed runs, a re-run finishes pending ones).",
                           "warning"))
    return Section("envelope", "Safe impact envelope", blocks)


def tornado_figure(sensitivity: dict) -> Figure:
    """One panel per weak location: the rank correlation of its utilization with each input, largest
    magnitude on top (a tornado plot).

    Parameters
    ----------
    sensitivity : dict
        Location -> {input key -> Spearman rho (-1 to 1) or None}
        (:func:`riskassess.products.envelope.utilization_sensitivity`), at least one location.

    Returns
    -------
    Figure
    """
    names = list(sensitivity)
    keys = list(next(iter(sensitivity.values())))
    fig = MplFigure(figsize=(WIDTH_IN, 0.7 + len(names) * (0.35 + 0.28 * len(keys))), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(names), 1, sharex=True))
    for ax, name in zip(axes, names):
        rho = {k: v for k, v in sensitivity[name].items() if v is not None}
        order = sorted(rho, key=lambda k: abs(rho[k]))
        ax.barh([plain(k) for k in order], [rho[k] for k in order],
                color=["tab:red" if rho[k] > 0 else "tab:blue" for k in order])
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_title(plain(name), loc="left")
        if not rho:
            ax.text(0.5, 0.5, "no finite utilization, or a constant input", ha="center", transform=ax.transAxes)
    axes[-1].set_xlim(-1.05, 1.05)
    axes[-1].set_xlabel("Spearman rank correlation of the utilization with the input (-)")
    return Figure.from_matplotlib("fig-sensitivity", "Sensitivity of each weak location's utilization (peak demand "
                                  "over decisive allowable) to each varied or uncertain input: rank correlation over the "
                                  "finished runs (red: the demand grows with the input).", fig)


def sensitivity_section(rows: list[dict]) -> Section | None:
    """The tornado plot of :func:`tornado_figure`, for a sweep with at least 3 finished runs.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store.

    Returns
    -------
    Section or None
    """
    sensitivity = utilization_sensitivity(rows)
    if not sensitivity or not any(v is not None for s in sensitivity.values() for v in s.values()):
        return None
    return Section("sensitivity", "Sensitivity of the utilization to the inputs", [tornado_figure(sensitivity)])


def _number(value) -> str:
    return "-" if value is None else f"{value:.3f}"


def runs_section(rows: list[dict]) -> Section:
    """The table of every run: id, overrides, state, secondary debris, peak contact force (N), wall
    time (s) and error.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store (:meth:`riskassess.sweep.store.ResultStore.rows`).

    Returns
    -------
    Section
    """
    keys = list(rows[0]["overrides"]) if rows else []
    table_rows = []
    for r in rows:
        result = r["result"] or {}
        status = run_status(r)
        table_rows.append([r["run_id"], *(f"{r['overrides'][k]:.5g}" for k in keys),
                           r["state"] + (f" ({r['error_kind']})" if r["state"] == "failed" else ""),
                           STATUS_TEXT[status],
                           f"{result['peak_contact_force_N']:.4g}" if result else "-",
                           f"{result['wall_time_s']:.1f}" if result else "-", (r["error"] or "")[:120]])
    return Section("sweep-runs", "Runs", [Table(["run", *keys, "state", "secondary debris", "peak contact force (N)",
                                                  "wall time (s)", "error"], table_rows,
                                                 alarm_rows={k for k, r in enumerate(rows)
                                                             if run_status(r) in ("failed", "indeterminate")})])
