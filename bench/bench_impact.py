"""Benchmark: the coupled impact at several net sizes, against a plain Exudyn spring net of the same size.

Usage: python3 bench/bench_impact.py [CASE] [--sizes 15 35 51 101] [--end-times 7.5 7.5 1 0.2]
                                     [--net-integration kernel|exudyn] [--repeat 1]

For each net size (nodes per side) the reference case (default ``cases/envisat_net_impact.toml``:
Envisat mock-up, 20 m/s, orbit on) is run with that net (same side length and thread material, so the
node mass falls and the thread stiffness grows with the size; the step is the case's, or half the
threads' stable step when that is smaller, see multibody.impact.net_stable_step), simulation only (no
output folder). Printed per size: wall time, CPU time of the solve (``time.process_time``, less
sensitive to a shared machine's load), us per step (wall), ns per node-step, and the ratio to a plain
Exudyn net of the same nodes and threads (``NodePoint`` masses, linear ``ObjectConnectorSpringDamper``
threads, no contact, no bodies, VelocityVerlet, sparse solver with the per-body mass inverse: the
fastest all-Exudyn set-up of EXUDYN-NOTES) built and timed in the same process. The machine's load
(``os.getloadavg``) is printed with every figure: timings on a shared machine are only comparable at
the same load. ``--repeat`` runs each size several times and keeps the fastest.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import time
from pathlib import Path

import exudyn as exu
from exudyn.itemInterface import (
    MarkerNodePosition,
    NodePoint,
    ObjectConnectorSpringDamper,
    ObjectMassPoint,
)

from multibody.impact import ImpactSimulation, net_stable_step
from multibody.solver_output import solver_chatter_captured
from riskassess.models.impact import model_inputs
from riskassess.cases.impact import load_case
from riskassess.products.summary import run_summary

ROOT = Path(__file__).resolve().parents[1]


def load() -> str:
    return f"load {os.getloadavg()[0]:.2f}"


def sized_inputs(case_path: Path, nodes_per_side: int, end_time: float, net_integration: str):
    """The case with ``nodes_per_side`` nodes per side, ``end_time`` (s) and a stable step."""
    case = load_case(case_path)
    net = case.net.model_copy(update={"nodes_per_side": nodes_per_side})
    simulation = {"end_time": end_time}
    if "net_integration" in type(case.simulation).model_fields:  # absent in older trees (for "before" figures)
        simulation["net_integration"] = net_integration
    case = case.model_copy(update={"net": net, "simulation": case.simulation.model_copy(update=simulation)})
    inputs = model_inputs(case, case_path.parent)
    step = min(case.simulation.step, 0.5 * net_stable_step(inputs.assembly.net))
    step = float(f"{step:.2g}")
    inputs.assembly.solver = dataclasses.replace(inputs.assembly.solver, step=step, end_time=end_time)
    return case, inputs


def time_impact(case_path, nodes_per_side, end_time, net_integration, repeat):
    case, inputs = sized_inputs(case_path, nodes_per_side, end_time, net_integration)
    solver = inputs.assembly.solver
    warm = dataclasses.replace(inputs.assembly, solver=dataclasses.replace(solver, end_time=10 * solver.step))
    ImpactSimulation(warm, inputs.rest_attitudes, inputs.rest_coms).run()  # numba compiles or loads its cache
    best = None
    for _ in range(repeat):
        sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
        cpu_start = time.process_time()
        recorder = sim.run()
        cpu = time.process_time() - cpu_start
        if best is None or recorder.wall_time < best[1].wall_time:
            best = (sim, recorder, load(), cpu)
    return case, best


def plain_exudyn_net(net, step: float, n_steps: int) -> float:
    """Wall time (s) per step of the net's nodes and threads alone in Exudyn (see the module doc)."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    markers = []
    for position, mass in zip(net.positions, net.masses):
        node = mbs.AddNode(NodePoint(referenceCoordinates=list(position), initialVelocities=[0.0, 20.0, 0.0]))
        mbs.AddObject(ObjectMassPoint(nodeNumber=node, mass=float(mass)))
        markers.append(mbs.AddMarker(MarkerNodePosition(nodeNumber=node)))
    for (a, b), rest, k, c in zip(net.threads, net.rest_lengths, net.stiffness, net.damping):
        mbs.AddObject(ObjectConnectorSpringDamper(markerNumbers=[markers[a], markers[b]], referenceLength=float(rest),
                                                  stiffness=float(k), damping=float(c)))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.timeIntegration.endTime = n_steps * step
    s.timeIntegration.numberOfSteps = n_steps
    s.timeIntegration.verboseMode = 0
    s.timeIntegration.explicit.computeEndOfStepAccelerations = False
    s.timeIntegration.explicit.computeMassMatrixInversePerBody = True
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.solution.file.write = False
    s.solution.sensors.active = False
    start = time.perf_counter()
    with solver_chatter_captured():
        exu.SolveDynamic(mbs, s, solverType=exu.DynamicSolverType.VelocityVerlet)
    return (time.perf_counter() - start) / n_steps


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_net_impact.toml"))
    parser.add_argument("--sizes", type=int, nargs="+", default=[15, 35, 51, 101])
    parser.add_argument("--end-times", type=float, nargs="+", default=[7.5, 7.5, 1.0, 0.2])
    parser.add_argument("--net-integration", choices=["kernel", "exudyn"], default="kernel")
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    case_path = Path(args.case)
    end_times = (args.end_times + args.end_times[-1:] * len(args.sizes))[:len(args.sizes)]
    print(f"{'net':>8} {'nodes':>6} {'end s':>6} {'step s':>8} {'wall s':>8} {'cpu s':>7} {'us/step':>8} "
          f"{'ns/node-step':>12} {'plain us/step':>13} {'ratio':>6}  machine")
    for size, end_time in zip(args.sizes, end_times):
        case, (sim, rec, machine, cpu) = time_impact(case_path, size, end_time, args.net_integration, args.repeat)
        solver = sim.assembly.solver
        n = sim.assembly.net.n_nodes
        per_step = rec.wall_time / solver.n_steps
        plain = plain_exudyn_net(sim.assembly.net, solver.step, max(200, min(2000, int(2e6 / n))))
        print(f"{size:>4}x{size:<3} {n:>6} {end_time:>6g} {solver.step:>8.2g} {rec.wall_time:>8.2f} {cpu:>7.2f} "
              f"{per_step * 1e6:>8.1f} "
              f"{per_step / n * 1e9:>12.1f} {plain * 1e6:>13.1f} {per_step / plain:>6.2f}  {machine}, "
              f"plain {load()}")
        if size == 35 and end_time == case.simulation.end_time:
            s = run_summary(rec, sim.assembly, case.name)
            print(f"         reference case: energy balance drift {s['checks']['energy_balance_relative_drift']:.2e}, "
                  f"peak contact force {s['peak_contact_force_N']['value']:.4g} N")


if __name__ == "__main__":
    main()
