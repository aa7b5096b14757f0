"""Benchmark of `riskassess diagnose`: a 300 s, 10 Hz record with the whole catalog, per scenario.

    python bench/bench_diagnosis.py [--workers 2]

Uses the sample records of cases/data/ (written by cases/data/make_diagnosis_samples.py; made here
if missing). Prints the wall time, the time of each candidate's fit and the result. The issue's goal:
under 2 minutes per diagnosis on 2 cores. On a shared machine the figures are upper bounds.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

RUNS = (("diagnose_tumbling_rigid.toml", "tumbling_rigid_nutation.csv"),
        ("diagnose_hinged_appendage.toml", "hinged_appendage_friction.csv"),
        ("diagnose_towing.toml", "towing_viscoelastic.csv"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--only", nargs="*", help="case file names to run (default: all)")
    args = parser.parse_args()
    tic = time.perf_counter()
    from riskassess.diagnose import diagnose_case   # numba compiled code loads from its cache here
    print(f"import (compiled model from the numba cache): {time.perf_counter() - tic:.1f} s")
    if not all((ROOT / "cases" / "data" / data).is_file() for _, data in RUNS):
        sys.path.insert(0, str(ROOT / "cases" / "data"))
        import make_diagnosis_samples

        make_diagnosis_samples.main()
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores; > 2 means other jobs share them)")
    for case_name, data_name in RUNS:
        if args.only and case_name not in args.only:
            continue
        with tempfile.TemporaryDirectory() as tmp:
            case = Path(tmp) / case_name
            # a towing diagnosis names its towing case relative to itself
            case.write_text((ROOT / "cases" / case_name).read_text().replace(
                'towing = "', f'towing = "{ROOT / "cases"}/'))
            tic = time.perf_counter()
            answer = diagnose_case(case, ROOT / "cases" / "data" / data_name, Path(tmp) / "out", workers=args.workers)
            wall = time.perf_counter() - tic
        print(f"\n{case_name} + {data_name}: {answer['samples']} samples, {len(answer['channels']['used'])} channels, "
              f"{len(answer['candidates'])} candidates fitted, {len(answer['not_applicable'])} not applicable")
        print(f"  wall {wall:.1f} s (goal < 120 s); nominal fit {answer['nominal']['fit_seconds']:.1f} s")
        for row in answer["candidates"]:
            print(f"  {row['id']:28s} fit {row['fit_seconds']:6.1f} s  evaluations {row['evaluations']:4d}  "
                  f"delta BIC {row['delta_bic']:12.1f}")
        print(f"  cause: {answer['cause']} (confidence {answer['confidence']}); gain {answer['gain_percent']['overall']:.1f} %")
        print("  parameters: " + ", ".join(f"{k} = {v['value']:.4g} +- {v['std']:.2g} {v['unit']}"
                                         for k, v in answer["parameters"].items()))
        print(f"  load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
