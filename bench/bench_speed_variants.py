"""A numerics change for speed judged against the round-off spread: replicas of the whole pipeline, A/B.

    python3 bench/bench_speed_variants.py --label main [--case envisat_net_impact] [--replicas 3]
                                          [--set contact_substep=4e-6 ...] [--store FILE] [--table-only]

Runs ``cases/<case>.toml`` through the whole pipeline (``riskassess.stages.run.run_case``: release on, weak
locations judged) with the launch speed x (1 + k 1e-7), k = 0, +1, -1, ... (as bench/bench_coupling_replicas.py:
the capture is round-off chaotic, so a change is judged against the spread of such replicas, not one run), with
``--set key=value`` changing ``[simulation]`` keys of the case. ``--label`` names the code and settings under
test (two labels run from two worktrees, or one worktree with and without ``--set``, are two columns of the
table). Per run it stores the CPU time of the run, the energy balance's largest drift, the debris' along-track
velocity change at the end and over the final third, the solar-array hinge's largest |M| (summary), the array's
release time, and every weak location's verdict with its judged peak. Resumable: each finished run is stored at
once in ``--store`` (default bench/results/speed_variants.json); ``--table-only`` prints the table from it.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from riskassess.cases.impact import load_case
from riskassess.stages.run import run_case

ROOT = Path(__file__).resolve().parents[1]
EPS = 1e-7


def parsed_value(text: str):
    """A --set value: a number when it reads as one, else the text."""
    try:
        return float(text) if any(c in text for c in ".eE") else int(text)
    except ValueError:
        return text


def replica(case_path: Path, k: int, settings: dict):
    """The case with the launch speed x (1 + k EPS) and the ``settings`` [simulation] keys."""
    case = load_case(case_path)
    launch = case.launch.model_copy(update={"velocity": case.launch.velocity * (1.0 + k * EPS)})
    return case.model_copy(update={"launch": launch,
                                   "simulation": case.simulation.model_copy(update=settings)})


def figures(run: Path) -> dict:
    """The compared figures of one finished run folder."""
    summary = json.loads((run / "summary.json").read_text())
    row = {
        "energy drift (%)": 100.0 * summary["checks"]["energy_balance_relative_drift"],
        "debris dv_y end (mm/s)": 1e3 * summary["debris_velocity_change_lvlh_m_s"][1],
        "debris dv_y final third (mm/s)": 1e3 * summary["debris_velocity_change_final_third_mean_lvlh_m_s"][1],
        "peak contact force (kN)": 1e-3 * summary["peak_contact_force_N"]["value"],
    }
    hinge = summary["joints"].get("solar_array_hinge")
    if hinge:
        row["array hinge max |M| (N m)"] = float(np.linalg.norm(hinge["max_abs_moment_joint_Nm"]))
    structures = run / "structures.json"
    if structures.exists():
        verdict = json.loads(structures.read_text())
        row["secondary debris"] = verdict["secondary_debris"]
        row["debris state"] = verdict["debris_state"]
        for location in verdict["locations"]:
            for name, criterion in location["criteria"].items():
                row[f"{location['name']} {name} fails"] = criterion.get("fails")
                if criterion.get("peak") is not None:
                    row[f"{location['name']} {name} peak"] = criterion["peak"]
        for piece in verdict["released_pieces"]:
            row[f"{piece['location']} released at (s)"] = piece["release_time_s"]
    return row


def run_one(case_path: Path, k: int, settings: dict) -> dict:
    case = replica(case_path, k, settings)
    load = os.getloadavg()[0]
    cpu = time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        run_case(case_path, Path(tmp) / "run", case=case)
        row = figures(Path(tmp) / "run")
    return row | {"cpu (s)": time.process_time() - cpu, "load": [load, os.getloadavg()[0]]}


def table(store: dict, case: str) -> None:
    """Per figure and label: mean and range over the replicas (booleans: the values seen)."""
    labels = sorted({key.split("|")[1] for key in store if key.split("|")[0] == case})
    runs = {label: [v for key, v in sorted(store.items()) if key.split("|")[:2] == [case, label]] for label in labels}
    keys = []
    for rows in runs.values():
        for row in rows:
            keys += [key for key in row if key not in keys and key not in ("load", "settings")]
    print(f"{case}: " + "; ".join(f"{label} {len(rows)} runs" for label, rows in runs.items()))
    print(f"{'figure':52s} " + " | ".join(f"{label:>34s}" for label in labels))
    for key in keys:
        cells = []
        for label in labels:
            values = [row[key] for row in runs[label] if key in row]
            if not values:
                cells.append(f"{'-':>34s}")
            elif isinstance(values[0], (bool, str)) or values[0] is None:
                cells.append(f"{'/'.join(sorted({str(v) for v in values})):>34s}")
            else:
                v = np.array(values, float)
                cells.append(f"{v.mean():10.5g} [{v.min():10.5g}, {v.max():10.5g}]")
        print(f"{key[:52]:52s} " + " | ".join(cells))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--label", default="main")
    parser.add_argument("--case", default="envisat_net_impact")
    parser.add_argument("--replicas", type=int, default=3)
    parser.add_argument("--set", nargs="*", default=[], help="[simulation] key=value")
    parser.add_argument("--store", type=Path, default=ROOT / "bench" / "results" / "speed_variants.json")
    parser.add_argument("--table-only", action="store_true")
    args = parser.parse_args()
    store = json.loads(args.store.read_text()) if args.store.exists() else {}
    if not args.table_only:
        settings = {key: parsed_value(value) for key, value in (item.split("=", 1) for item in args.set)}
        case_path = ROOT / "cases" / f"{args.case}.toml"
        for k in [0, 1, -1, 2, -2, 3, -3][:args.replicas]:
            key = f"{args.case}|{args.label}|{k:+d}"
            if key in store:
                continue
            store[key] = run_one(case_path, k, settings) | {"settings": args.set}
            tmp = args.store.with_suffix(".tmp")
            tmp.write_text(json.dumps(store, indent=1))
            os.replace(tmp, args.store)
            print(f"{key}: cpu {store[key]['cpu (s)']:.1f} s, load {store[key]['load']}", flush=True)
    table(store, args.case)


if __name__ == "__main__":
    sys.exit(main())
