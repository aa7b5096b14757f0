"""Profile the reference case by sampling, with numba's compiled functions named: run it under ``perf``.

Usage: perf record -e cpu-clock -F 2000 -o perf.data python3 bench/perf_profile.py [END_TIME]
       perf report -i perf.data --no-children --sort sym --time 35%-97%

Runs the reference case (``cases/envisat_net_impact.toml``) to END_TIME (s, default 7.5) after a short warm-up
run (numba loads or compiles its kernels), then writes ``/tmp/perf-<pid>.map``, the file ``perf report`` reads
to name code in anonymous memory: every symbol numba's JIT engine defined, at its address, each assumed to
run to the next symbol (numba's ``NUMBA_ENABLE_PROFILING`` wrote no map for kernels loaded from its cache).
``cpu-clock`` is a software event, so this works on machines without hardware counters. ``--time`` keeps
the samples of the solve (the warm-up, imports and compilation come first). docs/model.md, Speed (helper
"speed4") has a profile made so.
"""
from __future__ import annotations

import gc
import os
import sys
from pathlib import Path

from numba.core.registry import CPUDispatcher

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script
from bench_impact import sized_inputs

from multibody.impact import ImpactSimulation

ROOT = Path(__file__).resolve().parents[1]


def run(end_time: float) -> None:
    """The reference case to ``end_time`` (s), simulation only."""
    _, inputs = sized_inputs(ROOT / "cases" / "envisat_net_impact.toml", 35, end_time, "kernel")
    ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms).run()


def write_perf_map() -> int:
    """Write ``/tmp/perf-<pid>.map`` for every function numba's JIT engines hold; returns how many."""
    engines = {}
    for obj in gc.get_objects():
        if isinstance(obj, CPUDispatcher):
            for result in obj.overloads.values():
                engine = result.library._codegen._engine
                engines[id(engine)] = engine
    addresses = {}
    for engine in engines.values():
        for name in list(engine._defined_symbols):
            address = engine.get_function_address(name)
            if address:
                addresses[address] = name
    ordered = sorted(addresses)
    with open(f"/tmp/perf-{os.getpid()}.map", "w") as out:
        for k, address in enumerate(ordered):
            size = min(ordered[k + 1] - address, 1 << 20) if k + 1 < len(ordered) else 4096
            out.write(f"{address:x} {size:x} {addresses[address]}\n")
    return len(ordered)


def main():
    end_time = float(sys.argv[1]) if len(sys.argv) > 1 else 7.5
    run(0.002)
    run(end_time)
    print(f"{write_perf_map()} symbols in /tmp/perf-{os.getpid()}.map", flush=True)


if __name__ == "__main__":
    main()
