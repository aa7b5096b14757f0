"""Report sections that restate what was run: the case inputs with units, and the run facts."""
from __future__ import annotations

from itertools import groupby

import numpy as np
from pydantic import ValidationError

from riskassess.casedoc import input_rows
from riskassess.case import Case
from riskassess.report.blocks import Note, Section, Table
from riskassess.results import MissingData, RunFolder


def _at_a_glance(run: RunFolder, case: dict) -> Table:
    rows = [["impact speed of the net", f"{case['launch']['velocity']:.4g}", "m/s"],
            ["net side, nodes per side", f"{case['net']['side_length']:.4g}, {case['net']['nodes_per_side']}", "m, -"]]
    try:
        net = run.net
        rows.append(["net mass incl. bullets", f"{net['masses'].sum():.4g}", "kg"])
    except MissingData:
        pass
    bodies = case["target"]["bodies"]
    rows.append(["debris mass (all bodies)", f"{sum(b['mass'] for b in bodies):.6g}", "kg"])
    rows.append(["debris bodies, joints", f"{len(bodies)}, {len(case['target'].get('joints', []))}", "-"])
    orbit = case["orbit"]
    rows.append(["orbit", f"circular, {orbit['altitude'] / 1e3:.4g} km" if orbit["kind"] == "circular"
                 else "none (free space)", ""])
    sim = case["simulation"]
    rows.append(["simulated time, step", f"{sim['end_time']:.4g}, {sim['step']:.3g}", "s"])
    return Table(["quantity", "value", "unit"], rows, "At a glance")


def case_section(run: RunFolder) -> Section:
    case = run.case
    blocks = [_at_a_glance(run, case)]
    try:
        rows = input_rows(Case.model_validate(case))
    except ValidationError as exc:
        blocks.append(Note(f"case.json does not match this version's case format ({exc.error_count()} "
                           f"differences); inputs are listed without units.", "warning"))
        rows = [(k, str(v), "", "") for k, v in _flatten(case)]
    for group, items in groupby(rows, key=lambda r: r[0].rpartition(".")[0]):
        items = [[key.rpartition(".")[2], value, unit, _meaning_without_unit(meaning, unit)]
                 for key, value, unit, meaning in items]
        if not group:  # name and description, shown above
            continue
        blocks.append(Table(["key", "value", "unit", "meaning"], items, f"[{group}]", css_class="inputs"))
    return Section("case", "Case summary: inputs", blocks)


def _meaning_without_unit(meaning: str, unit: str) -> str:
    """The description without its '(unit)', which has its own column."""
    return meaning.replace(f" ({unit})", "").replace(f"({unit})", "").strip() if unit else meaning


def _flatten(data, prefix=""):
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _flatten(v, f"{prefix}{k}.")
    elif isinstance(data, list) and data and isinstance(data[0], dict):
        for k, v in enumerate(data):
            yield from _flatten(v, f"{prefix[:-1]}[{k}].")
    else:
        yield prefix[:-1], data


def run_facts_section(run: RunFolder) -> Section:
    summary, manifest, case = run.summary, run.manifest, run.case
    sim = case["simulation"]
    steps_per_s = summary.get("steps_per_second")
    rows = [
        ["integrator", summary["integrator"]],
        ["step (s)", f"{summary['step_s']:.3g}"],
        ["shortest contact sub-step (s)", f"{sim['contact_substep']:.3g}"],
        ["steps", f"{summary['steps']}"],
        ["simulated time (s)", f"{summary['simulated_time_s']:.4g}"],
        ["wall time (s)", f"{summary['wall_time_s']:.1f}"],
        ["steps per second", f"{steps_per_s:.0f}" if steps_per_s else "-"],
        ["output rates: time series, net snapshots (Hz)", f"{sim['output_rate']:g}, {sim['net_output_rate']:g}"],
        ["run created (UTC)", manifest.get("created", "-")],
        ["run status", manifest.get("status", "-")],
        ["run folder", str(run.path.resolve())],
        ["run folder format", f"{manifest['format']} version {manifest.get('version')}"],
    ]
    rows += [[f"version of {name}", version] for name, version in manifest.get("software", {}).items()]
    series = run.timeseries
    rows.append(["time-series samples, net snapshots", f"{len(series['time'])}, {len(run.net['time'])}"])
    rows.append(["bodies (mass, kg)", ", ".join(f"{n} ({m:.4g})" for n, m in
                                                zip(series["body_names"], np.asarray(series["body_masses"])))])
    return Section("run-facts", "Run facts", [Table(["item", "value"], rows)])
