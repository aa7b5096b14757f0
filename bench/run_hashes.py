"""Bit-identity check of a code change: hashes of everything a reference run records.

Usage: python3 bench/run_hashes.py [END_TIME] [--load-filter HZ]

Runs the reference case (``cases/envisat_net_impact.toml``, 35 x 35, kernel path) to END_TIME (s, default 0.3) and
prints a hash of every time series (keys and values), of the net snapshots and of Exudyn's end state, with the CPU
time of the run, and a hash of the series less the booked energies (:data:`BOOKED_ENERGIES`). Two versions of the
code that print the same hashes computed the same run to the last bit (docs/model.md, Speed). ``--load-filter HZ``
gives every joint a load filter at HZ (:mod:`multibody.load_filter`) and also prints the hash of the series less
the filtered loads' columns: a recording, so it must equal the run's without the filter.
"""
from __future__ import annotations

import hashlib
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script
from bench_impact import sized_inputs  # noqa: E402

from multibody.impact import ImpactSimulation  # noqa: E402
from multibody.recorder import FILTERED_LOADS  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: The series a change of the energy booking alone changes (helper thread14 booked the clipped threads' loss, helper
#: joints15 the joints' dampers).
BOOKED_ENERGIES = ("energy_dissipated_threads", "energy_dissipated_joints", "energy_total")


def digest(arrays) -> str:
    """First 12 hex digits of the sha256 of ``arrays`` (name, array) pairs, names and bytes in order."""
    h = hashlib.sha256()
    for name, array in arrays:
        h.update(name.encode())
        h.update(np.ascontiguousarray(array).tobytes())
    return h.hexdigest()[:12]


def main():
    args = sys.argv[1:]
    cutoff_hz = 0.0
    if "--load-filter" in args:
        k = args.index("--load-filter")
        cutoff_hz = float(args[k + 1])
        del args[k:k + 2]
    end_time = float(args[0]) if args else 0.3
    _, inputs = sized_inputs(ROOT / "cases" / "envisat_net_impact.toml", 35, end_time, "kernel")
    for joint in inputs.assembly.joints:
        joint.load_filter_hz = cutoff_hz
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    start = time.process_time()
    recorder = sim.run()
    cpu = time.process_time() - start
    data = sim.system.mbs.systemData
    state = [("q", np.array(data.GetODE2Coordinates())), ("qt", np.array(data.GetODE2Coordinates_t()))]
    print(f"end {end_time:g} s: series {digest(recorder.series.items())} ({len(recorder.series)} keys, "
          f"{len(recorder.series['time'])} rows), net {digest(recorder.net.items())}, bodies {digest(state)}; "
          f"CPU {cpu:.2f} s (with compilation if the sources changed), load {os.getloadavg()[0]:.2f}")
    motion = [(key, value) for key, value in recorder.series.items() if key not in BOOKED_ENERGIES]
    print(f"   series less {', '.join(BOOKED_ENERGIES)} (the dynamics without the energy booking): {digest(motion)}")
    if cutoff_hz:
        unfiltered = [(key, value) for key, value in recorder.series.items() if key not in FILTERED_LOADS]
        print(f"   series less the filtered loads ({cutoff_hz:g} Hz; {', '.join(FILTERED_LOADS)}): {digest(unfiltered)}")


if __name__ == "__main__":
    main()
