"""Where a reference run's CPU time goes, per step: the kernel, the recorder's samples, the rest of the hook, Exudyn.

Usage: python3 bench/step_split.py [END_TIME]

Runs the reference case (``cases/envisat_net_impact.toml``, 35 x 35, kernel path) to END_TIME (s, default 2) after
a short warm-up, with ``time.process_time`` around the pre-step hook (:class:`multibody.kernel_net.KernelNet`), the
compiled step inside it and each recorder sample, and prints us of CPU a step: total, hook, kernel, samples (and
per sample), Exudyn with the rest outside the hook, and the hook's glue (hook - kernel - samples, with the timers'
own cost, about 2 us a step). Used for the A/B pairs of docs/model.md, Speed (helper "speed5").
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script
from bench_impact import sized_inputs  # noqa: E402

import multibody.kernel_net as kernel_net_module  # noqa: E402
import multibody.recorder as recorder_module  # noqa: E402
from multibody.impact import ImpactSimulation  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def timed_run(end_time: float) -> dict:
    """CPU seconds of the run to ``end_time`` (s) and of its parts; the number of steps and samples."""
    spent = {"hook": 0.0, "kernel": 0.0, "sample": 0.0, "steps": 0, "samples": 0}
    clock = time.process_time
    step_function, call, sample = (kernel_net_module.kernel_net_step, kernel_net_module.KernelNet.__call__,
                                   recorder_module.Recorder.sample)

    def timed_step(*args):
        start = clock()
        result = step_function(*args)   # older trees return the bodies' forces (for "before" figures)
        spent["kernel"] += clock() - start
        return result

    def timed_call(self, mbs, t):
        start = clock()
        keep = call(self, mbs, t)
        spent["hook"] += clock() - start
        spent["steps"] += 1
        return keep

    def timed_sample(self, t):
        start = clock()
        sample(self, t)
        spent["sample"] += clock() - start
        spent["samples"] += 1

    kernel_net_module.kernel_net_step = timed_step
    kernel_net_module.KernelNet.__call__ = timed_call
    recorder_module.Recorder.sample = timed_sample
    try:
        _, inputs = sized_inputs(ROOT / "cases" / "envisat_net_impact.toml", 35, end_time, "kernel")
        sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
        for key in spent:
            spent[key] = 0 * spent[key]
        start = clock()
        sim.run()
        spent["total"] = clock() - start
    finally:
        kernel_net_module.kernel_net_step = step_function
        kernel_net_module.KernelNet.__call__ = call
        recorder_module.Recorder.sample = sample
    return spent


def main():
    end_time = float(sys.argv[1]) if len(sys.argv) > 1 else 2.0
    timed_run(0.002)  # numba loads (or compiles) its kernels
    s = timed_run(end_time)
    n = s["steps"]
    us = 1e6 / n
    print(f"end {end_time:g} s: total {s['total']:.3f} s CPU, {s['total'] * us:.1f} us/step; hook {s['hook'] * us:.1f}; "
          f"kernel {s['kernel'] * us:.1f}; samples {s['sample'] * us:.1f} us/step ({s['sample'] / max(s['samples'], 1) * 1e6:.1f} "
          f"us each, {s['samples']}); exudyn+rest {(s['total'] - s['hook']) * us:.1f}; "
          f"glue {(s['hook'] - s['kernel'] - s['sample']) * us:.1f}; load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
