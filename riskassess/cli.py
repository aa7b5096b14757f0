"""``riskassess`` command line: parse, load the case, call the pipeline, print. No physics here."""
from __future__ import annotations

import argparse
import math
import json
import sys
from pathlib import Path

from rich.markup import escape
from rich.text import Text

from multibody.health import SimulationFailed
from riskassess import __version__
from riskassess.cases.impact import Case, CaseError, load_case
from riskassess.cases.inputs import SEARCHES
from riskassess.stages.kinds import KINDS as CASE_KINDS  # kind names only: each kind's schema loads when used
from riskassess.products.outfolder import OutputRefused, default_out, step_done
from riskassess.products.results import MissingData, RunFolder

#: Exit codes (docs/outputs.md): 0 done; 1 a product after a finished run failed; 2 invalid input or
#: refused output; 3 perceive: not observable; 4 approach: constraints not met; 5 the simulation
#: failed its numerical health check; 6 the structural verdict is indeterminate (no evidence).
EXIT_SIMULATION_FAILED = SimulationFailed.exit_code
EXIT_INDETERMINATE = 6


def _cmd_run(args) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from riskassess import api

    case = api.load_case(args.case)  # fail fast on a bad case, before any output folder exists
    _check_work(impact_estimate_of(case.model), args)
    out = Path(args.out) if args.out else default_out(case.name)
    end = case.simulation.end_time
    _announce_compilation(api.needs_compilation(case))
    columns = [TextColumn("[bold]simulating[/bold] {task.fields[t]:.3f} / %.3g s" % end), BarColumn(),
               TimeElapsedColumn(), TimeRemainingColumn()]
    steps = _steps(args)
    with Progress(*columns, disable=args.json or not sys.stderr.isatty(), transient=True) as bar:
        task = bar.add_task("run", total=end, t=0.0)
        result = api.run(case, out, progress=lambda t: bar.update(task, completed=t, t=t),
                         overwrite=args.overwrite, pending=steps, command=args.command)
    if args.json:
        extra = {}
        if result.verdict is not None:
            from riskassess.products.envelope import single_run_probability

            # the key scripts read from assess --json, in both modes: here it holds no number (one run is one draw)
            p = single_run_probability(result.verdict)
            extra = {"structures": result.verdict, "p_secondary_debris": p, "condition": p["condition"]}
        print(json.dumps({**result.summary, **extra}, indent=2))
    else:
        print_summary(result.summary, result.path)
        if result.verdict is not None:
            print_verdict(result.verdict)
    status = _products(result.path, steps, quiet=args.json)
    if result.debris_state == "indeterminate":
        return EXIT_INDETERMINATE  # a script must not read "no verdict" as success
    return status


#: Said on stderr before a run whose force kernels are not in numba's disk cache yet.
COMPILING = ("compiling the simulation kernels, once: about 1-2 min on one core (numba keeps them in its "
             "cache, ~/.cache/adr-riskassess/numba; later runs start at once)")


def _announce_compilation(needed: bool) -> None:
    """The first run after an install (or an edit of the compiled packages) sits at t = 0 while numba compiles,
    100 s measured on the shared 2-core machine at load 2-3: say so (stderr)."""
    if needed:
        print(COMPILING, file=sys.stderr, flush=True)


def impact_estimate_of(case: Case):
    """The expected cost of the case's impact run (steps, wall time, recorded bytes).

    Parameters
    ----------
    case : riskassess.cases.impact.Case
        The validated impact case: simulated time and step (s), net nodes per side (the net has
        that squared plus 4 bullets), target bodies (plus the chaser), output rates (Hz).

    Returns
    -------
    riskassess.stages.estimate.Estimate
    """
    from riskassess.stages.estimate import impact_estimate

    sim = case.simulation
    return impact_estimate(sim.end_time, sim.step, case.net.nodes_per_side ** 2 + 4, len(case.target.bodies) + 1,
                           sim.output_rate, sim.net_output_rate, case.contact.thread_segments)


def _check_work(estimate, args) -> None:
    """Say what the simulation will cost; refuse above the limits unless --force (riskassess.stages.estimate)."""
    from riskassess.stages.estimate import check_budget

    check_budget(estimate, getattr(args, "force", False))
    if not getattr(args, "json", False):
        print(estimate.text(), file=sys.stderr)


def _steps(args) -> list[str]:
    """The product steps a simulation command was asked for, in the order they run."""
    return [step for step, wanted in (("report", args.report), ("vtk", args.vtk)) if wanted]


def _products(run_dir: Path, steps, quiet: bool = False, make=None) -> int:
    """Product steps (report, VTK export) from a finished run folder, each recorded in its manifest
    (:func:`riskassess.products.outfolder.step_done`); a failure keeps the finished results: exit code 1
    (2 when the step's output is refused)."""
    status = 0
    for step in steps:
        try:
            (make or {"report": _make_report, "vtk": _make_vtk}[step])(run_dir, quiet=quiet)
        except OutputRefused as exc:
            step_done(run_dir, step, exc)
            raise
        except Exception as exc:  # any failure of a product: the results stay readable, the manifest says so
            step_done(run_dir, step, exc)
            print(f"error: {type(exc).__name__}: {exc}\n(the results in {run_dir} are kept; retry this step alone "
                  f"with 'riskassess {'report' if step == 'report' else 'export-vtk'} {run_dir}')", file=sys.stderr)
            status = 1
        else:
            step_done(run_dir, step)
    return status


