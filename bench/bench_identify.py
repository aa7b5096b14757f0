"""Sec. 4.3 identification benchmark (Boonrath, Singh & Botta 2024) on cases/zenit2_towing.toml:
data from the lower-order model with s_true = [2, 7, 2, 1] at the 10 Table 3 training rates over
the whole 275 s tow; identified by pymoo's PSO (then polished by the pattern search) and by the
pattern search from the paper's s0 = [1, 6, 3, 0.25]. Simulations run on ``identification.workers``
processes.

    python bench/bench_identify.py [--optimizers pso pattern mads] [--swarm N] [--generations N]
                                   [--polish N] [--pattern N] [--restart N] [--tolerance X]
                                   [--truth S1 S2 S3 S4]

(defaults: the case's ``[identification.optimizers]``). Prints the CPU time of one evaluation (its
10 runs, one after the other, in this process), then per optimizer: s, cost, largest relative error
against s_true, evaluations, wall time, and the load average before and after. Goal: every s
within 1e-3 relative, < 10 min on 2 cores. Timings are upper bounds when other jobs share the machine
(the load average says how much).
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from riskassess.cases.impact import load_model
from riskassess.stages.identify import benchmark, simulate
from riskassess.cases.towing import Optimizers, TowingCase


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--optimizers", nargs="+", default=["pso", "pattern"], choices=["pso", "pattern", "mads"])
    for flag, key, kind in (("--swarm", "swarm_size", int), ("--generations", "pso_generations", int),
                            ("--polish", "polish_evaluations", int), ("--pattern", "pattern_evaluations", int),
                            ("--restart", "restart_evaluations", int), ("--tolerance", "pattern_tolerance", float),
                            ("--mads", "mads_evaluations", int)):
        parser.add_argument(flag, dest=key, type=kind, default=None)
    parser.add_argument("--truth", type=float, nargs=4, default=None,
                        help="s of the data instead of the case's benchmark_truth (a robustness check off the paper's s)")
    args = parser.parse_args()
    case = load_model(args.case, TowingCase)
    ident = case.identification
    update = {key: value for key, value in vars(args).items() if key in Optimizers.model_fields and value is not None}
    settings = ident.optimizers.model_copy(update=update)
    truth = ident.benchmark_truth if args.truth is None else args.truth
    ident = ident.model_copy(update=dict(optimizers=settings, benchmark_truth=truth))
    case = case.model_copy(update=dict(identification=ident))
    print(f"settings: {settings.model_dump()}; load average {os.getloadavg()[0]:.1f}")
    simulate(case, case.rates.training_deg_s[0], ident.benchmark_truth)  # compiled code loaded
    cpu = time.process_time()
    for rate in case.rates.training_deg_s:
        simulate(case, rate, ident.benchmark_truth)
    print(f"one evaluation (10 runs of the twin, serial): {time.process_time() - cpu:.2f} s CPU")
    start = time.perf_counter()
    out = benchmark(case, optimizers=tuple(args.optimizers))
    print(f"data: {len(out['rates_deg_s'])} runs of {case.simulation.end_time - case.simulation.start_time:g} s "
          f"(step {ident.step * 1e3:g} ms) in {out['data_wall_s']:.1f} s; s_true = {out['truth']}, cost {out['cost_function']}")
    for name, run in out["runs"].items():
        print(f"  {name:12s} s = {np.round(run['s'], 5).tolist()} cost {run['cost']:.3e} max rel. error "
              f"{max(run['relative_error']):.2e} ({np.array(run['relative_error']).round(5).tolist()}) "
              f"{run['evaluations']} evaluations {run['wall_s']:.0f} s wall")
    print(f"total {time.perf_counter() - start:.0f} s wall; load average now {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
