"""Benchmark: the full reference case (35 x 35 net, 7.5 s, coupled), wall time and steps/s.

Usage: python3 bench/bench_impact.py [CASE] [--end-time T]
"""
from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

from riskassess.assemble import model_inputs
from riskassess.case import load_case
from riskassess.summary import run_summary
from multibody.impact import ImpactSimulation

ROOT = Path(__file__).resolve().parents[1]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_net_impact.toml"))
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--step", type=float, default=None)
    args = parser.parse_args()
    case = load_case(args.case)
    inputs = model_inputs(case, Path(args.case).parent)
    solver = inputs.assembly.solver
    if args.end_time or args.step:
        solver = dataclasses.replace(solver, end_time=args.end_time or solver.end_time, step=args.step or solver.step)
        inputs.assembly.solver = solver
    # Warm-up: numba compiles (or loads its cache) on the first force evaluation.
    warm = dataclasses.replace(inputs.assembly, solver=dataclasses.replace(solver, end_time=10 * solver.step))
    ImpactSimulation(warm, inputs.rest_attitudes, inputs.rest_coms).run()
    t0 = time.perf_counter()
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    build = time.perf_counter() - t0
    rec = sim.run()
    s = run_summary(rec, sim.assembly, case.name)
    n = sim.assembly.net.n_nodes
    print(f"case                 {case.name}: {n} net nodes, {len(sim.assembly.bodies)} bodies, "
          f"{len(sim.assembly.joints)} joints")
    print(f"simulated            {solver.end_time:g} s in {solver.n_steps} steps of {solver.step:g} s ({solver.integrator})")
    print(f"build time           {build:.2f} s")
    print(f"wall time            {rec.wall_time:.1f} s")
    print(f"steps per second     {solver.n_steps / rec.wall_time:.0f}")
    print(f"time per step        {rec.wall_time / solver.n_steps * 1e3:.3f} ms")
    print(f"peak contact force   {s['peak_contact_force_N']['value']:.4g} N at {s['peak_contact_force_N']['time_s']:.3f} s")
    print(f"peak contact moment  {s['peak_contact_moment_about_debris_com_Nm']['value']:.4g} N m")
    print(f"energy balance drift {s['checks']['energy_balance_relative_drift']:.2e}")


if __name__ == "__main__":
    main()