def _progress_bar(label: str, quiet: bool):
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(TextColumn(f"[bold]{label}[/bold] {{task.description}}"), BarColumn(), MofNCompleteColumn(),
                    TimeRemainingColumn(), disable=quiet or not sys.stderr.isatty(), transient=True)


def _make_report(run_dir: Path, pdf: bool = True, quiet: bool = False):
    from riskassess import api

    with _progress_bar("report", quiet) as bar:
        task = bar.add_task("", total=None)
        out = api.report(run_dir, pdf=pdf,
                         progress=lambda k, n, title: bar.update(task, completed=k, total=n, description=title))
    if not quiet:
        missing = [s.title for s in out.sections if s.missing]
        print(f"report: {out.html}" + (f" and {out.pdf} ({out.pdf_pages} pages)" if out.pdf else ""))
        if missing:
            print(f"sections without their data (the report says what is missing): {', '.join(missing)}")
    return out


def _make_vtk(run_dir: Path, out=None, every: int | None = None, quiet: bool = False, overwrite: bool = False,
              max_frames: int | None = None):
    from riskassess.products.vtk_export import export_vtk

    with _progress_bar("VTK export", quiet) as bar:
        task = bar.add_task("frames", total=None)
        result = export_vtk(run_dir, out, every, progress=lambda k, n: bar.update(task, completed=k, total=n),
                            overwrite=overwrite, max_frames=max_frames)
    if not quiet:
        print(f"VTK: {result.pvd} ({result.n_frames} frames, {result.times[0]:g}-{result.times[-1]:g} s); "
              f"open it in ParaView")
    return result


def _cmd_report(args) -> int:
    RunFolder(args.run_dir)   # not a run folder: exit code 2 before anything is written
    return _products(Path(args.run_dir), ["report"],
                     make=lambda run_dir, quiet: _make_report(run_dir, pdf=not args.no_pdf, quiet=quiet))


def _cmd_export_vtk(args) -> int:
    RunFolder(args.run_dir)
    return _products(Path(args.run_dir), ["vtk"], make=lambda run_dir, quiet: _make_vtk(
        run_dir, args.out, args.every, quiet=quiet, overwrite=args.overwrite, max_frames=args.max_frames))


def _cmd_assess(args) -> int:
    from riskassess import api

    case = api.load_case(args.case)
    if case.structures is None:
        raise CaseError(f"{args.case}: structures: missing; 'assess' needs [[structures.weak_locations]] "
                        f"(see docs/case-format.md)")
    if args.monte_carlo:
        return _assess_monte_carlo(args, case)
    if args.uncertain:
        raise ValueError("--uncertain needs --monte-carlo N (the number of samples)")
    return _cmd_run(args)


def _uncertain_inputs(case, given: list[str]) -> list[str]:
    """The case's ``[monte_carlo] uncertain`` inputs, with ``--uncertain`` ones added or replacing the same key."""
    from riskassess.cases.uncertain import parse_uncertain

    by_key = {parse_uncertain(text)[0]: text for text in (case.monte_carlo.uncertain if case.monte_carlo else [])}
    by_key.update({parse_uncertain(text)[0]: text for text in given})
    return list(by_key.values())


def _assess_monte_carlo(args, case) -> int:
    """``assess --monte-carlo N``: N runs of the case with the ``--uncertain`` inputs drawn, on the sweep
    runner and its store (resumable: a re-run finds the finished runs), and P(secondary debris)."""
    from riskassess.products.envelope import debris_probability, probability_statement, utilization_sensitivity
    from riskassess.sweep.store import ResultStore

    uncertain = _uncertain_inputs(case, args.uncertain)
    if not uncertain:
        raise ValueError("--monte-carlo needs at least one uncertain input ([monte_carlo] uncertain in the case, or "
                         "--uncertain KEY=DIST(...)): without one every run would be the same")
    if args.out or args.report or args.vtk:
        raise ValueError("--monte-carlo writes a results store (--store), not a run folder: --out, --report and "
                         "--vtk do not apply (use 'riskassess sweep' options --keep-runs for run folders)")
    store = args.store or str(Path("sweeps") / f"{case.name}-monte-carlo" / "results.sqlite")
    sweep_args = argparse.Namespace(
        case=args.case, vary=[], uncertain=uncertain, monte_carlo=args.monte_carlo, seed=args.seed,
        scheduler=None, workers=args.workers, store=store, retry_failed=False, keep_runs=None,
        confidence=args.confidence, reliability=0.9, no_pdf=True, json=args.json, force=args.force)
    store_path, outcome, env = _sweep(sweep_args)
    with ResultStore.open_readonly(store_path) as results:
        rows = results.rows()
    p = debris_probability(rows, args.confidence)
    statement = probability_statement(p, uncertain)
    if args.json:
        print(json.dumps({"store": str(store_path), "runs": outcome.total, "wall_s": outcome.wall_s,
                          "p_secondary_debris": p, "condition": statement,
                          "utilization_sensitivity": utilization_sensitivity(rows)}, indent=2))
    else:
        print(f"monte carlo: {outcome.total} runs ({outcome.skipped} already in the store, {outcome.done} done now, "
              f"{outcome.failed} failed) in {outcome.wall_s:.1f} s; store {store_path}")
        print(statement)
    return _sweep_exit(env)


