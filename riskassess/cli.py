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


def _table(title: str, columns, rows, justify=None):
    from rich.table import Table

    table = Table(title=title)
    for k, column in enumerate(columns):
        table.add_column(column, justify=(justify or {}).get(column, "left"))
    for row in rows:
        table.add_row(*row)
    return table


def _console():
    from rich.console import Console

    return Console(width=None if sys.stdout.isatty() else 150)


def print_verdict(verdict: dict) -> None:
    """The verdict table: location, criterion, peak demand, allowable, margin, fails?, released piece."""
    from riskassess.tables import VERDICT_COLUMNS, piece_fate, verdict_rows

    console = _console()
    rows = [[("[red]FAIL[/red]" if r["fails"] else "pass") if c == "fails?" else r[c] for c in VERDICT_COLUMNS]
            for r in verdict_rows(verdict)]
    right = {c: "right" for c in ("max demand", "at", "allowable", "margin", "likelihood")}
    console.print(_table(f"structural verdict (loads after {verdict['skip_initial_s']:g} s; range allowables "
                         f"decide at their '{verdict['release_policy']}' value)", VERDICT_COLUMNS, rows,
                         {**right, "fails?": "center"}))
    for p in verdict["released_pieces"]:
        console.print(f"released {'+'.join(p['bodies'])}: {piece_fate(p)}")
    if verdict["released_pieces"]:
        console.print("likelihoods of released locations are lower bounds: their loads after release are not known")
    console.print("secondary debris: " + ("[red]YES[/red]" if verdict["secondary_debris"] else "none"))


def print_summary(summary: dict, run_dir: Path) -> None:
    from riskassess.tables import summary_rows

    console = _console()
    console.print(_table(f"{summary['case']}: coupled net impact", ("quantity", "this run", "paper (decoupled)"),
                         summary_rows(summary), {"this run": "right", "paper (decoupled)": "right"}))
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
