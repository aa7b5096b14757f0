"""Benchmark: the compiled net step alone, on one frozen state of the reference case (load-robust A/B).

Usage: python3 bench/bench_kernel_step.py [T0 ...] [--steps 200] [--repeat 15]

Runs the reference case (``cases/envisat_net_impact.toml``) to ``T0`` (s), freezes the bodies there, and times
``--steps`` calls of :func:`multibody.kernel_net.kernel_net_step` (threads, broad phase, contact, the net's
Verlet update; no Exudyn, no recorder) from the same snapshot ``--repeat`` times, printing the fastest in us
per step (CPU time) and a hash of the end state. Two versions of the code that give the same results end in
the same state from the same snapshot, so they do the same work: on a shared machine, where whole runs
swing by tens of percent, the minimum over repeats of this fixed workload is the fairer comparison
(docs/model.md, Speed). No hardware counters are needed.
"""
from __future__ import annotations

import argparse
import hashlib
import inspect
import os
import sys
import time
from pathlib import Path

import numpy as np

import multibody.kernel_net as kernel_net_module
from multibody.impact import ImpactSimulation

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_impact import sized_inputs  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def captured_state_model():
    """Patch the structref's constructor so the run's net state arrays can be saved and restored (the cached
    constructor ``_new_net_step_model`` since helper speed20, the proxy class in older trees)."""
    captured = []
    name = "_new_net_step_model" if hasattr(kernel_net_module, "_new_net_step_model") else "NetStepModel"
    original = getattr(kernel_net_module, name)

    def capture(*args):
        captured.append(args)
        return original(*args)

    setattr(kernel_net_module, name, capture)
    return captured


def time_frozen_steps(t0: float, steps: int, repeat: int) -> tuple[float, str]:
    """Fastest CPU time (s) of ``steps`` kernel steps from the state at ``t0`` (s), and an end-state hash."""
    captured = captured_state_model()
    _, inputs = sized_inputs(ROOT / "cases" / "envisat_net_impact.toml", 35, t0, "kernel")
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    sim.run()
    net = sim.system.kernel_net
    data = sim.system.mbs.systemData
    q_bodies, qt_bodies, qtt_bodies = (np.array(net._bodies(get())) for get in (
        data.GetODE2Coordinates, data.GetODE2Coordinates_t, data.GetODE2Coordinates_tt))
    state = ([a for a in captured[-1] if isinstance(a, np.ndarray)]
             + [a for a in sim.system.kernel.buffers if isinstance(a, np.ndarray)])
    saved = [a.copy() for a in state]
    step = inputs.assembly.solver.step
    best = np.inf
    # the output arguments after the time: the bodies' end state, their forces (absent in older trees, for
    # "before" figures)
    n_outputs = len(inspect.signature(kernel_net_module.kernel_net_step.py_func).parameters) - 5
    extra = tuple(np.zeros_like(q_bodies) for _ in range(n_outputs))
    for _ in range(repeat):
        for array, snapshot in zip(state, saved):
            array[...] = snapshot
        start = time.process_time()
        for k in range(steps):
            kernel_net_module.kernel_net_step(net.model, q_bodies, qt_bodies, qtt_bodies, t0 + (k + 1) * step, *extra)
        best = min(best, time.process_time() - start)
    # positions and velocities (n, 3): the same hash whatever layout the kernel keeps its state in
    digest = hashlib.sha256(np.concatenate([net.positions(), net.velocities()]).tobytes()).hexdigest()[:12]
    return best, digest


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("t0", type=float, nargs="*", default=[0.3, 2.0])
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=15)
    args = parser.parse_args()
    for t0 in args.t0:
        best, digest = time_frozen_steps(t0, args.steps, args.repeat)
        print(f"t0 {t0:g} s: kernel {best / args.steps * 1e6:.1f} us/step (CPU, min of {args.repeat} x {args.steps}), "
              f"end state {digest}, load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