def _cmd_perceive(args) -> int:
    from riskassess.api import needs_compilation
    from riskassess.stages.perceive import perceive_case

    case = load_case(args.case)
    _check_work(impact_estimate_of(case), args)
    out = Path(args.out) if args.out else default_out(case.name)
    steps = _steps(args)
    _announce_compilation(needs_compilation(case))
    with _progress_bar("perceive", args.json) as bar:
        task = bar.add_task("", total=None)

        def progress(stage, done, total):
            bar.update(task, description=stage, completed=done, total=total)

        answer = perceive_case(args.case, out, progress=progress, case=case, overwrite=args.overwrite, pending=steps)
    if args.json:
        print(json.dumps(answer, indent=2))
    else:
        print_perception(answer, out)
    status = _products(out, steps, quiet=args.json)
    return 3 if answer["not_observable"] and status == 0 else status


def _cmd_tow(args) -> int:
    from riskassess.cases.impact import load_model
    from riskassess.stages.tow import tow_case
    from riskassess.cases.towing import TowingCase

    case = load_model(args.case, TowingCase)
    _check_work(tow_estimate_of(case), args)
    out = Path(args.out) if args.out else default_out(case.name)
    summary = tow_case(args.case, out, case=case, overwrite=args.overwrite)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{case.name}: towed {summary['simulated_s']:g} s with thrust '{summary['thrust_kind']}', "
              f"debris spin {math.radians(summary['spin_rate_deg_s']):.4f} rad/s; main tether peak "
              f"{summary['main_tether_peak_tension_N']:.1f} N, final {summary['main_tether_final_tension_N']:.1f} N, "
              f"slack while thrusting {summary['main_tether_slack_time_while_thrusting_s']:.2f} s; "
              f"{summary['wall_time_s']:.2f} s wall\nresults: {out}")
    return 0


def tow_estimate_of(case):
    """The expected cost of the case's tow (steps, wall time, recorded bytes).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The validated towing case: simulated time (s) and step (s); a full-net model adds the net's
        step, nodes per side and sub-steps.

    Returns
    -------
    riskassess.stages.estimate.Estimate
    """
    from riskassess.stages.estimate import tow_estimate

    sim = case.simulation
    if sim.model == "full-net":
        net = case.full_net
        return tow_estimate(sim.end_time, net.step, net.nodes_per_side ** 2 + 4, net.substeps)
    return tow_estimate(sim.end_time - sim.start_time, sim.step)


def _cmd_identify(args) -> int:
    from riskassess.cases.impact import load_model
    from riskassess.stages.identify import benchmark_case
    from riskassess.cases.towing import TowingCase

    case = load_model(args.case, TowingCase)
    choice = {k: v for k, v in (("cost", args.cost), ("searches", args.optimizers)) if v}
    case = case.model_copy(update={"identification": case.identification.model_copy(update=choice)})
    if not args.benchmark:
        from riskassess.stages.identify_fullnet import identify_full_net

        out = Path(args.out) if args.out else default_out(case.name, "_identify_fullnet")
        answer = identify_full_net(args.case, out, case, overwrite=args.overwrite)
    else:
        out = Path(args.out) if args.out else default_out(case.name, "_identify")
        answer = benchmark_case(args.case, out, case=case, overwrite=args.overwrite)
    if args.json:
        print(json.dumps(answer, indent=2))
        return 0
    for name, run in answer["runs"].items():
        valid = run.get("validation_totals")
        against = (f"max relative error {max(run['relative_error']):.2e}" if args.benchmark else
                   f"validation f1 {valid['f1']:.4g}, f2 {valid['f2']:.4g}" if valid else "no validation run held")
        print(f"{name:12s} s = {', '.join(f'{x:.6f}' for x in run['s'])}  cost {answer['cost_function']} {run['cost']:.4g}  "
              f"{against}  {run['evaluations']} evaluations, {run['wall_s']:.0f} s")
    if args.benchmark:
        print(f"{'truth':12s} s = {', '.join(f'{x:.6f}' for x in answer['truth'])}")
    for why in answer.get("excluded_runs", []):
        print(f"left out: {why['rate_deg_s']:g} deg/s: {why['reason']}")
    print(f"results: {out}")
    return 0


