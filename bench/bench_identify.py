"""Sec. 4.3 identification benchmark (Boonrath, Singh & Botta 2024) on cases/zenit2_towing.toml:
data from the lower-order model with s_true = [2, 7, 2, 1] at the 10 Table 3 training rates over
the whole 275 s tow; identified by pymoo's PSO (then polished by the pattern search) and by the
pattern search from the paper's s0 = [1, 6, 3, 0.25]. Simulations run on ``identification.workers``
processes.

    python bench/bench_identify.py [--optimizers pso pattern mads] [--cost f1 f2] [--starts s0|table6]
                                   [--swarm N] [--generations N] [--polish N] [--pattern N] [--restart N]
                                   [--tolerance X] [--mads N] [--truth S1 S2 S3 S4]
                                   [--results FILE.jsonl] [--only-start K ...] [--table-only]

``--cost f1 f2`` runs every optimizer on each cost; ``--starts table6`` starts MADS and the pattern search
from each of the paper's Table 6 initial guesses (MADS 1-5) instead of the case's s0 (Sec. 4.3 uses s0 for
the benchmark). At the end the paper's Tables 4 (converged cost per optimizer and cost) and 5 (converged s)
are printed as markdown rows, with the evaluations, wall and CPU time of each run.

``--results FILE.jsonl`` makes the bench resumable: every finished (optimizer, cost, start) run is appended to
the file as one JSON line (s, cost, relative error, evaluations, wall and CPU time, load average before and after)
the moment it ends, and a run already in the file is not run again; ``--table-only`` prints the tables from the
file without running anything. ``--only-start K ...`` runs only those Table 6 starts (1-5).

(defaults: the case's ``[identification.optimizers]``). Prints the CPU time of one evaluation (its
10 runs, one after the other, in this process), then per optimizer: s, cost, largest relative error
against s_true, evaluations, wall time, and the load average before and after. Goal: every s
within 1e-3 relative, < 10 min on 2 cores. Timings are upper bounds when other jobs share the machine
(the load average says how much).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time

import numpy as np

from riskassess.cases.impact import load_model
from riskassess.stages.identify import benchmark, simulate
from riskassess.cases.towing import Optimizers, TowingCase

#: Boonrath, Singh & Botta 2024, Table 6: the initial guesses of MADS 1-5 (s1, s2 m, s3, s4).
TABLE6_INITIAL_GUESSES = ([3.0, 9.0, 1.0, 0.5], [2.0, 9.0, 1.0, 0.5], [3.0, 8.0, 1.0, 0.5], [3.0, 9.0, 2.0, 0.5],
                          [3.0, 9.0, 1.0, 0.75])
#: Boonrath, Singh & Botta 2024, Tables 4 and 5 (benchmark, truth [2, 7, 2, 1], start s0 for MADS): converged cost and
#: s per (optimizer, cost). The paper ran MADS (MATLAB nups-mads) and PSO (40 particles, no polish); it has no pattern
#: search, so ours "pattern" has no paper row, and our "pso" and "pso+pattern" both stand beside its PSO.
PAPER_BENCHMARK = {("mads", "f1"): (0.4960, [1.9959287, 6.9976071, 1.9901418, 0.4832296]),
                   ("pso", "f1"): (6.3958e-5, [2.0000003, 7.0000015, 1.9999996, 0.9999957]),
                   ("mads", "f2"): (3.4684, [1.9971665, 7.0066112, 1.9987416, 0.8285154]),
                   ("pso", "f2"): (0.0217, [2.0000035, 7.0000049, 2.0000158, 0.9999974])}
PAPER_START = [1.0, 6.0, 3.0, 0.25]
PAPER_TRUTH = [2.0, 7.0, 2.0, 1.0]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--optimizers", nargs="+", default=["pso", "pattern"], choices=["pso", "pattern", "mads"])
    for flag, key, kind in (("--swarm", "swarm_size", int), ("--generations", "pso_generations", int),
                            ("--polish", "polish_evaluations", int), ("--pattern", "pattern_evaluations", int),
                            ("--restart", "restart_evaluations", int), ("--tolerance", "pattern_tolerance", float),
                            ("--mads", "mads_evaluations", int)):
        parser.add_argument(flag, dest=key, type=kind, default=None)
    parser.add_argument("--cost", nargs="+", default=None, choices=["f1", "f2"],
                        help="costs to run (default the case's identification.cost)")
    parser.add_argument("--starts", choices=["s0", "table6"], default="s0",
                        help="start of MADS and the pattern search: the case's s0 or each Table 6 initial guess")
    parser.add_argument("--workers", type=int, default=None, help="worker processes (default identification.workers)")
    parser.add_argument("--truth", type=float, nargs=4, default=None,
                        help="s of the data instead of the case's benchmark_truth (a robustness check off the paper's s)")
    parser.add_argument("--results", default=None,
                        help="JSON-lines file: finished runs are appended and not run again (resumable)")
    parser.add_argument("--only-start", type=int, nargs="+", default=None,
                        help="with --starts table6: only these Table 6 starts (1-5)")
    parser.add_argument("--table-only", action="store_true", help="print the tables from --results, run nothing")
    args = parser.parse_args()
    done = read_results(args.results)
    if args.table_only:
        print_tables([(r["label"], r["cost_name"], r) for r in done.values()])
        return
    case = load_model(args.case, TowingCase)
    ident = case.identification
    update = {key: value for key, value in vars(args).items() if key in Optimizers.model_fields and value is not None}
    settings = ident.optimizers.model_copy(update=update)
    truth = ident.benchmark_truth if args.truth is None else args.truth
    ident = ident.model_copy(update=dict(optimizers=settings, benchmark_truth=truth,
                                        workers=args.workers or ident.workers))
    case = case.model_copy(update=dict(identification=ident))
    print(f"settings: {settings.model_dump()}; load average {os.getloadavg()[0]:.1f}")
    costs = args.cost or [ident.cost]
    starts = {"s0": [("", ident.initial_guess)],
              "table6": [(f" {k + 1}", guess) for k, guess in enumerate(TABLE6_INITIAL_GUESSES)
                         if args.only_start is None or k + 1 in args.only_start]}[args.starts]
    simulate(case, case.rates.training_deg_s[0], ident.benchmark_truth)  # compiled code loaded
    cpu = time.process_time()
    for rate in case.rates.training_deg_s:
        simulate(case, rate, ident.benchmark_truth)
    print(f"one evaluation (10 runs of the twin, serial): {time.process_time() - cpu:.2f} s CPU")
    start = time.perf_counter()
    rows = []
    for cost in costs:
        for name in args.optimizers:
            for label, guess in (starts if name in ("mads", "pattern") else [("", ident.initial_guess)]):
                key = f"{name}{label}|{cost}|{list(guess)}|{truth}"
                if key in {r["key"] for r in done.values()}:
                    print(f"  {name}{label} {cost}: in {args.results}, not run again", flush=True)
                    rows += [(r["label"], r["cost_name"], r) for r in done.values() if r["key"] == key]
                    continue
                run_case = case.model_copy(update=dict(identification=case.identification.model_copy(
                    update=dict(cost=cost, initial_guess=list(guess)))))
                load_before, cpu_before = os.getloadavg()[0], _cpu_s()
                out = benchmark(run_case, optimizers=(name,))
                cpu_s = _cpu_s() - cpu_before
                print(f"data: {len(out['rates_deg_s'])} runs of {case.simulation.end_time - case.simulation.start_time:g} s "
                      f"(step {ident.step * 1e3:g} ms) in {out['data_wall_s']:.1f} s; s_true = {out['truth']}, cost "
                      f"{cost}, start {list(guess)}; load average {os.getloadavg()[0]:.1f}")
                for found, run in out["runs"].items():
                    print(f"  {found:12s} s = {np.round(run['s'], 5).tolist()} cost {run['cost']:.3e} max rel. error "
                          f"{max(run['relative_error']):.2e} ({np.array(run['relative_error']).round(5).tolist()}) "
                          f"{run['evaluations']} evaluations {run['wall_s']:.0f} s wall", flush=True)
                    rows.append((f"{found}{label}", cost, run))
                    record = {"key": key, "label": f"{found}{label}", "cost_name": cost, "start": list(guess),
                              "truth": list(truth), "cpu_s_whole": cpu_s, "load_before": load_before,
                              "load_after": os.getloadavg()[0], "settings": settings.model_dump(),
                              **{k: v for k, v in run.items() if k != "history"}}
                    append_result(args.results, record)
    print_tables(rows)
    print(f"total {time.perf_counter() - start:.0f} s wall; load average now {os.getloadavg()[0]:.1f}")


def _cpu_s() -> float:
    """CPU seconds of this process and its reaped worker processes (the pool's workers end with each search)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def read_results(path) -> dict:
    """Finished runs of a ``--results`` file, keyed by label and key (empty without a file).

    Parameters
    ----------
    path : str or None
        JSON-lines file written by :func:`append_result`.

    Returns
    -------
    dict
        {(key, label): record}, in file order.
    """
    if path is None or not os.path.exists(path):
        return {}
    with open(path, encoding="utf-8") as handle:
        records = [json.loads(line) for line in handle if line.strip()]
    return {(r["key"], r["label"]): r for r in records}


def append_result(path, record: dict) -> None:
    """Append one finished run to the ``--results`` file as one JSON line, flushed to disk at once.

    Parameters
    ----------
    path : str or None
        JSON-lines file; nothing is written without one.
    record : dict
        The run's record (JSON-serialisable).
    """
    if path is None:
        return
    with open(path, "a", encoding="utf-8") as handle:
        handle.write(json.dumps(record) + "\n")
        handle.flush()
        os.fsync(handle.fileno())


def paper_row(label: str, cost: str, run: dict):
    """The paper's Table 4-5 entry (converged cost, s) that stands beside one of our benchmark runs, or None.

    Parameters
    ----------
    label : str
        Our optimizer label (``mads``, ``pso``, ``pso+pattern``, ``pattern``, ``mads 3``, ...).
    cost : str
        ``f1`` or ``f2``.
    run : dict
        Our run's record (``truth`` and ``start`` when known).

    Returns
    -------
    tuple of (float, list of float) or None
        The paper's converged cost and s; None where the paper has no such run (the pattern search, a Table 6 start:
        the paper's Table 6 starts are for the full-net identification, Sec. 4.4, not the benchmark), or where our run
        used another truth or start.
    """
    if run.get("truth", PAPER_TRUTH) != PAPER_TRUTH:
        return None
    name = label.split()[0]
    if name == "mads" and run.get("start", PAPER_START) != PAPER_START:
        return None
    return PAPER_BENCHMARK.get(("pso" if name.startswith("pso") else name, cost))


def print_tables(rows):
    """The paper's Tables 4 (converged cost) and 5 (converged s) as markdown rows, plus evaluations and wall time,
    with the paper's value beside ours where the paper has the same run (:func:`paper_row`).

    Parameters
    ----------
    rows : list of (str, str, dict)
        (optimizer label, cost name, benchmark entry: ``s``, ``cost``, ``relative_error``, ``evaluations``, ``wall_s``).
    """
    print("\nTable 4 (converged cost, benchmark):\n| optimizer | cost | start | converged value | paper | ours / paper "
          "| evaluations | wall (s) | CPU (s) | load |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, cost, run in rows:
        cpu = f"{run['cpu_s_whole']:.0f}" if "cpu_s_whole" in run else ""
        load = f"{run['load_before']:.1f}-{run['load_after']:.1f}" if "load_before" in run else ""
        paper = paper_row(label, cost, run)
        beside = f"{paper[0]:.4g} | {run['cost'] / paper[0]:.3g}" if paper else " | "
        print(f"| {label} | {cost} | {run.get('start', '')} | {run['cost']:.4g} | {beside} | {run['evaluations']} | "
              f"{run['wall_s']:.0f} | {cpu} | {load} |")
    print("\nTable 5 (converged s, benchmark; truth [2, 7, 2, 1]; under each of ours the paper's, where it has the "
          "run, and ours - paper):\n| optimizer, cost | s1 | s2 | s3 | s4 | max rel. error | max rel. error s1-s3 |")
    print("|---|---|---|---|---|---|---|")
    for label, cost, run in rows:
        paper = paper_row(label, cost, run)
        if run.get("truth") not in (None, PAPER_TRUTH):
            label = f"{label} (truth {run['truth']})"
        print(f"| {label} {cost} | " + " | ".join(f"{v:.7f}" for v in run["s"]) + f" | {max(run['relative_error']):.1e} | "
              f"{max(run['relative_error'][:3]):.1e} |")
        if paper:
            error = np.abs(np.subtract(paper[1], PAPER_TRUTH)) / np.abs(PAPER_TRUTH)
            print(f"| paper {label.split()[0].split('+')[0]} {cost} | " + " | ".join(f"{v:.7f}" for v in paper[1])
                  + f" | {error.max():.1e} | {error[:3].max():.1e} |")
            print("| ours - paper | " + " | ".join(f"{a - b:+.2e}" for a, b in zip(run["s"], paper[1])) + " | | |")


if __name__ == "__main__":
    main()
