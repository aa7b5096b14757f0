"""Why the Ka-band dish root's first-second shear differs between the sequential and the coupled run.

    python3 bench/bench_held_loads_kaband.py

The sequential method drives the free debris with the wall run's contact loads as interval means held over
each output interval (1 ms at the case's 1 kHz): a load that steps every interval. This bench runs the first
second of ``cases/envisat_paper_sequential.toml`` in both modes at 1 kHz and at 5 kHz output (held steps of
0.2 ms), two replicas each (launch speed x 1 and x (1 + 1e-7)), and prints the dish root's peak shear stress over
0.25-1 s and the net's contact impulse on the Ka-band: if the held steps excite the penalty joints' ringing,
the sequential excess shrinks at 5 kHz while the contact on the Ka-band stays the same. Results in
``bench/results/held_loads_kaband.json``.
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_coupling_replicas import CASE, ROOT, replica_case  # noqa: E402

from riskassess.stages.run import run_case  # noqa: E402

STORE = ROOT / "bench" / "results" / "held_loads_kaband.json"


def one(mode: str, rate: float, k: int) -> dict:
    """The first second in ``mode`` at ``rate`` (Hz) output, launch speed x (1 + k 1e-7): the dish root's peaks."""
    case = replica_case(mode, k, output_rate=rate, end_time=1.0)
    cpu, load = time.process_time(), os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        run_case(CASE, Path(tmp) / "run", case=case)
        demands = np.load(Path(tmp) / "run" / "structures.npz")
        s = np.load(Path(tmp) / "run" / ("wall_timeseries.npz" if mode == "sequential" else "timeseries.npz"))
    t = demands["time"]
    judged = (t >= 0.25) & (t <= 1.0)
    dt = np.diff(s["time"], prepend=0.0)
    return {"dish root shear 0.25-1 s (MPa)": 1e-6 * float(np.abs(demands["ka_band_dish_root/shear_stress"][judged]).max()),
            "dish root normal 0.25-1 s (MPa)": 1e-6 * float(np.abs(demands["ka_band_dish_root/normal_stress"][judged]).max()),
            "contact impulse on bodies 3-4 (Ka-band), sum |F| dt (N s)": float(
                (np.linalg.norm(s["contact_force_lvlh"][:, 3:5].sum(axis=1), axis=1) * dt).sum()),
            "cpu (s)": time.process_time() - cpu, "load": load}


def main() -> None:
    store = json.loads(STORE.read_text()) if STORE.exists() else {}
    for rate in (1000.0, 5000.0):
        for mode in ("sequential", "coupled"):
            for k in (0, 1):
                key = f"{mode}|{rate:g} Hz|{k:+d}"
                if key not in store:
                    store[key] = one(mode, rate, k)
                    STORE.write_text(json.dumps(store, indent=1))
                print(key, {n: round(v, 4) for n, v in store[key].items()}, flush=True)


if __name__ == "__main__":
    main()