def print_perception(answer: dict, out: Path, console=None) -> None:
    """The perception estimates as a table on the terminal, and where the results are.

    Parameters
    ----------
    answer : dict
        The perception answer (``perception.json``).
    out : Path
        The output folder, printed.
    console : rich.console.Console, optional
        Where to print; default the terminal.
    """
    from riskassess.products.tables import perception_rows

    console = console or _console()
    _print_table(console, f"{escape(answer['case'])}: debris mass and inertia from LiDAR and the net collision",
                 ("quantity", "estimate", "1 sigma", "error vs truth"), perception_rows(answer),
                 {"estimate": "right", "1 sigma": "right", "error vs truth": "right"})
    for key in ("model_mismatch", "model_mass_mismatch"):
        if answer.get(key):
            console.print(f"[yellow]wrong model[/yellow]: {escape(str(answer[key]))}")
    if answer["not_observable"]:
        console.print(f"[red]not observable[/red]: {escape(str(answer['not_observable']))}")
    console.print(f"results: {escape(str(out))}")


def _cells(row) -> list[Text]:
    """Every string cell shown literally (names are user text); a rich ``Text`` keeps its style."""
    return [cell if isinstance(cell, Text) else Text(str(cell)) for cell in row]


def _table(title: str, columns, rows, justify=None):
    """A rich table; ``title`` is markup (user text in it escaped by the caller)."""
    from rich.table import Table

    table = Table(title=title)
    for column in columns:
        table.add_column(escape(column), justify=(justify or {}).get(column, "left"), no_wrap=True)
    for row in rows:
        table.add_row(*_cells(row))
    return table


def _print_table(console, title: str, columns, rows, justify=None) -> None:
    """A table when it fits the console without wrapping a cell; otherwise the rows stacked, one
    block per row: its first cell, then 'column: value' lines (empty cells left out; a row that
    continues the one above, with an empty first cell, repeats that cell). Never a cut cell."""
    from rich.measure import Measurement

    table = _table(title, columns, rows, justify)
    # its natural width, measured as if the console were unbounded (console.measure clamps to it)
    if Measurement.get(console, console.options.update_width(1_000_000), table).maximum <= console.width:
        console.print(table)
        return
    console.print(title, style="italic")
    head = Text("")
    for row in rows:
        cells = _cells(row)
        head = cells[0] if cells[0].plain else head
        console.print(Text.assemble(head, style="bold"), overflow="fold")
        for column, cell in zip(columns[1:], cells[1:]):
            if cell.plain:
                console.print(Text.assemble(f"  {column}: ", cell), overflow="fold")


def _console():
    """The terminal: markup only where the CLI writes it, every user string passed through
    ``escape`` (``x[/red]`` in a name used to crash, ``[link=...]`` was followed); no emoji codes."""
    from rich.console import Console

    return Console(width=None if sys.stdout.isatty() else 150, emoji=False)


def print_verdict(verdict: dict, console=None) -> None:
    """The verdict table: location, criterion, peak demand, allowable, margin, fails?, released piece.

    Parameters
    ----------
    verdict : dict
        The structural verdict (``structures.json``).
    console : rich.console.Console, optional
        Where to print; default the terminal.
    """
    from riskassess.products.tables import STATE_TEXT, VERDICT_COLUMNS, debris_line, piece_fate, verdict_rows

    console = console or _console()
    marked = {"fails": Text("FAIL", style="red"), "indeterminate": Text("indeterminate", style="yellow")}
    rows = [[marked.get(r["state"], STATE_TEXT[r["state"]]) if c == "fails?" else r[c] for c in VERDICT_COLUMNS]
            for r in verdict_rows(verdict)]
    right = {c: "right" for c in ("max demand", "at", "allowable", "margin", "likelihood")}
    _print_table(console, f"structural verdict (loads after {verdict['skip_initial_s']:g} s; range allowables "
                          f"decide at their '{escape(str(verdict['release_policy']))}' value)", VERDICT_COLUMNS, rows,
                 {**right, "fails?": "center"})
    for p in verdict["released_pieces"]:
        console.print(f"released {escape('+'.join(p['bodies']))}: {escape(piece_fate(p))}")
    if verdict["released_pieces"]:
        console.print("likelihoods of released locations are lower bounds: their loads after release are not known")
    for loc in verdict["locations"]:
        if loc.get("condition"):            # folders written before the condition sentence lack it
            console.print(escape(loc["condition"]), overflow="fold")
    line = escape(debris_line(verdict))
    colour = {"debris": "red", "indeterminate": "yellow"}.get(verdict.get("debris_state"))
    console.print(f"[{colour}]{line}[/{colour}]" if colour else line)


def print_summary(summary: dict, run_dir: Path, console=None) -> None:
    """The run summary as a table (this run against the seed paper), and where the results are.

    Parameters
    ----------
    summary : dict
        The run summary (``summary.json``).
    run_dir : Path
        The run folder, printed.
    console : rich.console.Console, optional
        Where to print; default the terminal.
    """
    from riskassess.products.tables import summary_rows

    console = console or _console()
    _print_table(console, f"{escape(summary['case'])}: coupled net impact", ("quantity", "this run", "paper (decoupled)"),
                 summary_rows(summary), {"this run": "right", "paper (decoupled)": "right"})
    console.print(f"results: {escape(str(run_dir))}")


