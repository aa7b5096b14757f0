"""Sec. 4.4 of Boonrath, Singh & Botta 2024 per optimizer and start: sub-tether identification against
full-net runs with PSO (+ pattern-search polish), the pattern search and MADS, from the wrapped start and
from the capture start, each identified model scored on the training and the unseen validation runs
(f1, f2 per run, eqs. 18, 20), printed beside the paper's Tables 7, 8 and 10.

    python bench/bench_fullnet_identify.py --out DIR [--case cases/zenit2_towing.toml]
        [--starts wrapped capture] [--training N] [--validation N] [--end T]
        [--optimizers pso pattern mads] [--cost f1 f1_inertial f2] [--mads-starts s0 table6] [--workers N]
        [--table-only] [--rescore] [--score LABEL S1 S2 S3 S4]

The full-net runs (the first N training and validation rates of Table 3, to T) are cached in
``DIR/<start>/fullnet/rate_<deg_s>_end_<T>[_capture].npz``, the same files ``riskassess identify`` writes:
copy an identify folder's ``fullnet/*.npz`` there to reuse them. MADS runs from the case's s0 and/or from each
Table 6 initial guess (MADS 1-5, as the paper's Sec. 4.4); the pattern search from s0; PSO with the case's seed,
then the polish. Every answer is kept in ``DIR/results.json`` as soon as it is found (a re-run skips those
done, for the same held runs and settings); ``--table-only`` prints the tables from it. As ``riskassess identify``
does, a run whose debris was not held (a failed capture, :func:`riskassess.stages.identify_fullnet.not_held`) is
left out of training and validation and named in each answer's ``excluded_runs``. The second table gives f1
per run with the angular velocities compared in body components (the cost ``f1``), in inertial components
(``f1_inertial``: runs cached since 2026-11-27 store the attitudes; '-' for older runs) and roll-blind. ``--score LABEL S1 S2 S3 S4`` scores a given s (an
answer found on other runs or with older code) on these runs, without a search. CPU time counts this
process and its worker processes (the machine may be shared; wall times are printed with the load average).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.products import results
from riskassess.stages.identify import has_attitudes, run_optimizers
from riskassess.stages.identify_fullnet import (_entry, _totals, comparison_rows, full_net_runs, held_runs,
                                                lower_order_case)
sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_identify import TABLE6_INITIAL_GUESSES  # noqa: E402
from bench_omega_frames import attitude_from_rates  # noqa: E402

#: Boonrath et al. 2024 Sec. 4.4 (10 training + 10 validation runs, 275 s of towing): per cost, per optimizer
#: run, (training cost, validation cost): Tables 7 and 10 (f1), 8 and 10 (f2).
PAPER = {"f1": {"MADS 1": (55.6119, 50.2055), "MADS 2": (55.5872, 50.2248), "MADS 3": (55.5879, 49.9488),
                "MADS 4": (55.6074, 50.2130), "MADS 5": (55.5998, 50.2141), "PSO 1": (55.5847, 50.1917),
                "PSO 2": (55.5875, 49.9409), "PSO 3": (55.5875, 49.9430)},
         "f2": {"MADS 1": (1226.48, 1301.75), "MADS 2": (1226.81, 1296.49), "MADS 3": (1226.73, 1300.29),
                "MADS 4": (1226.35, 1301.70), "MADS 5": (1227.10, 1299.75), "PSO 1": (1226.18, 1299.46),
                "PSO 2": (1226.42, 1302.19), "PSO 3": (1226.17, 1299.21)}}
PAPER_RUNS = 10


def reconstruct_attitudes(data: list[dict], dt: float) -> list[float]:
    """Give every run cached without attitudes (before 2026-11-27) attitudes integrated from its start attitude and
    sampled body rates (:func:`bench_omega_frames.attitude_from_rates`); returns their rates (deg/s)."""
    rebuilt = []
    for run in data:
        if has_attitudes(run) or run.get("start") is None:
            continue
        for b, key in enumerate(("chaser", "debris")):
            run[f"{key}_to_inertial"] = attitude_from_rates(run["start"]["body_to_inertial"][b], run[f"{key}_omega_body"], dt)
        rebuilt.append(float(run["rate_deg_s"]))
    return rebuilt


def cpu_seconds() -> float:
    """CPU time of this process and of its finished worker processes (s)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def start_case(case: TowingCase, start: str, training: int, validation: int, end: float) -> TowingCase:
    """The case with the full-net start and the identification's run counts and end time."""
    full_net = case.full_net.model_copy(update=dict(start=start, identification_training_runs=training,
                                                   identification_validation_runs=validation,
                                                   identification_end_time=end))
    return case.model_copy(update=dict(full_net=full_net))


