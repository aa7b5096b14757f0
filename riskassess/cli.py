"""``riskassess`` command line: parse, load the case, call the pipeline, print. No physics here."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from riskassess.case import Case, CaseError, load_case


def _cmd_run(args) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from riskassess.pipeline import run_case

    case = load_case(args.case)  # fail fast on a bad case, before any output folder exists
    out = Path(args.out) if args.out else Path("runs") / case.name
    end = case.simulation.end_time
    columns = [TextColumn("[bold]simulating[/bold] {task.fields[t]:.3f} / %.3g s" % end), BarColumn(),
               TimeElapsedColumn(), TimeRemainingColumn()]
    with Progress(*columns, disable=args.json or not sys.stderr.isatty(), transient=True) as bar:
        task = bar.add_task("run", total=end, t=0.0)
        result = run_case(args.case, out, progress=lambda t: bar.update(task, completed=t, t=t), case=case)
    if args.json:
        extra = {"structures": result.structures} if result.structures is not None else {}
        print(json.dumps({**result.summary, **extra}, indent=2))
    else:
        print_summary(result.summary, result.run_dir)
        if result.structures is not None:
            print_verdict(result.structures)
    return 0


def _cmd_assess(args) -> int:
    case = load_case(args.case)
    if case.structures is None:
        raise CaseError(f"{args.case}: structures: missing; 'assess' needs [[structures.weak_locations]] "
                        f"(see docs/case-format.md)")
    return _cmd_run(args)


def _format_value(value, unit):
    scale, prefix = (1e-6, "MPa") if unit == "Pa" else (1.0, unit)
    return f"{value * scale:.4g} {prefix}"


def _format_allowable(low, high, unit):
    return _format_value(low, unit) if low == high else f"{_format_value(low, unit)} - {_format_value(high, unit)}"


def print_verdict(verdict: dict) -> None:
    """The verdict table: location, criterion, peak demand, allowable, margin, fails?, released piece."""
    from rich.console import Console
    from rich.table import Table

    console = Console(width=None if sys.stdout.isatty() else 150)
    table = Table(title=f"structural verdict (loads after {verdict['skip_initial_s']:g} s; "
                        f"range allowables decide at their '{verdict['release_policy']}' value)")
    for column, justify in (("location", "left"), ("criterion", "left"), ("max demand", "right"),
                            ("allowable", "right"), ("margin", "right"), ("fails?", "center"),
                            ("likelihood", "right"), ("released piece", "left")):
        table.add_column(column, justify=justify)
    pieces = {p["location"]: p for p in verdict["released_pieces"]}
    for loc in verdict["locations"]:
        piece = pieces.get(loc["name"])
        piece_text = (f"{'+'.join(piece['bodies'])}, {piece['mass_kg']:.4g} kg, "
                      f"{' x '.join(f'{e:.3g}' for e in piece['size_m'][:2])} m, at {piece['release_time_s']:.3f} s"
                      if piece else "-")
        for k, (name, c) in enumerate(loc["criteria"].items()):
            table.add_row(loc["name"] if k == 0 else "", f"{name} ({c['mode']})", _format_value(c["peak"], c["unit"]),
                          _format_allowable(*c["allowable"], c["unit"]), f"{c['margin_of_safety']:+.2f}",
                          "[red]FAIL[/red]" if c["fails"] else "pass",
                          (">= " if loc["released_at_s"] is not None else "") + f"{c['likelihood']:.0%}",
                          piece_text if k == 0 else "")
    console.print(table)
    for p in verdict["released_pieces"]:
        v = p["velocity_relative_to_chaser_lvlh_m_s"]
        console.print(f"released {'+'.join(p['bodies'])}: at end {'inside' if p['inside_net_at_end'] else 'OUTSIDE'} "
                      f"the net, velocity rel. chaser [{v[0]:.3f}, {v[1]:.3f}, {v[2]:.3f}] m/s LVLH, "
                      f"spin {p['spin_rate_rad_s']:.3f} rad/s")
    if verdict["released_pieces"]:
        console.print("likelihoods of released locations are lower bounds: their loads after release are not known")
    console.print("secondary debris: " + ("[red]YES[/red]" if verdict["secondary_debris"] else "none"))


def print_summary(summary: dict, run_dir: Path) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console(width=None if sys.stdout.isatty() else 150)
    ref = summary["paper_reference"]
    table = Table(title=f"{summary['case']}: coupled net impact", show_lines=False)
    table.add_column("quantity")
    table.add_column("this run", justify="right")
    table.add_column("paper (decoupled)", justify="right")
    f = summary["peak_contact_force_N"]
    m = summary["peak_contact_moment_about_debris_com_Nm"]
    table.add_row("peak contact force (N)", f"{f['value']:.4g} at {f['time_s']:.3f} s", f"{ref['peak_contact_force_N']:.3g}")
    table.add_row("peak contact moment (N m)", f"{m['value']:.4g} at {m['time_s']:.3f} s",
                  f"{ref['peak_contact_moment_Nm']:.3g}")
    dv = summary["debris_velocity_change_final_third_mean_lvlh_m_s"]
    est = summary["momentum_exchange_estimate_lvlh_m_s"]
    table.add_row("debris along-track velocity change, mean of last third (m/s)", f"{dv[1]:.4f} (estimate {est[1]:.4f})",
                  f"{ref['debris_along_track_velocity_simulated_m_s']}")
    for name, j in summary["joints"].items():
        mom = j["max_abs_moment_after_transient_Nm"] or j["max_abs_moment_joint_Nm"]
        text = "/".join(f"{v:.3g}" for v in mom)
        if j["kind"] == "revolute":
            text += f"; angle {j['max_abs_angle_rad']:.4f} rad"
        table.add_row(f"{name}: |M| h1/h2/h3 after 0.25 s (N m)", text,
                      f"{ref['hinge_moment_h1_Nm']:.0f}/-/{ref['hinge_moment_h3_Nm']:.0f}" if j["kind"] == "revolute" else "")
    checks = summary["checks"]
    table.add_row("energy balance drift (rel.)", f"{checks['energy_balance_relative_drift']:.2e}", "")
    table.add_row("wall time (s), steps/s", f"{summary['wall_time_s']:.1f}, {summary['steps_per_second']:.0f}", "")
    console.print(table)
    console.print(f"results: {run_dir}")


def _cmd_validate(args) -> int:
    case = load_case(args.case)
    print(f"{args.case}: valid case '{case.name}'")
    return 0


def _cmd_schema(args) -> int:
    print(json.dumps(Case.model_json_schema(), indent=2))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="riskassess", description="Net-capture co-simulation and risk assessment.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="simulate a case and write a run folder")
    run.add_argument("case", help="case file (TOML)")
    run.add_argument("--out", help="output folder (default runs/<case name>)")
    run.add_argument("--json", action="store_true", help="print the run summary as JSON")
    run.set_defaults(func=_cmd_run)
    assess = sub.add_parser("assess", help="simulate a case with weak locations and print the structural verdict")
    assess.add_argument("case", help="case file (TOML) with [[structures.weak_locations]]")
    assess.add_argument("--out", help="output folder (default runs/<case name>)")
    assess.add_argument("--json", action="store_true", help="print the run summary (with the verdict) as JSON")
    assess.set_defaults(func=_cmd_assess)
    val = sub.add_parser("validate", help="check a case file and exit")
    val.add_argument("case")
    val.set_defaults(func=_cmd_validate)
    schema = sub.add_parser("schema", help="print the case-file JSON schema (keys, units, limits)")
    schema.set_defaults(func=_cmd_schema)
    return parser


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except CaseError as exc:
        print(f"error: invalid case\n{exc}", file=sys.stderr)
        return 2
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
