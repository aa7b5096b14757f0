"""Why the solar array deflects more in the coupled run than in the sequential one: the load it gets, or its motion.

    python3 bench/bench_array_deflection_modes.py [--replicas 3] [--end-time 2.5]

Runs the first seconds of ``cases/envisat_paper_sequential.toml`` in both modes (launch speed x (1 + k 1e-7),
k = 0, 1, -1, ...) and prints per run the array's largest swing about the hinge axis h2 and its time, and the
contact's angular impulse on the array about the hinge line (the recorded load: the wall run's in a sequential
run, the run's own in a coupled one; the hinge point carried with the array's attitude). If the impulses agree
while the swings do not, the difference is the debris' motion, not the load. Results in
``bench/results/array_deflection_modes.json``.
"""
from __future__ import annotations

import argparse
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

STORE = ROOT / "bench" / "results" / "array_deflection_modes.json"


def one(mode: str, k: int, end_time: float) -> dict:
    """One run in ``mode`` to ``end_time`` (s), launch speed x (1 + k 1e-7): the array's swing and its load."""
    case = replica_case(mode, k, end_time=end_time)
    array = next(b for b in case.target.bodies if b.name == "solar_array")
    hinge = next(j for j in case.target.joints if j.name == "solar_array_hinge")
    com_to_hinge_body = np.asarray(hinge.position, float) - np.asarray(array.center_of_mass, float)
    cpu, load = time.process_time(), os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        run_case(CASE, Path(tmp) / "run", case=case)
        s = np.load(Path(tmp) / "run" / "timeseries.npz")
        loads = np.load(Path(tmp) / "run" / ("wall_timeseries.npz" if mode == "sequential" else "timeseries.npz"))
    b = [str(n) for n in s["body_names"]].index("solar_array")
    j = [str(n) for n in s["joint_names"]].index("solar_array_hinge")
    t = loads["time"]
    dt = np.diff(t, prepend=0.0)
    rotation = loads["body_to_lvlh"][:, b]
    hinge_lvlh = loads["body_com_lvlh"][:, b] + rotation @ com_to_hinge_body
    axis_lvlh = rotation @ np.asarray(hinge.axis, float)
    arm = loads["body_com_lvlh"][:, b] - hinge_lvlh
    about_hinge = loads["contact_moment_lvlh"][:, b] + np.cross(arm, loads["contact_force_lvlh"][:, b])
    torque_axis = np.einsum("ki,ki->k", about_hinge, axis_lvlh)
    swing = np.degrees(s["joint_rotation_joint"][:, j, 1])
    first = t <= 0.5
    return {"largest swing about h2 (deg)": float(np.abs(swing).max()),
            "at (s)": float(s["time"][np.abs(swing).argmax()]),
            "contact angular impulse on the array about the hinge axis, first 0.5 s (N m s)": float(
                (torque_axis * dt)[first].sum()),
            "the same, whole run (N m s)": float((torque_axis * dt).sum()),
            "contact impulse on the array, first 0.5 s, |sum F dt| (N s)": float(np.linalg.norm(
                (loads["contact_force_lvlh"][:, b] * dt[:, None])[first].sum(axis=0))),
            "cpu (s)": time.process_time() - cpu, "load": load}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--replicas", type=int, default=3)
    parser.add_argument("--end-time", type=float, default=2.5)
    args = parser.parse_args()
    store = json.loads(STORE.read_text()) if STORE.exists() else {}
    for k in [0, 1, -1, 2, -2, 3, -3][:args.replicas]:
        for mode in ("sequential", "coupled"):
            key = f"{mode}|{args.end_time:g} s|{k:+d}"
            if key not in store:
                store[key] = one(mode, k, args.end_time)
                STORE.write_text(json.dumps(store, indent=1))
            print(key, {n: round(v, 5) for n, v in store[key].items()}, flush=True)


if __name__ == "__main__":
    main()