def searches(optimizers, mads_starts, s0):
    """(label, optimizer name, initial guess) of every search: PSO once, the pattern search from s0, MADS from
    s0 and/or each Table 6 guess."""
    out = []
    for name in optimizers:
        if name == "mads":
            if "s0" in mads_starts:
                out.append(("mads s0", "mads", list(s0)))
            if "table6" in mads_starts:
                out += [(f"mads {k + 1}", "mads", list(g)) for k, g in enumerate(TABLE6_INITIAL_GUESSES)]
        else:
            out.append((name, name, list(s0)))
    return out


def run_one(case: TowingCase, train, valid, label, name, guess, cost, workers, end) -> dict:
    """One search on the (held) training runs and the identified model's scores on the training and the
    (held) validation runs; returns the entries per reported optimizer ('pso' gives 'pso' and 'pso+pattern';
    ``wall_s`` is each one's own, ``cpu_s`` the whole search's)."""
    ident = case.identification.model_copy(update=dict(cost=cost, initial_guess=guess, workers=workers))
    lower = lower_order_case(case.model_copy(update=dict(identification=ident)), train[0])
    cpu, wall, load = cpu_seconds(), time.perf_counter(), os.getloadavg()[0]
    found = run_optimizers(lower, train, (name,), end_time=end, workers=workers)
    cpu, wall = cpu_seconds() - cpu, time.perf_counter() - wall
    out = {}
    for reported, answer in found.items():
        entry = _entry(lower, answer, train, valid, end)
        entry.pop("history")
        entry.update(cpu_s=cpu, search_wall_s=wall, load_before=load, load_after=os.getloadavg()[0],
                     start_guess=guess)   # CPU and wall of the whole search ('pso' and 'pso+pattern' alike)
        out[label if reported == name else label.replace(name, reported)] = entry
    return out


def rescore(case: TowingCase, done: dict, start: str, train, valid, held, end, rebuilt=()) -> None:
    """Every answer in ``done`` of ``start`` identified on these held training runs (same rates and end) compared
    again with today's :func:`comparison_rows` on today's held training and validation runs (its rows, totals and
    ``rates`` replaced, ``reconstructed_attitudes``: the runs whose attitudes were integrated from their rates;
    s, evaluations and CPU kept)."""
    trained = [float(r["rate_deg_s"]) for r in train]
    for key, entry in done.items():
        if (key.split("|")[0] != start or [r["rate_deg_s"] for r in entry["training"]] != trained
                or entry["end_s"] != end):
            continue
        lower = lower_order_case(case, train[0])
        rows = {role: comparison_rows(lower, entry["s"], runs, end) for role, runs in (("training", train),
                                                                                        ("validation", valid))}
        entry.update(training=rows["training"], validation=rows["validation"], rates=held,
                     reconstructed_attitudes=list(rebuilt),
                     training_totals=_totals(rows["training"]), validation_totals=_totals(rows["validation"]))
        print(f"  rescored {key}", flush=True)


def score_given(case: TowingCase, train, valid, s, end) -> dict:
    """The entry of a given ``s`` (e.g. an answer found on other runs, or with older code) scored on these held
    training and validation runs, as a search's answer is (no search: 0 evaluations; ``cpu_s`` the scoring's)."""
    cpu, lower = cpu_seconds(), lower_order_case(case, train[0])
    rows = {role: comparison_rows(lower, list(s), runs, end) for role, runs in (("training", train),
                                                                               ("validation", valid))}
    return {"s": list(s), "cost": None, "optimizer": "given", "evaluations": 0, "wall_s": 0.0,
            "training_totals": _totals(rows["training"]), "validation_totals": _totals(rows["validation"]),
            "training": rows["training"], "validation": rows["validation"], "cpu_s": cpu_seconds() - cpu}


def free_roll(totals: dict, n: int) -> str:
    """' (x.xxx)': f1 per run with omega_D compared blind to a roll about the debris' symmetry axis (the
    diagnostic of identify_fullnet.comparison_rows), or '' when not computed."""
    return f" ({totals['f1_free_roll'] / n:.3f})" if "f1_free_roll" in totals else ""


