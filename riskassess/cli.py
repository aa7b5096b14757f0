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
        print(json.dumps(result.summary, indent=2))
    else:
        print_summary(result.summary, result.run_dir)
    return 0


def print_summary(summary: dict, run_dir: Path) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console()
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
