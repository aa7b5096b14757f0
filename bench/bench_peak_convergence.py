"""Are the judged load peaks physics or numerics? Each weak location's peak demands against the
joint penalty stiffness and damping, the step and the output rate, over replicas.

    python3 bench/bench_peak_convergence.py [CASE] [--end-time T] [--replicas R] [--first-mode HZ]
                                            [--workers N]

Runs the case (default ``cases/envisat_small.toml``) with joint release off (every peak is then the
demand the intact joint carries, not cut at a release) at a baseline and one change at a time:

- step halved (the automatic penalty stiffness follows the step: its modes sit at 0.5 / step rad/s,
  so this is also 4x stiffer joints; with ``--first-mode`` the joints keep the structure's mode);
- penalty stiffness / 4 at the same step (modes at 0.25 / step rad/s; ``multibody.hinge.PENALTY_STEP_FACTOR``
  changed in the worker only), or, with ``--first-mode``, the structure's first mode / 2;
- penalty damping 0.2 of critical instead of 0.05 (every joint's ``penalty_damping_ratio``);
- output rate doubled (the peak between samples).

Each configuration runs ``R`` replicas whose launch velocity differs by k x 1e-7 (k = 0..R-1), far
below any physical uncertainty: the net's contacts make the capture sensitive to its initial state,
so a single run's peak is one sample of a spread, and the spread is printed beside the change.
``--first-mode HZ`` gives every joint ``first_mode_hz = HZ`` (the structure's compliance instead of a
penalty tuned to the step). Prints, per location and criterion and per window (the skipped initial
impact, and the judged rest), the baseline's median peak over the replicas and its range, and each
variant's change of the median; a change above 5 % is flagged. Prints the wall time and the load.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import multibody.hinge as hinge
from multibody.health import SimulationFailed
from riskassess.stages.run import run_case

ROOT = Path(__file__).resolve().parents[1]
TOLERANCE = 0.05
#: Relative launch-velocity offset between replicas: far below any physical uncertainty.
REPLICA_OFFSET = 1e-7
VARIANTS = ("baseline", "step/2", "stiffness/4", "damping 0.2", "output 2x")


def _sub(pattern: str, change, text: str) -> str:
    new, count = re.subn(pattern, change, text, count=1, flags=re.M)
    if count != 1:
        raise SystemExit(f"the case has no line matching {pattern!r}: cannot build this variant")
    return new


def case_text(text: str, variant: str, replica: int, first_mode: float | None) -> str:
    """The case of one variant and replica, as TOML text."""
    joint_extra = []
    if first_mode:
        joint_extra.append(f"first_mode_hz = {first_mode / 2 if variant == 'stiffness/4' else first_mode:g}")
    if variant == "damping 0.2":
        joint_extra.append("penalty_damping_ratio = 0.2")
    if joint_extra:
        text = re.sub(r'^(kind = "(revolute|clamped)".*)$', lambda m: "\n".join([m.group(1)] + joint_extra), text,
                      flags=re.M)
    if variant == "step/2":
        text = _sub(r"^step = ([0-9.e-]+)", lambda m: f"step = {float(m.group(1)) / 2:g}", text)
    if variant == "output 2x":
        text = _sub(r"^output_rate = ([0-9.e]+)", lambda m: f"output_rate = {2 * float(m.group(1)):g}", text)
    return _sub(r"^velocity = ([0-9.e+-]+)",
                lambda m: f"velocity = {float(m.group(1)) * (1 + replica * REPLICA_OFFSET)!r}", text)


def peaks(text: str, base_dir: str, penalty_factor: float) -> dict | str:
    """{"location / criterion": {window: peak}} of one run, or the failure message."""
    hinge.PENALTY_STEP_FACTOR = penalty_factor
    with tempfile.TemporaryDirectory(dir=base_dir) as tmp:      # mesh and data paths stay relative
        case = Path(tmp) / "case.toml"
        case.write_text(text)
        try:
            run_case(case, Path(tmp) / "run")
        except SimulationFailed as exc:     # a variant the model cannot run is a finding, not a crash
            return str(exc)
        skip = json.loads((Path(tmp) / "run" / "structures.json").read_text())["skip_initial_s"]
        series = np.load(Path(tmp) / "run" / "structures.npz")
        t = series["time"]
        windows = {"first impact": t < skip, "judged": t >= skip} if skip > 0 else {"judged": t >= 0}
        out = {}
        for key in series.files:
            if key == "time" or key.split("/")[1] not in ("moment", "normal_stress", "shear_stress"):
                continue
            out[key.replace("/", " / ")] = {w: float(np.abs(series[key][m]).max()) for w, m in windows.items()
                                           if m.any()}
        return out


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--replicas", type=int, default=4)
    parser.add_argument("--first-mode", type=float, default=None, help="every joint's first_mode_hz (Hz)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    text = Path(args.case).read_text()
    if 'release = "low"' not in text:      # otherwise the peaks would be cut at each joint's release
        raise SystemExit(f"{args.case}: expected release = \"low\" in [structures] to switch it off")
    text = text.replace('release = "low"', 'release = "never"', 1)
    if args.end_time:
        text = _sub(r"^end_time = [0-9.e]+", f"end_time = {args.end_time:g}", text)
    factor = hinge.PENALTY_STEP_FACTOR
    jobs = {(v, r): (case_text(text, v, r, args.first_mode), str(Path(args.case).resolve().parent),
                     factor / 2 if v == "stiffness/4" and not args.first_mode else factor)
            for v in VARIANTS for r in range(args.replicas)}
    start, load = time.perf_counter(), os.getloadavg()[0]
    with ProcessPoolExecutor(args.workers) as pool:
        futures = {key: pool.submit(peaks, *job) for key, job in jobs.items()}
        results = {key: f.result() for key, f in futures.items()}
    print(f"{args.case}, release off, joints: "
          + (f"first_mode_hz = {args.first_mode:g}" if args.first_mode else "automatic penalty")
          + f"; {len(jobs)} runs ({args.replicas} replicas each) in {time.perf_counter() - start:.0f} s on "
          f"{args.workers} workers, load average {load:.1f} -> {os.getloadavg()[0]:.1f}")
    for key, value in results.items():
        if isinstance(value, str):
            print(f"{key[0]} replica {key[1]}: {value}")
    report(results, args.replicas)


def report(results: dict, replicas: int) -> None:
    """Per window, location and criterion: baseline median [range], each variant's median change."""
    def finished(variant):
        """The replicas of ``variant`` that ran (a failed one holds its message)."""
        return [results[(variant, r)] for r in range(replicas) if not isinstance(results[(variant, r)], str)]
    base = finished("baseline")
    names = [v for v in VARIANTS if v != "baseline"]
    unconverged = total = 0
    for window in base[0][next(iter(base[0]))]:
        print(f"\nwindow: {window}")
        print(f"{'location / criterion':40s} {'baseline median [range]':>30s} {'spread':>7s} "
              + " ".join(f"{n:>12s}" for n in names))
        for key in base[0]:
            values = np.array([run[key][window] for run in base])
            med = np.median(values)
            cells = []
            for n in names:
                runs = finished(n)
                if not runs:
                    cells.append(f"{'failed':>12s}")
                    continue
                change = np.median([run[key][window] for run in runs]) / med - 1.0 if med else float("nan")
                cells.append(f"{change:+12.1%}")
                unconverged += abs(change) > TOLERANCE
                total += 1
            spread = (values.max() - values.min()) / med if med else float("nan")
            print(f"{key:40s} {f'{med:.4g} [{values.min():.3g}, {values.max():.3g}]':>30s} {spread:7.0%} "
                  + " ".join(cells))
    print(f"\n{unconverged} of {total} median changes above {TOLERANCE:.0%}: "
          + ("NOT CONVERGED" if unconverged else "converged")
          + "; spread = (max - min) / median over the replicas")


if __name__ == "__main__":
    main()
