"""Thread-to-surface contact (``contact.thread_segments``) off and on: pass-throughs, cost, energy, verdict.

    python3 bench/bench_thread_segments.py [CASE ...] [--end-time T] [--velocity V] [--release never]
        [--keys off,on] [--cache DIR]

For each case (default ``cases/envisat_small.toml`` and ``cases/envisat_net_impact.toml``) and each setting of
the key, the case runs through the impact pipeline (:func:`riskassess.stages.run.run_case`: simulation, summary,
structures verdict; no report) in a temporary folder, and the bench prints: the CPU time of the whole run and per
step (``time.process_time``, A/B back to back in one process), the energy balance's largest drift, the peak
contact force, the threads passing through each body at the net snapshots (:mod:`multibody.thread_crossing`: the
most at once, in how many snapshots, from when), the run's answer and each weak location's state and utilization
(judged peak / decisive allowable), with the machine's load. ``--cache DIR`` keeps each run's figures as JSON
(resumable: a run already there is not repeated).
"""
from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from multibody.thread_crossing import pass_through_history
from riskassess.cases.impact import load_case
from riskassess.models.impact import model_inputs
from riskassess.stages.run import run_case

ROOT = Path(__file__).resolve().parents[1]


def case_text(text: str, thread_segments: bool, end_time: float | None, velocity: float | None,
              release: str | None) -> str:
    """The case with the key set (inserted after ``transition_speed`` in [contact]) and the overrides."""
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("transition_speed"))
    lines.insert(k + 1, f"thread_segments = {'true' if thread_segments else 'false'}")
    out = "\n".join(lines) + "\n"
    for key, value in (("end_time", end_time), ("velocity", velocity)):
        if value is not None:
            old = next(line for line in out.splitlines() if line.startswith(f"{key} = "))
            out = out.replace(old, f"{key} = {value!r}", 1)
    if release is not None:
        old = next(line for line in out.splitlines() if line.startswith("release = "))
        out = out.replace(old, f'release = "{release}"', 1)
    return out


def pass_through_figures(run_dir: Path, case_path: Path) -> dict:
    """Per body name: the most threads through it at once, the snapshots with any, the first and last time (s)."""
    case = load_case(case_path)
    assembly = model_inputs(case, case_path.parent).assembly
    net, series = np.load(run_dir / "net.npz"), np.load(run_dir / "timeseries.npz")
    history = pass_through_history(net["time"], net["positions_lvlh"], series["time"], series["body_com_lvlh"],
                                   series["body_to_lvlh"], assembly.net, [b.meshes_body for b in assembly.bodies])
    out = {}
    for snap in history:
        for b, found in snap.by_body.items():
            name = assembly.bodies[b].name
            row = out.setdefault(name, {"most": 0, "snapshots": 0, "first_s": snap.time, "last_s": snap.time})
            row["most"] = max(row["most"], int(found.threads.size))
            row["snapshots"] += 1
            row["last_s"] = snap.time
    return {"bodies": out, "snapshots": int(len(net["time"]))}


def run(case_path: Path, thread_segments: bool, args) -> dict:
    """One run's figures (module doc)."""
    text = case_text(case_path.read_text(), thread_segments, args.end_time, args.velocity, args.release)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / case_path.name
        path.write_text(text)
        for data in ("data", "meshes"):
            if (case_path.parent / data).exists():
                os.symlink((case_path.parent / data).resolve(), Path(tmp) / data)
        load = os.getloadavg()[0]
        start = time.process_time()
        try:
            run_case(path, Path(tmp) / "run")
        except Exception as error:  # a failed run is a figure too (e.g. its energy balance): say so, go on
            return {"case": case_path.name, "thread_segments": thread_segments, "failed": str(error),
                    "cpu_s": time.process_time() - start, "load": [load, os.getloadavg()[0]]}
        cpu = time.process_time() - start
        summary = json.loads((Path(tmp) / "run" / "summary.json").read_text())
        structures = json.loads((Path(tmp) / "run" / "structures.json").read_text())
        crossings = pass_through_figures(Path(tmp) / "run", path)
        case = load_case(path)
    steps = int(round(case.simulation.end_time / case.simulation.step))
    locations = {}
    for row in structures["locations"]:
        judged = [c for c in row["criteria"].values() if c["peak"] is not None]
        worst = max((c["peak"] / c["decisive_allowable"] for c in judged), default=None)
        locations[row["name"]] = {"state": row["state"], "utilization": worst,
                                  "reason": row.get("indeterminate_reason")}
    return {"case": case_path.name, "thread_segments": thread_segments, "cpu_s": cpu, "steps": steps,
            "cpu_us_per_step": 1e6 * cpu / steps, "load": [load, os.getloadavg()[0]],
            "energy_drift": summary["checks"]["energy_balance_relative_drift"],
            "peak_contact_force_N": summary["peak_contact_force_N"], "pass_throughs": crossings,
            "debris_state": structures["debris_state"], "locations": locations}


def print_run(r: dict) -> None:
    if "failed" in r:
        key = str(r['thread_segments']).lower()
        print(f"\n{r['case']}  thread_segments = {key}: FAILED after {r['cpu_s']:.1f} s CPU "
              f"(load {r['load'][0]:.1f}): {r['failed']}")
        return
    peak = r["peak_contact_force_N"]
    peak = peak.get("value") if isinstance(peak, dict) else peak
    print(f"\n{r['case']}  thread_segments = {str(r['thread_segments']).lower()}: CPU {r['cpu_s']:.1f} s "
          f"({r['cpu_us_per_step']:.0f} us/step, {r['steps']} steps; load {r['load'][0]:.1f} -> {r['load'][1]:.1f}); "
          f"energy drift {100 * r['energy_drift']:.2f} %; peak contact force {peak:.4g} N; answer {r['debris_state']}")
    bodies = r["pass_throughs"]["bodies"]
    print(f"  threads through (of {r['pass_throughs']['snapshots']} snapshots): "
          + ("; ".join(f"{n}: up to {b['most']} at once, {b['snapshots']} snapshots, "
                       f"{b['first_s']:.2f}-{b['last_s']:.2f} s" for n, b in bodies.items()) or "none"))
    for name, loc in r["locations"].items():
        u = "-" if loc["utilization"] is None else f"{loc['utilization']:.3g}"
        print(f"  {name:26s} {loc['state']:13s} utilization {u}" + (f"  ({loc['reason']})" if loc["reason"] else ""))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("cases", nargs="*", default=[str(ROOT / "cases" / "envisat_small.toml"),
                                                     str(ROOT / "cases" / "envisat_net_impact.toml")])
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--velocity", type=float, default=None)
    parser.add_argument("--release", default=None, help='structures.release override, e.g. "never"')
    parser.add_argument("--keys", default="off,on")
    parser.add_argument("--cache", default=None, help="folder keeping each run's figures (resumable)")
    args = parser.parse_args()
    for case in args.cases:
        for key in args.keys.split(","):
            tag = f"{Path(case).stem}_{key}_{args.end_time}_{args.velocity}_{args.release}.json"
            cached = Path(args.cache) / tag if args.cache else None
            if cached and cached.exists():
                r = json.loads(cached.read_text())
            else:
                r = run(Path(case), key == "on", args)
                if cached:
                    cached.parent.mkdir(parents=True, exist_ok=True)
                    cached.with_suffix(".tmp").write_text(json.dumps(r, indent=1, default=float))
                    os.replace(cached.with_suffix(".tmp"), cached)
            print_run(r)


if __name__ == "__main__":
    main()
