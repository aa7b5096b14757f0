"""Fixed-window peaks of a bench_peak_convergence cache, raw and through the step filter.

    python3 bench/peak_windows.py CASE CACHE [--windows 0-0.6,0.25-1.1,0.25-11]

For every run the cache holds (``bench/bench_peak_convergence.py --load-filter ...``: raw and filtered joint loads),
each weak location's peak in each window (s), the baseline's median [range] over its replicas, and each variant's
median change against it with the range of its replicas. Fixed windows, not the replicas' parting time: a window
that ends before the replicas part compares the numerics of one deterministic history.
"""
from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import numpy as np

from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs, weak_locations
from structures.weak_location import judged_demands


def window_peaks(run: dict, locations, windows) -> dict:
    """{(reading, "location/criterion", window): peak} of one run (readings "raw" and "filtered")."""
    t = run["time"]
    half = 0.5 * float(np.median(np.diff(t)))
    out = {}
    for reading, force, moment in (("raw", run["force"], run["moment"]),
                                   ("filtered", run["force_filtered"], run["moment_filtered"])):
        for loc in locations:
            demand = judged_demands(loc, t, force[:, loc.joint], moment[:, loc.joint])
            for criterion in loc.criteria():
                for low, high in windows:
                    inside = (t >= low - half) & (t < high - half)
                    out[(reading, f"{loc.name}/{criterion}", (low, high))] = float(demand[criterion][inside].max())
    return out


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("cache")
    parser.add_argument("--windows", default="0-0.6,0.25-1.1,0.25-11", help="comma list of LOW-HIGH (s)")
    args = parser.parse_args()
    case_path = Path(args.case).resolve()
    text = case_path.read_text().replace('release = "low"', 'release = "never"', 1)
    case = validate_case(tomllib.loads(text), case_path)
    locations = weak_locations(case, model_inputs(case, case_path.parent).assembly)
    windows = [tuple(float(v) for v in w.split("-")) for w in args.windows.split(",")]
    peaks: dict = {}
    for path in sorted(p for p in Path(args.cache).glob("*.npz") if ".tmp" not in p.name):   # not a run being written
        variant, _ = path.stem.rsplit("-", 1)
        with np.load(path) as data:
            run = dict(data)
        if "force_filtered" not in run:
            raise SystemExit(f"{path}: no filtered loads (run the bench with --load-filter)")
        for key, value in window_peaks(run, locations, windows).items():
            peaks.setdefault(key, {}).setdefault(variant, []).append(value)
    for (reading, name, (low, high)), runs in sorted(peaks.items()):
        base = float(np.median(runs["baseline"]))
        cells = " | ".join(f"{v}: {np.median(x) / base - 1:+.1%} ({min(x) / base - 1:+.0%}..{max(x) / base - 1:+.0%}, n={len(x)})"
                           for v, x in runs.items() if v != "baseline")
        print(f"{reading:8s} {name:34s} {low:g}-{high:g} s: baseline {base:.4g} [{min(runs['baseline']):.3g}, "
              f"{max(runs['baseline']):.3g}] n={len(runs['baseline'])} | {cells}")


if __name__ == "__main__":
    main()
