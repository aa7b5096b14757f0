"""What the net's closing does to a capture, read from a kept run folder (``bench_safe_velocity_history.py ... --keep DIR``
of a case with ``[net.closing]``, e.g. bench/results/closing/envisat_small_segments_modes_high_closing.toml):

    python3 bench/bench_closing_phases.py DIR [DIR ...] [--joint solar_array_hinge]

Per run: the closing's trigger and times, the loop's natural lengths (open, at the reel-in's start, closed), the
winch's work and the energy balance's largest drift; the largest demand of the weak location on ``--joint`` (the
resultant of the joint-frame moment components h1 and h3, as ``bench_safe_velocity_history.py``) and its time in
each phase: before the activation, while reeling in, after the loop is closed, and over the whole run; the net's
kinetic energy relative to the debris' main body at the phase boundaries and the end; and the capture window's
answer (``structures.json``: settled, when, the cap) with every location's state.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

WINDOW_S = 1.0   # s, the table of demand and winch work after the activation


def hinge_demand(series, joint: str) -> np.ndarray:
    """(n,) resultant of the joint-frame moment components h1 and h3 (N m) of ``joint``."""
    moment_joint = series["joint_moment_joint"][:, list(series["joint_names"]).index(joint), :]
    return np.hypot(moment_joint[:, 0], moment_joint[:, 2])


def phase_peak(t, demand, start, end) -> str:
    """The largest demand over [start, end) (s) and its time, as text."""
    inside = (t >= start) & (t < end)
    if not inside.any():
        return "-"
    k = np.flatnonzero(inside)[np.argmax(demand[inside])]
    return f"{demand[k]:7.1f} N m at {t[k]:7.3f} s"


def print_run(folder: Path, joint: str) -> None:
    """Everything printed about the kept run in ``folder``."""
    series = np.load(folder / "timeseries.npz")
    summary = json.loads((folder / "summary.json").read_text())
    structures = json.loads((folder / "structures.json").read_text())
    closing = summary.get("closing")
    print(f"== {folder}")
    if closing is None:
        print("  no closing mechanism in this run")
        return
    t, demand = series["time"], hinge_demand(series, joint)
    skip = structures["skip_initial_s"]
    start = closing["activated_at_s"] if closing["activated_at_s"] is not None else np.inf
    closed = closing["closed_at_s"] if closing["closed_at_s"] is not None else np.inf
    print(f"  first contact {closing['first_contact_s']} s, activated {closing['activated_at_s']} s, "
          f"closed {closing['closed_at_s']} s ({'reached' if closing['closed'] else 'not reached'} by {t[-1]:.2f} s)")
    print(f"  loop natural length: open {closing['loop_open_length_m']:.2f} m, at the reel-in's start "
          f"{closing.get('loop_start_length_m')} m, closed {closing['loop_closed_length_m']:.2f} m")
    drift = summary["checks"]["energy_balance_relative_drift"]
    print(f"  winch work {closing['winch_work_J']:.2f} J; energy balance largest drift {100 * drift:.3f} % "
          f"(reference {summary['health']['energy_reference_J']:.2f} J)")
    judged = t >= skip
    print(f"  {joint} demand: before the activation {phase_peak(t[judged], demand[judged], 0.0, start)}; "
          f"reeling in {phase_peak(t, demand, start, closed)}; after closed {phase_peak(t, demand, closed, np.inf)}; "
          f"whole run {phase_peak(t[judged], demand[judged], 0.0, np.inf)}")
    winch = -series["energy_winch_work"]
    print(f"  per {WINDOW_S:g} s from the activation: largest demand (N m), winch work at the window's end (J), "
          "net kinetic energy (J)")
    for a in np.arange(start, min(t[-1], closed + 10.0), WINDOW_S) if np.isfinite(start) else []:
        inside = (t >= a) & (t < a + WINDOW_S)
        if inside.any():
            k = np.flatnonzero(inside)[-1]
            print(f"    {a:7.2f} s: {demand[inside].max():7.1f}  {winch[k]:8.2f}  {series['energy_net_kinetic'][k]:8.2f}")
    window = structures.get("capture_window") or {}
    print(f"  capture: settled {window.get('settled')} at {window.get('settled_at_s')} s (cap {window.get('end_time_cap_s')} "
          f"s, stopped early {window.get('stopped_early')}); net relative energy at the end "
          f"{window.get('net_energy_relative_end_J')} J")
    states = ", ".join(f"{row['name']} {row['state']}" for row in structures["locations"])
    print(f"  answer {structures['debris_state']}: {states}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", type=Path, help="kept run folders (bench_safe_velocity_history.py --keep)")
    parser.add_argument("--joint", default="solar_array_hinge", help="the case joint whose demand is printed")
    args = parser.parse_args(argv)
    for folder in args.folders:
        print_run(folder, args.joint)


if __name__ == "__main__":
    main()
