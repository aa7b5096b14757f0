"""What the capture's settle test costs a whole-capture run, per window of simulated time, without the simulation.

    python3 bench/bench_capture_monitor.py CASE [--end-time 420] [--windows 0,60,120,200,300,420] [--seed 0]

Builds the case's :class:`structures.capture_window.CaptureMonitor` as a run does
(:func:`riskassess.stages.run.capture_monitor`: its weak locations, net masses, reference body, the output rate)
and feeds it what the recorder hands it: every output sample's joint loads (:meth:`~CaptureMonitor.sample`, the
case's ``output_rate``) and every net snapshot (:meth:`~CaptureMonitor.snapshot`, ``net_output_rate``), here drawn
from a generator (loads of some 10-100 N and N m, a net moving at 0.1 m/s relative to the debris, so that the
capture never settles and the test runs to the end, as a run capped at its end time does). Prints per window the
CPU time (``time.process_time``) in us per integration step (the case's ``simulation.step``), the figure
``bench/bench_capture_cost.py`` prints as ``capture`` for a real run, and how many snapshots the monitor holds.

Until helper speed22 (2026-11-28) every settle check (every 0.1 s) ran :func:`~structures.capture_window.settle_time`
over the whole history of snapshots (50 a simulated second), so a check cost in proportion to the simulated time and
the monitor's share of a step grew through a capture; and every sample stacked its loads into a new array.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from riskassess.cases.impact import load_case
from riskassess.models.impact import model_inputs, weak_locations
from riskassess.stages.run import capture_monitor


def feed(monitor, n_joints: int, n_nodes: int, end_time: float, output_interval: float, net_interval: float,
         edges, rng) -> tuple:
    """Feed ``monitor`` samples and snapshots up to ``end_time`` (s); returns the CPU time (s) spent in its two
    methods per window of ``edges`` and whether it ever answered "over"."""
    cpu = np.zeros(len(edges) - 1)
    per_snapshot = int(round(net_interval / output_interval))
    positions_lvlh = rng.normal(0.0, 3.0, (n_nodes, 3))
    com_lvlh, velocity_lvlh = np.zeros((1, 3)), np.zeros((1, 3))
    body_to_lvlh, omega_body = np.eye(3)[None], np.zeros((1, 3))
    over = False
    n_samples = int(round(end_time / output_interval))
    for k in range(1, n_samples + 1):
        t = k * output_interval
        force_joint = rng.normal(0.0, 100.0, (n_joints, 3))
        moment_joint = rng.normal(0.0, 10.0, (n_joints, 3))
        velocities_lvlh = rng.normal(0.0, 0.1, (n_nodes, 3)).astype(np.float32)
        w = min(int(np.searchsorted(edges, t, side="right")) - 1, len(cpu) - 1)
        start = time.process_time()
        monitor.sample(t, force_joint, moment_joint)
        if k % per_snapshot == 0:
            over = monitor.snapshot(t, positions_lvlh, velocities_lvlh, com_lvlh, velocity_lvlh, body_to_lvlh,
                                    omega_body) or over
        cpu[w] += time.process_time() - start
    return cpu, over


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("--end-time", type=float, default=420.0)
    parser.add_argument("--windows", default="0,60,120,200,300,420")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    case_path = Path(args.case)
    case = load_case(case_path)
    inputs = model_inputs(case, case_path.parent)
    assembly = inputs.assembly
    locations = weak_locations(case, assembly)
    monitor = capture_monitor(case, locations, assembly)
    if monitor is None:
        raise SystemExit(f"{case_path}: the case does not judge the capture (structures.window)")
    monitor.body = 0     # the generator's one body
    edges = [e for e in (float(v) for v in args.windows.split(",")) if e < args.end_time] + [args.end_time]
    load = os.getloadavg()[0]
    cpu, over = feed(monitor, len(assembly.joints), assembly.net.n_nodes, args.end_time,
                     1.0 / case.simulation.output_rate, 1.0 / case.simulation.net_output_rate, edges,
                     np.random.default_rng(args.seed))
    step = case.simulation.step
    print(f"{case_path.name}: {len(locations)} locations, {len(assembly.joints)} joints, {assembly.net.n_nodes} nodes, "
          f"step {step:g} s, load average {load:.2f} -> {os.getloadavg()[0]:.2f}; settled: {over}")
    print(f"{'window (s)':>14} {'CPU (s)':>8} {'us a step':>10}")
    for k in range(len(cpu)):
        steps = (edges[k + 1] - edges[k]) / step
        print(f"{edges[k]:6.1f}-{edges[k + 1]:6.1f} {cpu[k]:8.3f} {1e6 * cpu[k] / steps:10.3f}")
    print(f"whole: {cpu.sum():.2f} s CPU, {1e6 * cpu.sum() / (args.end_time / step):.3f} us a step; "
          f"{len(monitor.energy_time)} snapshots held")


if __name__ == "__main__":
    main()
