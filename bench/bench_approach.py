"""Solve every approach case file (cases/approach_*.toml): solve time, final time, fuel, the
constraint margins on the re-simulation and the relative difference to the paper's figures.

    python3 bench/bench_approach.py [CASE ...]

Timings are the wall and CPU (process) times of the IPOPT solve alone; the wall time includes
whatever else runs on the machine.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

from riskassess.stages.approach import solve_case
from riskassess.cases.approach import ApproachCase
from riskassess.cases.impact import load_model


def _relative(reference, key):
    if not reference or key not in reference:
        return "-"
    return f"{100 * reference[key + '_relative_difference']:+.1f}%"


def main(paths) -> None:
    paths = paths or sorted(str(p) for p in (Path(__file__).parents[1] / "cases").glob("approach_*.toml"))
    print(f"{'case':28s} {'status':26s} {'solve s':>7s} {'cpu s':>6s} {'iter':>5s} {'t_f s':>8s} {'fuel kg':>8s} "
          f"{'keep-out m':>10s} {'width m':>8s} {'miss m':>7s} {'ok':>3s} {'t_f vs paper':>12s} "
          f"{'fuel vs paper':>13s} {'paper solve s':>13s}")
    for path in paths:
        case = load_model(path, ApproachCase)
        tic = time.perf_counter()
        answer, _, _ = solve_case(case, path)
        fine, ref = answer["constraints_resimulated"], answer["reference"]
        width = f"{fine['width_margin_m']:.4f}" if "width_margin_m" in fine else "-"
        print(f"{case.name:28s} {answer['solver_status']:26s} {answer['solve_s']:7.2f} {answer['solve_cpu_s']:6.2f} {answer['iterations']:5d} "
              f"{answer['final_time']:8.4f} {answer['fuel_kg']:8.5f} {fine['keep_out_margin_m']:10.4f} {width:>8s} "
              f"{fine['final_mouth_miss_m']:7.4f} {'yes' if answer['constraints_satisfied'] else 'NO':>3s} "
              f"{_relative(ref, 'final_time'):>12s} {_relative(ref, 'fuel_kg'):>13s} "
              f"{str(ref.get('solve_s', '-')) if ref else '-':>13}  (stage {time.perf_counter() - tic:.1f} s)")


if __name__ == "__main__":
    main(sys.argv[1:])