def _cmd_diagnose(args) -> int:
    from riskassess.stages.diagnose import diagnose_case

    noise = {}
    for item in args.noise:
        name, _, sigma = item.partition("=")
        try:
            noise[name.strip()] = float(sigma)
        except ValueError:
            raise ValueError(f"--noise {item}: expected CHANNEL=SIGMA with SIGMA a number (channel units)") from None
    with _progress_bar("diagnose", args.json) as bar:
        task = bar.add_task("", total=None)
        answer = diagnose_case(args.case, args.measured, args.out, noise, progress=lambda stage, done, total:
                               bar.update(task, description=stage, completed=done, total=total),
                               overwrite=args.overwrite)
    if args.json:
        print(json.dumps(answer, indent=2, default=float))
    elif answer["scenario"] == "impact":
        _print_impact_diagnosis(answer, args.out)
    else:
        confidence = "" if answer["confidence"] is None else f" (confidence {answer['confidence']:.3f})"
        print(f"{answer['case']}: cause = {answer['cause']}{confidence}\n{answer['statement']}")
        if len(answer["selection_steps"]) > 1:
            for k, step in enumerate(answer["selection_steps"], 1):
                print(f"  step {k}: + {step['added']}: BIC lower by {step['delta_bic_over_previous']:.1f}, residual "
                      f"{step['train_rms_sigma']:.2f} / {step['holdout_rms_sigma']:.2f} sigma (training / held-out)")
        for name, p in answer["parameters"].items():
            print(f"  {name} = {p['value']:.4g} +- {p['std']:.2g} {p['unit']}")
        print("held-out RMSE before -> after (gain %): " + ", ".join(
            f"{c} {answer['rmse_before'][c]:.3g} -> {answer['rmse_after'][c]:.3g} ({answer['gain_percent'][c]:.0f})"
            for c in answer["rmse_before"]))
        if answer["extended_case"]:
            print(f"extended case: {answer['extended_case']}")
        for key, label in (("unknown", "unknown channels (not used)"), ("not_predicted", "channels the scenario "
                                                                                           "does not predict")):
            if answer["channels"][key]:
                print(f"{label}: {', '.join(answer['channels'][key])}")
        print(f"results: {args.out or default_out(answer['case'], '-diagnosis')}")
    return 0


def _print_impact_diagnosis(answer: dict, out) -> None:
    """The impact scenario's answer as text: cause, why, the fitted parameter and every candidate."""
    confidence = "" if answer["confidence"] is None else f" (confidence {answer['confidence']:.3f})"
    print(f"{answer['case']}: cause = {answer['cause']}{confidence}\n{answer['statement']}")
    for name, p in answer["parameters"].items():
        print(f"  {name} = {p['value']:.4g} +- {p['std']:.2g} {p['unit']}")
    print("candidates (delta BIC over the nominal model, fitted value, training / held-out RMS in sigmas):")
    for row in answer["candidates"]:
        (name, p), = row["parameters"].items()
        print(f"  {row['id']:<24s} {row['delta_bic']:10.1f}  {name} = {p['value']:.4g} {p['unit']}  "
              f"{row['train_rms_sigma']:.2f} / {row['holdout_rms_sigma']:.2f}")
    print(f"nominal: {answer['nominal']['train_rms_sigma']:.2f} / {answer['nominal']['holdout_rms_sigma']:.2f} sigma; "
          f"{answer['simulations']} simulations in {answer['wall_s']:.0f} s")
    if answer["extended_case"]:
        print(f"extended case: {answer['extended_case']}")
    print(f"results: {out or default_out(answer['case'], '-diagnosis')}")


def _cmd_approach(args) -> int:
    from riskassess.stages.approach import approach_case
    from riskassess.cases.approach import ApproachCase
    from riskassess.cases.impact import load_model

    case = load_model(args.case, ApproachCase)
    out = Path(args.out) if args.out else default_out(case.name)
    answer = approach_case(args.case, out, replay=args.replay, case=case, overwrite=args.overwrite)
    if args.json:
        print(json.dumps(answer, indent=2))
    else:
        points = answer["constraints_resimulated"]
        print(f"{answer['case']}: {answer['objective']} -> solver {answer['solver_status']}, t_f "
              f"{answer['final_time']:.4f} s, fuel {answer['fuel_kg']:.4f} kg, solve {answer['solve_s']:.2f} s; "
              f"keep-out margin {points['keep_out_margin_m']:.4f} m, end miss {points['final_mouth_miss_m']:.4f} m "
              f"(re-simulated); constraints {'satisfied' if answer['constraints_satisfied'] else 'VIOLATED'}")
        print(f"results: {out}")
    return 0 if answer["constraints_satisfied"] else 4


def _cmd_sweep(args) -> int:
    from riskassess.products.envelope import envelope_statement
    from riskassess.sweep.products import products_dir

    store_path, outcome, env = _sweep(args)
    if args.json:
        print(json.dumps({"store": str(store_path), "total": outcome.total, "skipped": outcome.skipped,
                          "done": outcome.done, "failed": outcome.failed, "indeterminate": outcome.indeterminate,
                          "wall_s": outcome.wall_s, "envelope": env, "statement": envelope_statement(env)}, indent=2))
    else:
        print(f"sweep: {outcome.total} runs ({outcome.skipped} already in the store, {outcome.done} done now "
              f"({outcome.indeterminate} of them indeterminate), {outcome.failed} failed) in {outcome.wall_s:.1f} s; "
              f"store {store_path}")
        print(envelope_statement(env))
        print(f"report: {products_dir(store_path) / 'report.html'}")
    return _sweep_exit(env)


