"""The runs of safe-velocity stores one by one: answer, the judged location's state and utilization, energy drift.

    python3 bench/bench_safe_velocity_runs.py STORE [STORE ...] [--location solar_array_hinge_panel]

For each store written by ``bench/bench_safe_velocity.py`` (or ``riskassess sweep --store``), per velocity: the runs
done, with debris, indeterminate and without; the location's utilization (judged peak / decisive allowable)
min / median / max; the energy balance's largest drift; the wall time of a run; then one line per run: its sample,
answer, the location's state and utilization (and release time), the largest utilization of the other locations,
the drift, its inputs and the reasons of an indeterminate answer. Reads the store only; runs nothing.
"""
from __future__ import annotations

import argparse
import json
import sqlite3
from pathlib import Path

import numpy as np

from riskassess.products.sweep_records import indeterminate_reasons_of


def store_runs(path: Path) -> dict:
    """Velocity (m/s) -> list of (sample, state, result dict or None, wall s, overrides), in sample order."""
    with sqlite3.connect(path) as con:
        rows = con.execute("select sample, overrides, state, result, wall_s from runs order by grid_index, sample").fetchall()
    by_velocity: dict = {}
    for sample, overrides, state, result, wall in rows:
        inputs = json.loads(overrides)
        by_velocity.setdefault(inputs.get("launch.velocity"), []).append(
            (sample, state, json.loads(result) if result else None, wall, inputs))
    return by_velocity


def print_summary(velocity, runs: list, location: str) -> None:
    """One line: counts, the location's utilization and the drift over the finished runs."""
    done = [r for r in runs if r[1] == "done" and r[2] is not None]
    answers = [r[2]["debris_state"] for r in done]
    head = (f"{velocity} m/s: {len(done)} runs done of {len(runs)}: debris {answers.count('debris')}, indeterminate "
            f"{answers.count('indeterminate')}, no debris {answers.count('no_debris')}")
    if not done:
        print(head)
        return
    use = [r[2]["locations"][location]["utilization"] for r in done]
    drift = [100 * r[2]["energy_balance_relative_drift"] for r in done]
    wall = [r[3] for r in done]
    print(f"{head}; {location} utilization min / median / max {min(use):.3f} / {np.median(use):.3f} / {max(use):.3f}; "
          f"energy drift largest {max(drift):.2f} % (median {np.median(drift):.2f} %); wall {min(wall):.0f}-{max(wall):.0f} s a run")


def print_run(sample: int, state: str, result: dict | None, inputs: dict, location: str) -> None:
    """One line per run."""
    if result is None:
        print(f"   sample {sample:2d}: {state}")
        return
    judged = result["locations"][location]
    released = f", released at {judged['released_at_s']:.3f} s" if judged["released_at_s"] is not None else ""
    others = max(row["utilization"] for name, row in result["locations"].items() if name != location)
    why = "; ".join(f"{r['location'] or 'run'}: {r['rule']}" for r in indeterminate_reasons_of(result))
    shown = ", ".join(f"{k} {v:.4g}" for k, v in inputs.items() if k != "launch.velocity")
    print(f"   sample {sample:2d}: {result['debris_state']:13s} {judged['state']:6s} {judged['utilization']:.3f}{released}; "
          f"others <= {others:.4f}; drift {100 * result['energy_balance_relative_drift']:.2f} %; {shown}"
          + (f"; {why}" if why else ""))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("stores", nargs="+")
    parser.add_argument("--location", default="solar_array_hinge_panel")
    args = parser.parse_args()
    for store in args.stores:
        print(store)
        for velocity, runs in sorted(store_runs(Path(store)).items(), key=lambda kv: (kv[0] is None, kv[0])):
            print_summary(velocity, runs, args.location)
            for sample, state, result, _, inputs in runs:
                print_run(sample, state, result, inputs, args.location)


if __name__ == "__main__":
    main()