def print_tables(done: dict) -> None:
    """Markdown rows: per start and cost, every search's s, evaluations, training and validation f1, f2 per run
    (f1 in brackets: omega_D compared blind to a roll about the debris' symmetry axis, when computed), then the
    paper's per-run values of the same cost."""
    print("\n| start, runs | cost | optimizer | s1 | s2 (m) | s3 | s4 | evaluations | CPU (s) | training f1 / run "
          "| training f2 / run (N) | validation f1 / run | validation f2 / run (N) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for key, entry in done.items():
        start, cost, label = key.split("|")
        nt, nv = len(entry["training"]), len(entry["validation"])
        tr, va = entry["training_totals"], entry["validation_totals"]
        s = entry["s"]
        left = len(entry.get("excluded_runs", []))
        runs = f"{nt}+{nv}" + (f" held ({left} left out)" if left else "")
        valid = (f"{va['f1'] / nv:.3f}{free_roll(va, nv)} | {va['f2'] / nv:.1f}" if va else "no validation run held | -")
        print(f"| {start}, {runs} to {entry['end_s']:g} s | {cost} | {label} | {s[0]:.4f} | {s[1]:.4f} | "
              f"{s[2]:.4f} | {s[3]:.4f} | {entry['evaluations']} | {entry['cpu_s']:.0f} | {tr['f1'] / nt:.3f}"
              f"{free_roll(tr, nt)} | {tr['f2'] / nt:.1f} | {valid} |")
    for cost, rows in PAPER.items():
        for label, (train, valid) in rows.items():
            f1 = (f"{train / PAPER_RUNS:.3f}", f"{valid / PAPER_RUNS:.3f}") if cost == "f1" else ("-", "-")
            f2 = (f"{train / PAPER_RUNS:.1f}", f"{valid / PAPER_RUNS:.1f}") if cost == "f2" else ("-", "-")
            print(f"| paper, 10+10 to 300 s | {cost} | {label} | | | | | | | {f1[0]} | {f2[0]} | {f1[1]} | {f2[1]} |")


def frame_cell(totals: dict | None, n: int) -> str:
    """'body / inertial / roll-blind' f1 per run of one set of runs (a '-' where not computed: runs cached
    without attitudes give no inertial figure)."""
    if not totals:
        return "no run held | | "
    return " | ".join(f"{totals[key] / n:.3f}" if key in totals else "-" for key in ("f1", "f1_inertial", "f1_free_roll"))


def print_frame_table(done: dict) -> None:
    """Markdown rows: per answer, f1 per run with the angular velocities compared in body components (eq. 18 as
    the cost ``f1``), in inertial components (``f1_inertial``) and with omega_D blind to a roll about the debris'
    axis, on training and validation runs; then the paper's f1 per run (Tables 7, 10)."""
    print("\n| start, runs | identified on | s1 | s2 (m) | s3 | s4 | training f1 / run: body | inertial | roll-blind "
          "| validation f1 / run: body | inertial | roll-blind |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for key, entry in done.items():
        start, cost, label = key.split("|")
        nt, nv = len(entry["training"]), len(entry["validation"])
        s = entry["s"]
        print(f"| {start}, {nt}+{nv} to {entry['end_s']:g} s | {cost}, {label} | {s[0]:.4f} | {s[1]:.4f} | {s[2]:.4f} "
              f"| {s[3]:.4f} | {frame_cell(entry['training_totals'], nt)} | {frame_cell(entry['validation_totals'], nv)} |")
    for label, (train, valid) in PAPER["f1"].items():
        print(f"| paper, 10+10 to 300 s | f1, {label} | | | | | {train / PAPER_RUNS:.3f} | | | {valid / PAPER_RUNS:.3f} | | |")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--out", required=True, help="folder of the cached full-net runs and results.json")
    parser.add_argument("--starts", nargs="+", default=["wrapped", "capture"], choices=["wrapped", "capture"])
    parser.add_argument("--training", type=int, default=10, help="first N training rates of Table 3")
    parser.add_argument("--validation", type=int, default=10, help="first N validation rates of Table 3")
    parser.add_argument("--end", type=float, default=300.0, help="end of every run (s)")
    parser.add_argument("--optimizers", nargs="+", default=["pso", "pattern", "mads"], choices=["pso", "pattern", "mads"])
    parser.add_argument("--cost", nargs="+", default=["f1", "f2"], choices=["f1", "f1_inertial", "f2"])
    parser.add_argument("--mads-starts", nargs="+", default=["s0", "table6"], choices=["s0", "table6"])
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--table-only", action="store_true", help="print the tables of DIR/results.json")
    parser.add_argument("--runs-only", type=float, nargs="+", metavar="RATE",
                        help="only run (or find cached) the full-net runs at these rates, in this order, and stop")
    parser.add_argument("--reconstruct-attitudes", action="store_true",
                        help="runs cached without attitudes get them integrated from their sampled body rates "
                             "(bench_omega_frames.attitude_from_rates; each answer lists which runs had them so)")
    parser.add_argument("--rescore", action="store_true",
                        help="score every answer of DIR/results.json for these runs again with today's comparison "
                             "(no search; e.g. to add a diagnostic column)")
    parser.add_argument("--score", nargs=5, metavar=("LABEL", "S1", "S2", "S3", "S4"),
                        help="score this s on the runs (no search), kept in DIR/results.json as '<start>|given|LABEL'")
    args = parser.parse_args()
    out = Path(args.out)
    store = out / "results.json"
    done = json.loads(store.read_text()) if store.exists() else {}
    if args.table_only:
        print_tables(done)
        print_frame_table(done)
        return
    case = load_model(args.case, TowingCase)
    if case.full_net is None:
        raise SystemExit(f"{args.case}: the full-net identification needs a [full_net] section")
    for start in args.starts:
        run_case = start_case(case, start, args.training, args.validation, args.end)
        rates = list(case.rates.training_deg_s[:args.training]) + list(case.rates.validation_deg_s[:args.validation])
        wall, load = time.perf_counter(), os.getloadavg()[0]
        if args.runs_only:
            for rate in args.runs_only:   # one at a time: each is cached as it ends
                full_net_runs(run_case, [rate], out / start, args.end, args.workers)
                print(f"{start}: {rate:g} deg/s cached ({time.perf_counter() - wall:.0f} s wall so far, load "
                      f"{load:.1f} -> {os.getloadavg()[0]:.1f})", flush=True)
            continue
        data = full_net_runs(run_case, rates, out / start, args.end, args.workers)
        rebuilt = reconstruct_attitudes(data, case.simulation.output_interval) if args.reconstruct_attitudes else []
        print(f"{start}: {len(rates)} full-net runs to {args.end:g} s ready in {time.perf_counter() - wall:.0f} s wall "
              f"(load average {load:.1f} -> {os.getloadavg()[0]:.1f}; cached runs took "
              f"{sum(d['wall_s'] for d in data):.0f} s of solver wall time)", flush=True)
        # the same rule as 'riskassess identify': a run whose debris was not held is left out and named
        train, valid, excluded = held_runs(run_case, data, min(args.training, len(case.rates.training_deg_s)))
        for why in excluded:
            print(f"  left out {why['rate_deg_s']:g} deg/s: {why['reason']}", flush=True)
        held = [float(r["rate_deg_s"]) for r in train + valid]
        if args.score:
            entry = score_given(run_case, train, valid, [float(v) for v in args.score[1:]], args.end)
            entry.update(rates=held, end_s=args.end, excluded_runs=excluded, reconstructed_attitudes=rebuilt)
            done[f"{start}|given|{args.score[0]}"] = entry
            results.atomic_write_json(store, done)
            continue
        if args.rescore:
            rescore(run_case, done, start, train, valid, held, args.end, rebuilt)
            results.atomic_write_json(store, done)
            continue
        for cost in args.cost:
            for label, name, guess in searches(args.optimizers, args.mads_starts, case.identification.initial_guess):
                key = f"{start}|{cost}|{label}"
                if (key in done and done[key]["rates"] == held and done[key]["end_s"] == args.end
                        and done[key].get("reconstructed_attitudes", []) == rebuilt):
                    continue
                for reported, entry in run_one(run_case, train, valid, label, name, guess, cost, args.workers,
                                               args.end).items():
                    entry.update(rates=held, end_s=args.end, excluded_runs=excluded, reconstructed_attitudes=rebuilt)
                    done[f"{start}|{cost}|{reported}"] = entry
                    tr, va = entry["training_totals"], entry["validation_totals"]
                    scored = f"validation f1 {va['f1']:.3f} f2 {va['f2']:.1f}" if va else "no validation run held"
                    print(f"  {start} {cost} {reported:12s} s = {[round(v, 4) for v in entry['s']]} training f1 "
                          f"{tr['f1']:.3f} f2 {tr['f2']:.1f}, {scored}; "
                          f"{entry['evaluations']} evaluations, {entry['cpu_s']:.0f} s CPU, {entry['wall_s']:.0f} s wall "
                          f"(load {entry['load_before']:.1f} -> {entry['load_after']:.1f})", flush=True)
                results.atomic_write_json(store, done)
    print_tables(done)
    print_frame_table(done)


if __name__ == "__main__":
    main()
