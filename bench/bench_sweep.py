"""Sweep throughput on this machine: runs per hour with 1 and with 2 LocalCluster workers.

    python3 bench/bench_sweep.py [--runs 6] [--end-time 7.5] [--workers 1 2]

Sweeps cases/envisat_small.toml (15 x 15 net, the reference weak locations) over
``--runs`` impact velocities from 10 to 20 m/s, each worker count into a fresh store, and
prints wall time, runs per hour and the speed-up over one worker.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from riskassess.sweep.runner import run_sweep
from riskassess.sweep.spec import parse_vary, run_specs
from riskassess.sweep.store import ResultStore

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=6)
    parser.add_argument("--end-time", type=float, default=7.5)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "small.toml"
        case.write_text((ROOT / "cases" / "envisat_small.toml").read_text()
                        .replace("end_time = 7.5", f"end_time = {args.end_time}", 1))
        specs = run_specs([parse_vary(f"launch.velocity=10:20:{args.runs}")])
        base = None
        for workers in args.workers:
            store = ResultStore(Path(tmp) / f"w{workers}" / "results.sqlite")
            t0 = time.perf_counter()
            outcome = run_sweep(case, specs, store, {"arguments": []}, n_workers=workers)
            wall = time.perf_counter() - t0
            per_run = [r["result"]["wall_time_s"] for r in store.rows() if r["state"] == "done"]
            base = base or wall
            print(f"{workers} worker(s): {outcome.done} runs done, {outcome.failed} failed, {wall:.1f} s wall "
                  f"(incl. cluster start), {3600 * outcome.done / wall:.0f} runs/hour, speed-up {base / wall:.2f}; "
                  f"simulation time per run {min(per_run):.1f}-{max(per_run):.1f} s")


if __name__ == "__main__":
    main()