def _sweep_exit(env: dict) -> int:
    """Failed, indeterminate or pending runs: the envelope holds runs it cannot count as safe."""
    from riskassess.sweep.runner import UNKNOWN_RUNS_EXIT

    return UNKNOWN_RUNS_EXIT if env["failed_runs"] + env["indeterminate_runs"] + env["pending_runs"] else 0


def _sweep(args):
    """Run the sweep of ``args`` (every option checked before any work) into its store and write its
    products; returns (store path, outcome, envelope)."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from riskassess.sweep.cluster_log import CLUSTER_LOG
    from riskassess.sweep.products import (PRODUCTS, check_products, check_products_at, products_dir,
                                           write_sweep_products)
    from riskassess.sweep.runner import run_sweep, validate_runs
    from riskassess.cases.uncertain import parse_uncertain
    from riskassess.sweep.spec import check_options, check_sweep, parse_vary, run_specs
    from riskassess.sweep.store import ResultStore, default_store_path

    # every option checked before any work
    check_options(args.workers, args.confidence, args.reliability)
    case = load_case(args.case)  # a bad base case fails before any worker starts
    vary, uncertain = [parse_vary(v) for v in args.vary], [parse_uncertain(u) for u in args.uncertain]
    check_sweep(vary, uncertain, args.monte_carlo, args.seed, force=args.force)
    specs = run_specs(vary, uncertain, args.monte_carlo, args.seed)
    validated = validate_runs(args.case, Path(args.case).read_text(), specs)  # before the store exists
    if not args.json:
        print(f"sweep: {validated}", file=sys.stderr)
    store_path = Path(args.store) if args.store else default_store_path(case.name)
    products = PRODUCTS[:2] if args.no_pdf else PRODUCTS
    if not store_path.exists():
        check_products_at(store_path, {}, products)   # a new store owns no file yet: refuse before making it
    store = ResultStore(store_path)
    arguments = [f"--vary {v}" for v in args.vary] + [f"--uncertain {u}" for u in args.uncertain] + (
        [f"--monte-carlo {args.monte_carlo}", f"--seed {args.seed}"] if args.uncertain else [])
    columns = [TextColumn("[bold]sweep[/bold] done {task.fields[done]}, failed {task.fields[failed]}, "
                          "remaining {task.fields[remaining]}"), BarColumn(), TimeElapsedColumn(), TextColumn("ETA"),
               TimeRemainingColumn()]
    try:
        check_products(store, products)   # no run before a refusal
        with Progress(*columns, disable=args.json or not sys.stderr.isatty()) as bar:
            task = bar.add_task("sweep", total=None, done=0, failed=0, remaining="?")

            def progress(done, failed, remaining):
                bar.update(task, completed=done + failed, total=done + failed + remaining, done=done, failed=failed,
                           remaining=remaining)

            outcome = run_sweep(args.case, specs, store, {"arguments": arguments, "created": _now()},
                                scheduler=args.scheduler, n_workers=args.workers, retry_failed=args.retry_failed,
                                keep_runs=args.keep_runs, progress=progress, validate=False,
                                log_path=products_dir(store.path) / CLUSTER_LOG)
        env = write_sweep_products(store, args.confidence, args.reliability, pdf=not args.no_pdf)
    finally:
        store.close()   # releases the writer lock
    return store.path, outcome, env


def _now() -> str:
    import datetime

    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def _cmd_sweep_status(args) -> int:
    """Read-only: SQLite mode=ro, no lock, nothing written to the store or beside it."""
    from riskassess.products.envelope import run_status
    from riskassess.sweep.store import ResultStore

    with ResultStore.open_readonly(args.store) as store:
        rows = store.rows()
    for r in rows:
        values = " ".join(f"{k}={v:.6g}" for k, v in r["overrides"].items())
        line = f"{r['run_id']} {r['state']} {values}"
        status = run_status(r)
        if status in ("debris", "no_debris", "indeterminate"):
            line += " secondary_debris=" + {"debris": "yes", "no_debris": "no"}.get(status, status)
        if r["state"] == "failed":
            line += f" error={r['error_kind']}: {r['error'].splitlines()[0] if r['error'] else ''}"
        print(line)
    return 0


def _cmd_validate(args) -> int:
    from riskassess.stages.kinds import load_any_case

    kind, case = load_any_case(args.case)
    print(f"{args.case}: valid {kind} case '{case.name}'")
    return 0


def _cmd_schema(args) -> int:
    from riskassess.stages.kinds import case_schema

    print(json.dumps(case_schema(args.kind), indent=2))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="riskassess", description="Net-capture co-simulation and risk assessment.")
    parser.add_argument("--version", action="version", version=f"riskassess {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    _simulation_command(sub, "run", _cmd_run, "simulate a case and write a run folder", "case file (TOML)",
                        "print the run summary as JSON")
    assess = _simulation_command(sub, "assess", _cmd_assess,
                                 "simulate a case with weak locations and print the structural verdict",
                                 "case file (TOML) with [[structures.weak_locations]]",
                                 "print the run summary (with the verdict) as JSON")
    assess.add_argument("--monte-carlo", type=int, default=0, metavar="N",
                        help="P(secondary debris) from N runs with the --uncertain inputs drawn (on the sweep runner)")
    assess.add_argument("--uncertain", action="append", default=[], metavar="KEY=DIST(...)",
                        help="an uncertain input, as for 'sweep' (e.g. contact.mu_kinetic=uniform(0.1,0.3))")
    assess.add_argument("--seed", type=int, default=0, help="random seed of the Monte Carlo draws (default 0)")
    assess.add_argument("--workers", type=int, default=2, help="Monte Carlo worker processes (default 2)")
    assess.add_argument("--store", help="Monte Carlo results store (default sweeps/<case name>-monte-carlo/"
                                        "results.sqlite); a re-run resumes it")
    assess.add_argument("--confidence", type=float, default=0.95,
                        help="confidence of the interval of P(secondary debris) (default 0.95)")
    _simulation_command(sub, "perceive", _cmd_perceive,
                        "track the tumbling debris by LiDAR, simulate the net collision, estimate mass and inertia",
                        "case file (TOML) with [perception] and [chaser]",
                        "print the estimates (mass_estimate, inertia_estimate, errors, timings) as JSON")
    tow = _case_command(sub, "tow", _cmd_tow,
                        "lower-order towing run of a towing case (chaser, tethers, net-wrapped debris)",
                        "towing case file (TOML), e.g. cases/zenit2_towing.toml", "print the summary as JSON")
    tow.add_argument("--force", action="store_true", help="run even when the estimated work is above the limit")
    diagnose = sub.add_parser("diagnose", help="compare a simulated scenario with measured data, name the missing "
                                               "effect, fit it and report the prediction gain")
    diagnose.add_argument("case", help="diagnosis case file (TOML, kind = \"diagnosis\", scenario tumbling_rigid, "
                                          "hinged_appendage, towing or impact)")
    diagnose.add_argument("--measured", required=True, help="measured data (CSV: time, then named channels, SI)")
    diagnose.add_argument("--out", help="output folder (default runs/<case name>-diagnosis)")
    diagnose.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)
    diagnose.add_argument("--json", action="store_true", help="print the diagnosis (cause, confidence, parameters, "
                                                              "rmse_before, rmse_after, gain_percent) as JSON")
    diagnose.add_argument("--noise", action="append", default=[], metavar="CHANNEL=SIGMA",
                          help="1-sigma noise of a channel (its SI unit) instead of the estimate from the data")
    diagnose.set_defaults(func=_cmd_diagnose)
    ident = _case_command(sub, "identify", _cmd_identify,
                          "identify the sub-tether parameters of the lower-order towing model",
                          "towing case file (TOML) with [identification]",
                          "print s, cost, optimizer, wall_s and every run as JSON", "runs/<case name>_identify")
    ident.add_argument("--benchmark", action="store_true", help="Sec. 4.3 benchmark: data from the model itself "
                       "with identification.benchmark_truth at the training rates")
    ident.add_argument("--optimizers", nargs="+", choices=SEARCHES, help="optimizers to run, in order "
                       "(default identification.searches); 'pso' is followed by the pattern-search polish")
    ident.add_argument("--cost", choices=["f1", "f1_inertial", "f2"], help="cost function (default "
                       "identification.cost): f1 weighted RMSE of r_D/C and both angular velocities (eq. 18; rates in "
                       "body components), f1_inertial the same with the rates in inertial components, f2 main-tether "
                       "tension RMSE (eq. 20)")
    approach = _case_command(sub, "approach", _cmd_approach,
                             "optimal approach of the net carried by two maneuverable units (direct collocation, "
                             "IPOPT); exit code 4 when not solved or a constraint fails",
                             "approach case file (TOML), e.g. cases/approach_mu_min_time.toml",
                             "print final_time, fuel_kg, constraints_satisfied, solve_s and the checks as JSON")
    approach.add_argument("--replay", action="store_true", help="also replay the path with the 3-D Exudyn net")
    report = sub.add_parser("report", help="write report.html (self-contained) and report.pdf into a run folder")
    report.add_argument("run_dir", help="run folder written by 'riskassess run'")
    report.add_argument("--no-pdf", action="store_true", help="HTML only")
    report.set_defaults(func=_cmd_report)
    vtk = sub.add_parser("export-vtk", help="write the impact as VTK files and a ParaView collection (impact.pvd)")
    vtk.add_argument("run_dir", help="run folder written by 'riskassess run'")
    vtk.add_argument("--out", help="output folder (default RUN_DIR/vtk): new, empty, or this run's earlier export "
                                   "with --overwrite")
    vtk.add_argument("--overwrite", action="store_true", help="replace this run's earlier export in that folder "
                                                              "(only the files its manifest lists)")
    frames = vtk.add_mutually_exclusive_group()
    frames.add_argument("--every", type=int, help="export every N-th net snapshot (default: evenly strided to stay "
                                                  "within 20 MB)")
    frames.add_argument("--max-frames", type=int, help="export at most N net snapshots, evenly strided")
    vtk.set_defaults(func=_cmd_export_vtk)
    sweep = sub.add_parser("sweep", help="run a grid / Monte Carlo of cases on Dask; results survive interruption; "
                           "exit code 5 when runs failed, are indeterminate or pending")
    sweep.add_argument("case", help="base case file (TOML)")
    sweep.add_argument("--vary", action="append", default=[], metavar="KEY=START:STOP:N",
                       help="grid of a case key, N values with both ends (repeat for a cartesian grid)")
    sweep.add_argument("--monte-carlo", type=int, default=0, metavar="N", help="samples of the uncertain keys "
                       "at every grid point")
    sweep.add_argument("--uncertain", action="append", default=[], metavar="KEY=DIST(...)",
                       help="uniform(low,high), normal(mean,std), lognormal(median,sigma_log), "
                            "triangular(low,mode,high)")
    sweep.add_argument("--seed", type=int, default=0, help="random seed of the Monte Carlo draws (default 0)")
    sweep.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster here)")
    sweep.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    sweep.add_argument("--store", help="results store (SQLite; default sweeps/<case name>/results.sqlite); the "
                       "report goes beside a store named results.sqlite, else into STORE_STEM.products/")
    sweep.add_argument("--retry-failed", action="store_true", help="also re-run runs that failed in the run itself")
    sweep.add_argument("--keep-runs", metavar="DIR", help="keep every run folder under DIR/<run id>")
    sweep.add_argument("--confidence", type=float, default=0.95, help="confidence of the safe limit (default 0.95)")
    sweep.add_argument("--reliability", type=float, default=0.9,
                       help="required P(no secondary debris) of the safe limit (default 0.9)")
    sweep.add_argument("--no-pdf", action="store_true", help="HTML report only")
    sweep.add_argument("--json", action="store_true", help="print outcome and envelope as JSON")
    sweep.add_argument("--force", action="store_true", help="allow more than 100000 runs (at most 10 million)")
    sweep.set_defaults(func=_cmd_sweep)
    status = sub.add_parser("sweep-status", help="list every run of a results store: id, state, inputs "
                            "(opens the store read-only)")
    status.add_argument("store", help="results store written by 'riskassess sweep'")
    status.set_defaults(func=_cmd_sweep_status)
    val = sub.add_parser("validate", help="check a case file and exit")
    val.add_argument("case")
    val.set_defaults(func=_cmd_validate)
    schema = sub.add_parser("schema", help="print the JSON schema of a kind of case file (keys, units, limits)")
    schema.add_argument("--kind", choices=list(CASE_KINDS), default="impact",
                        help="case kind: impact (run, assess, perceive, sweep; the default), towing (tow, identify), "
                             "diagnosis (diagnose), approach")
    schema.set_defaults(func=_cmd_schema)
    return parser


OVERWRITE_HELP = ("replace this case's earlier output in --out: only the files its manifest lists are removed "
                  "(see docs/outputs.md)")


def _case_command(sub, name, func, help_text, case_help, json_help, out_default="runs/<case name>"):
    """A command that runs a stage on one case file into an output folder; returns its parser."""
    parser = sub.add_parser(name, help=help_text)
    parser.add_argument("case", help=case_help)
    parser.add_argument("--out", help=f"output folder (default {out_default}); new, empty, or this case's "
                                      f"earlier output with --overwrite")
    parser.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)
    parser.add_argument("--json", action="store_true", help=json_help)
    parser.set_defaults(func=func)
    return parser


def _simulation_command(sub, name, func, help_text, case_help, json_help):
    """A command that simulates a case into a run folder (run, assess, perceive); returns its parser."""
    parser = _case_command(sub, name, func, help_text, case_help, json_help)
    parser.add_argument("--report", action="store_true", help="also write report.html and report.pdf")
    parser.add_argument("--vtk", action="store_true", help="also export VTK files (RUN_DIR/vtk/impact.pvd)")
    parser.add_argument("--force", action="store_true", help="run even when the estimated work is above the limit "
                                                             "(1 h wall or 8 GB recorded; docs/outputs.md)")
    return parser


def main(argv=None) -> int:
    """Run the ``riskassess`` command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name; default ``sys.argv[1:]``.

    Returns
    -------
    int
        Exit code: 0 done, 2 bad input (invalid case, bad option, refused output folder, missing
        data), :data:`EXIT_SIMULATION_FAILED` when the simulation failed its health checks, or the
        command's own code (e.g. :data:`EXIT_INDETERMINATE`).
    """
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except CaseError as exc:
        print(f"error: invalid case\n{exc}", file=sys.stderr)
        return 2
    except SimulationFailed as exc:
        if getattr(args, "json", False):
            print(json.dumps({"status": "failed", "debris_state": "indeterminate", "secondary_debris": None,
                              "failure": {"time_s": exc.time, "quantity": exc.quantity, "cause": exc.cause}},
                             indent=2))
        print(f"error: {exc}\nThe run is recorded as failed; secondary debris: INDETERMINATE (nothing after "
              f"the failure was simulated, so nothing can be called safe).", file=sys.stderr)
        return EXIT_SIMULATION_FAILED
    except (ValueError, MissingData) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
