"""Benchmark of `riskassess diagnose`: a 300 s, 10 Hz record with the whole catalog, per scenario.

    python bench/bench_diagnosis.py [--workers 2] [--only CASE ...] [--towing-truths]

Uses the sample records of cases/data/ (written by cases/data/make_diagnosis_samples.py; made here
if missing). Prints the wall time, the time of each candidate's fit and the result. The issue's goal:
under 2 minutes per diagnosis on 2 cores. On a shared machine the figures are upper bounds.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

RUNS = (("diagnose_tumbling_rigid.toml", "tumbling_rigid_nutation.csv"),
        ("diagnose_hinged_appendage.toml", "hinged_appendage_friction.csv"),
        ("diagnose_towing.toml", "towing_viscoelastic.csv"))


#: --towing-truths: viscoelastic tethers other than the sample's (k_m N/m, tau_m s, noise seed): a faster and
#: softer branch, a stiff slow one, and one that relaxes over most of the record.
TOWING_TRUTHS = ((2000.0, 10.0, 11), (12000.0, 80.0, 12), (4000.0, 200.0, 13))


def towing_truths(workers: int) -> None:
    """Records of cases/diagnose_towing.toml with the TOWING_TRUTHS viscoelastic tethers (Exudyn, 4 ms,
    300 s at 10 Hz, the default noise): the fitted k_m and tau_m against the truth in their own
    standard deviations."""
    import numpy as np

    from riskassess.products.measured import write_measured
    from riskassess.diagnosis.synthetic import noisy, sample_times, simulate_effect
    from riskassess.stages.diagnose import diagnose_case
    from riskassess.diagnosis.cases import load_diagnosis_case

    times = sample_times(300.0, 10.0)
    for k_m, tau, seed in TOWING_TRUTHS:
        with tempfile.TemporaryDirectory() as tmp:
            case = _towing_case_copy(Path(tmp))
            truth = {"maxwell_stiffness": k_m, "relaxation_time": tau}
            clean = simulate_effect(load_diagnosis_case(case), times, "tether_viscoelasticity", truth)
            data, _ = noisy(clean, np.random.default_rng(seed))
            write_measured(Path(tmp) / "measured.csv", times, data)
            tic, cpu = time.perf_counter(), _cpu_seconds()
            answer = diagnose_case(case, Path(tmp) / "measured.csv", Path(tmp) / "out", workers=workers)
            wall, cpu = time.perf_counter() - tic, _cpu_seconds() - cpu
        print(f"\ntruth k_m = {k_m:g} N/m, tau_m = {tau:g} s (seed {seed}): cause {answer['cause']} "
              f"(confidence {answer['confidence']}), gain {answer['gain_percent']['overall']:.1f} %, wall {wall:.1f} s, "
              f"CPU {cpu:.1f} s")
        row = next(r for r in answer["candidates"] if r["id"] == "tether_viscoelasticity")
        print(f"  tether_viscoelasticity: delta BIC {row['delta_bic']:.1f}, rank "
              f"{[r['id'] for r in answer['candidates']].index(row['id']) + 1}; {answer['statement']}")
        for name, value in truth.items():
            fit = row["parameters"][name]
            print(f"  {name}: {fit['value']:.4g} +- {fit['std']:.2g} {fit['unit']} "
                  f"(truth {value:g}: {(fit['value'] - value) / fit['std']:+.1f} sigma)")
        print(f"  load average after: {os.getloadavg()[0]:.2f}")


def _cpu_seconds() -> float:
    """CPU time (s) of this process and its finished children (the worker pool): on a shared machine the
    wall time is an upper bound, the CPU time what the work costs (wall on 2 idle cores >= CPU / 2)."""
    import resource

    return sum(resource.getrusage(who).ru_utime + resource.getrusage(who).ru_stime
               for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))


def _towing_case_copy(folder: Path) -> Path:
    """cases/diagnose_towing.toml copied into ``folder`` with the towing case it names (a case names
    its files relative to itself)."""
    case = folder / "diagnose_towing.toml"
    case.write_text((ROOT / "cases" / case.name).read_text())
    shutil.copyfile(ROOT / "cases" / "zenit2_towing.toml", folder / "zenit2_towing.toml")
    return case


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--only", nargs="*", help="case file names to run (default: all)")
    parser.add_argument("--towing-truths", action="store_true",
                        help="instead: viscoelastic tethers other than the sample's, fitted against their truth")
    args = parser.parse_args()
    if args.towing_truths:
        towing_truths(args.workers)
        return
    tic = time.perf_counter()
    from riskassess.stages.diagnose import diagnose_case   # numba compiled code loads from its cache here
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
            case = ROOT / "cases" / case_name  # diagnose writes only under its output folder
            tic, cpu = time.perf_counter(), _cpu_seconds()
            answer = diagnose_case(case, ROOT / "cases" / "data" / data_name, Path(tmp) / "out", workers=args.workers)
            wall, cpu = time.perf_counter() - tic, _cpu_seconds() - cpu
        print(f"\n{case_name} + {data_name}: {answer['samples']} samples, {len(answer['channels']['used'])} channels, "
              f"{len(answer['candidates'])} candidates fitted, {len(answer['not_applicable'])} not applicable")
        print(f"  wall {wall:.1f} s (goal < 120 s); CPU {cpu:.1f} s in all processes; nominal fit "
              f"{answer['nominal']['fit_seconds']:.1f} s")
        for row in answer["candidates"]:
            print(f"  {row['id']:28s} fit {row['fit_seconds']:6.1f} s  evaluations {row['evaluations']:4d}  "
                  f"delta BIC {row['delta_bic']:12.1f}")
        print(f"  cause: {answer['cause']} (confidence {answer['confidence']}); gain {answer['gain_percent']['overall']:.1f} %")
        print("  parameters: " + ", ".join(f"{k} = {v['value']:.4g} +- {v['std']:.2g} {v['unit']}"
                                         for k, v in answer["parameters"].items()))
        print(f"  load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
