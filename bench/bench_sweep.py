"""Sweep throughput: wall time of a Monte Carlo at one impact velocity on a LocalCluster.

    python3 bench/bench_sweep.py [CASE] [--runs 29] [--workers 2] [--end-time T]
                                 [--uncertain KEY=DIST(...) ...] [--seed 0]

Default: the reference case (``cases/envisat_net_impact.toml``, 35 x 35 net, 7.5 s, 20 m/s) with 29
Monte Carlo samples (the fewest runs that show P(no debris) >= 90 % at 95 % confidence with no failure:
0.9^29 = 0.047) of the contact friction and damping, on 2 workers, through the project's sweep runner
(``riskassess.sweep.runner.run_sweep``: store lock, one run folder per run) into a fresh store. Prints
the wall time including the cluster's start, runs per hour, the simulation time per run and the machine's
load; the report products are not made (``riskassess sweep`` adds them).
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from riskassess.sweep.runner import run_sweep
from riskassess.cases.uncertain import parse_uncertain
from riskassess.sweep.spec import run_specs
from riskassess.sweep.store import ResultStore

ROOT = Path(__file__).resolve().parents[1]
#: [paper T2] mu_s = 0.19, alpha = 0.05 s/m, each +-20 % [assumed spread]
DEFAULT_UNCERTAIN = ["contact.mu_static=uniform(0.152,0.228)", "contact.hunt_crossley_alpha=uniform(0.04,0.06)"]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_net_impact.toml"))
    parser.add_argument("--runs", type=int, default=29)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--end-time", type=float, default=None, help="shorter runs (s); default: the case's")
    parser.add_argument("--uncertain", action="append", default=None)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    uncertain = args.uncertain or DEFAULT_UNCERTAIN
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / Path(args.case).name
        text = Path(args.case).read_text()
        if args.end_time is not None:
            lines = [f"end_time = {args.end_time}" if line.startswith("end_time =") else line
                     for line in text.splitlines()]
            text = "\n".join(lines) + "\n"
        case.write_text(text)
        for path in Path(args.case).parent.glob("*"):  # mesh files next to the case
            if path.suffix.lower() in (".stl", ".obj", ".ply") and not (Path(tmp) / path.name).exists():
                (Path(tmp) / path.name).symlink_to(path.resolve())
        specs = run_specs([], [parse_uncertain(u) for u in uncertain], args.runs, args.seed)
        store = ResultStore(Path(tmp) / "results.sqlite")
        load_before = os.getloadavg()[0]
        start = time.perf_counter()
        try:
            outcome = run_sweep(case, specs, store, {"arguments": [f"--uncertain {u}" for u in uncertain]},
                                n_workers=args.workers)
            wall = time.perf_counter() - start
            per_run = [r["result"]["wall_time_s"] for r in store.rows() if r["state"] == "done"]
        finally:
            store.close()
    print(f"case {Path(args.case).name}, {len(specs)} Monte Carlo runs ({', '.join(uncertain)}), "
          f"{args.workers} workers")
    print(f"{outcome.done} done ({outcome.indeterminate} indeterminate), {outcome.failed} failed")
    print(f"wall time {wall:.1f} s ({wall / 60:.2f} min, incl. cluster start), {3600 * outcome.done / wall:.0f} runs/hour")
    if per_run:
        print(f"simulation time per run {min(per_run):.1f}-{max(per_run):.1f} s")
    print(f"machine load {load_before:.2f} before, {os.getloadavg()[0]:.2f} after")


if __name__ == "__main__":
    main()
