"""Sec. 4.3 identification benchmark (Boonrath, Singh & Botta 2024) on cases/zenit2_towing.toml:
data from the lower-order model with s_true = [2, 7, 2, 1] at the 10 Table 3 training rates over
the whole 275 s tow; identified by pymoo's PSO (then polished by the pattern search) and by the
pattern search from the paper's s0 = [1, 6, 3, 0.25]. Simulations run on ``identification.workers``
processes.

    python bench/bench_identify.py [--optimizers pso pattern] [--swarm 20] [--generations 12]
                                   [--polish 300] [--pattern 540]

Prints per optimizer: s, cost, largest relative error against s_true, evaluations, wall time.
Goal (issue 7): every s within 1e-3 relative, < 10 min on 2 cores. Timings are upper bounds when
other jobs share the machine.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from riskassess.case import load_model
from riskassess.identify import benchmark
from riskassess.towing_case import TowingCase


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--optimizers", nargs="+", default=["pso", "pattern"], choices=["pso", "pattern"])
    parser.add_argument("--swarm", type=int, default=20)
    parser.add_argument("--generations", type=int, default=12)
    parser.add_argument("--polish", type=int, default=300)
    parser.add_argument("--pattern", type=int, default=540)
    args = parser.parse_args()
    case = load_model(args.case, TowingCase)
    ident = case.identification
    settings = ident.optimizers.model_copy(update=dict(swarm_size=args.swarm, pso_generations=args.generations,
                                                       polish_evaluations=args.polish, pattern_evaluations=args.pattern))
    case = case.model_copy(update=dict(identification=ident.model_copy(update=dict(optimizers=settings))))
    start = time.perf_counter()
    out = benchmark(case, optimizers=tuple(args.optimizers))
    print(f"data: {len(out['rates_deg_s'])} runs of {case.simulation.end_time - case.simulation.start_time:g} s "
          f"(step {ident.step * 1e3:g} ms) in {out['data_wall_s']:.1f} s; s_true = {out['truth']}, cost {out['cost_function']}")
    for name, run in out["runs"].items():
        print(f"  {name:12s} s = {np.round(run['s'], 5).tolist()} cost {run['cost']:.3e} max rel. error "
              f"{max(run['relative_error']):.2e} ({np.array(run['relative_error']).round(5).tolist()}) "
              f"{run['evaluations']} evaluations {run['wall_s']:.0f} s wall")
    print(f"total {time.perf_counter() - start:.0f} s wall")


if __name__ == "__main__":
    main()
