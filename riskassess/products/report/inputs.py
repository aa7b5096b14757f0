"""Report sections that restate what was run: the case inputs with units, and the run facts."""
from __future__ import annotations

from itertools import groupby

import numpy as np
from pydantic import ValidationError

from riskassess.cases.doc import input_rows
from riskassess.cases.impact import Case
from riskassess.products.report.blocks import Note, Section, Table
from riskassess.products.results import MissingData, RunFolder
from riskassess.products.tables import format_vector


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


def _validated_rows(case: dict):
    """Input rows with units, or raw rows and a warning for a case.json of another format version."""
    try:
        return input_rows(Case.model_validate(case)), None
    except ValidationError as exc:
        return [(k, str(v), "", "") for k, v in _flatten(case)], Note(
            f"case.json does not match this version's case format ({exc.error_count()} differences); inputs are "
            f"listed without units.", "warning")


def _bodies_table(case: dict) -> Table:
    rows = []
    for body in case["target"]["bodies"]:
        inertia = body.get("inertia")
        rows.append([body["name"], f"{body['mass']:.6g}", _vector(body.get("center_of_mass")),
                     _vector([inertia[i][i] for i in range(3)]) if inertia else "from the shapes",
                     ", ".join(shape["kind"] for shape in body["shapes"])])
    return Table(["body", "mass (kg)", "CoM, target frame (m)", "inertia diagonal (kg m^2)", "shapes"], rows,
                 "Debris bodies")


def _joints_table(case: dict) -> Table:
    rows = [[j["name"], j["kind"], f"{j['parent']} -> {j['child']}", _vector(j["position"]), _vector(j["axis"]),
             f"{j['torsional_stiffness']:.4g}", f"{j['torsional_damping']:.4g}", f"{j['initial_angle']:.4g}"]
            for j in case["target"].get("joints", [])]
    return Table(["joint", "kind", "parent -> child", "point, target frame (m)", "axis h2", "k (N m/rad)",
                  "c (N m s/rad)", "initial angle (rad)"], rows, "Joints")


def _vector(values) -> str:
    return "-" if values is None else format_vector(values, 4)


def case_section(run: RunFolder) -> Section:
    """At a glance, the scalar inputs with units, the bodies and the joints; every input is in the appendix.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``case.json``).

    Returns
    -------
    Section
    """
    case = run.case
    rows, warning = _validated_rows(case)
    scalar = [[key, value, unit] for key, value, unit, _ in rows
              if "." in key and not key.startswith(("target.", "structures."))]
    blocks = [_at_a_glance(run, case)] + ([warning] if warning else [])
    blocks.append(Table(["input", "value", "unit"], scalar, "Simulation, orbit, net, bullets, launch and contact",
                        css_class="inputs-short"))
    try:
        blocks += [_bodies_table(case), _joints_table(case)]
    except (KeyError, TypeError):
        blocks.append(Note("The bodies and joints of this case.json could not be read (another format version); "
                           "see the appendix.", "warning"))
    blocks.append(Note("Every input of the case, with its meaning, is listed in the appendix; weak locations are "
                       "in the verdict and the appendix."))
    return Section("case", "Case summary: inputs", blocks)


def appendix_inputs_section(run: RunFolder) -> Section:
    """Every input of the validated case, grouped by table, with value, unit and meaning.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``case.json``).

    Returns
    -------
    Section
    """
    rows, warning = _validated_rows(run.case)
    blocks = [warning] if warning else []
    for group, items in groupby(rows, key=lambda r: r[0].rpartition(".")[0]):
        items = [[key.rpartition(".")[2], value, unit, _meaning_without_unit(meaning, unit)]
                 for key, value, unit, meaning in items]
        if not group:  # name and description, shown in the title
            continue
        blocks.append(Table(["key", "value", "unit", "meaning"], items, f"[{group}]", css_class="inputs"))
    return Section("appendix-inputs", "Appendix: every case input", blocks)


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
    """Integrator, step, wall time, output rates, folder format and software versions of the run.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``summary.json``, ``case.json``, ``timeseries.npz``, ``net.npz``).

    Returns
    -------
    Section
    """
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
