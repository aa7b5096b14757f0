"""Are the judged load peaks physics or numerics? Each weak location's peak demands against the
joint penalty stiffness and damping, the step and the output rate.

    python3 bench/bench_peak_convergence.py [CASE] [--end-time T]

Runs the case (default ``cases/envisat_small.toml``) with joint release off (every peak is then the
demand the intact joint carries, not cut at a release) at a baseline and one change at a time:

- step halved (the automatic penalty stiffness follows the step: its modes sit at 0.5 / step rad/s,
  so this is also 4x stiffer joints);
- penalty stiffness / 4 at the same step (modes at 0.25 / step rad/s; ``multibody.hinge.PENALTY_STEP_FACTOR``
  changed in this process only);
- penalty damping 0.2 of critical instead of 0.05 (every joint's ``penalty_damping_ratio``);
- output rate doubled (2000 Hz: the peak between samples).

Prints, per location and criterion, the baseline peak and its time, and each variant's relative change;
a change above 5 % is flagged "NOT CONVERGED". Prints the wall time and the load.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import tempfile
import time
from pathlib import Path

import multibody.hinge as hinge
from multibody.health import SimulationFailed
from riskassess.stages.run import run_case

ROOT = Path(__file__).resolve().parents[1]
TOLERANCE = 0.05


def _variant(text: str, change: str) -> str:
    if change == "step/2":
        return re.sub(r"^step = ([0-9.e-]+)", lambda m: f"step = {float(m.group(1)) / 2:g}", text, count=1, flags=re.M)
    if change == "damping 0.2":
        return re.sub(r'^(kind = "(revolute|clamped)".*)$', r"\1\npenalty_damping_ratio = 0.2", text, flags=re.M)
    if change == "output 2x":
        return re.sub(r"^output_rate = ([0-9.e]+)", lambda m: f"output_rate = {2 * float(m.group(1)):g}", text,
                      count=1, flags=re.M)
    return text


def peaks(case_text: str, folder: Path, penalty_factor: float) -> dict:
    """{(location, criterion): (peak, time)} of one run in ``folder``."""
    case = folder / "case.toml"
    case.write_text(case_text)
    saved = hinge.PENALTY_STEP_FACTOR
    hinge.PENALTY_STEP_FACTOR = penalty_factor
    try:
        run_case(case, folder / "run")
    finally:
        hinge.PENALTY_STEP_FACTOR = saved
    verdict = json.loads((folder / "run" / "structures.json").read_text())
    return {(loc["name"], name): (c["peak"], c["peak_time_s"]) for loc in verdict["locations"]
            for name, c in loc["criteria"].items()}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--end-time", type=float, default=None)
    args = parser.parse_args()
    base_dir = Path(args.case).resolve().parent
    text = Path(args.case).read_text()
    if 'release = "low"' not in text:      # otherwise the peaks would be cut at each joint's release
        raise SystemExit(f"{args.case}: expected release = \"low\" in [structures] to switch it off")
    text = text.replace('release = "low"', 'release = "never"', 1)
    if args.end_time:
        text = re.sub(r"^end_time = [0-9.e]+", f"end_time = {args.end_time:g}", text, count=1, flags=re.M)
    variants = {"baseline": (text, hinge.PENALTY_STEP_FACTOR), "step/2": (_variant(text, "step/2"), hinge.PENALTY_STEP_FACTOR),
                "stiffness/4": (text, hinge.PENALTY_STEP_FACTOR / 2), "damping 0.2": (_variant(text, "damping 0.2"),
                                                                                    hinge.PENALTY_STEP_FACTOR),
                "output 2x": (_variant(text, "output 2x"), hinge.PENALTY_STEP_FACTOR)}
    start, load = time.perf_counter(), os.getloadavg()[0]
    results = {}
    for name, (case_text, factor) in variants.items():
        with tempfile.TemporaryDirectory(dir=base_dir) as tmp:      # mesh and data paths stay relative
            try:
                results[name] = peaks(case_text, Path(tmp), factor)
            except SimulationFailed as exc:     # a variant the model cannot run is a finding, not a crash
                print(f"{name}: {exc}")
                results[name] = None
    print(f"{args.case}, release off; {len(variants)} runs in {time.perf_counter() - start:.0f} s, load average "
          f"{load:.1f} -> {os.getloadavg()[0]:.1f}")
    names = [n for n in variants if n != "baseline"]
    print(f"{'location / criterion':44s} {'baseline peak':>13s} {'at (s)':>7s} " + " ".join(f"{n:>12s}" for n in names))
    unconverged = 0
    for key, (peak, at) in results["baseline"].items():
        cells = []
        for n in names:
            other = results[n][key][0] if results[n] else None
            change = (other / peak - 1.0) if peak and other is not None else float("nan")
            cells.append(f"{change:+12.1%}")
            unconverged += abs(change) > TOLERANCE
        print(f"{key[0] + ' / ' + key[1]:44s} {peak:13.4g} {at:7.3f} " + " ".join(cells))
    print(f"{unconverged} of {len(results['baseline']) * len(names)} changes above {TOLERANCE:.0%}: "
          + ("NOT CONVERGED" if unconverged else "converged"))


if __name__ == "__main__":
    main()
