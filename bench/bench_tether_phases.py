"""What the main tether does to a capture, read from a kept run folder (``bench_safe_velocity_history.py ... --keep DIR``
of a case with ``[net.tether]``, e.g. bench/results/tether/envisat_small_segments_modes_high_tether.toml):

    python3 bench/bench_tether_phases.py DIR [DIR ...] [--joint solar_array_hinge] [--window 5]

Per run: the spool's brake (time, natural length), when the line first went taut and where the tethered node was
then, in the frames of the array and the main body (its distance to each one's box, :mod:`bench_closing_loop_geometry`'s
boxes), the same at the peak tension; the peak tension (N) and its time, the largest force on the chaser (N, what its
thrusters hold), the energy the tether's damper took and the reel's work (J); per ``--window`` s: the largest tension,
the largest demand of the weak location on ``--joint`` (h1, h3 resultant, as ``bench_closing_phases.py``) and the net's
kinetic energy relative to the debris' main body (``structures.json``'s capture history where it has one, else the
net's kinetic energy); the demand's peak before and after the brake; the capture window's answer and the energy
balance's largest drift.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench scripts
from bench_closing_loop_geometry import HALF_EXTENTS, segment_box_distance  # noqa: E402
from bench_closing_phases import hinge_demand, phase_peak  # noqa: E402


def node_against_boxes(point_lvlh, series, k: int) -> str:
    """The point's (m, LVLH) distance (m) to each mock-up box at sample ``k``, and its position in each body's frame."""
    names = [str(n) for n in series["body_names"]]
    parts = []
    for name, half in HALF_EXTENTS.items():
        b = names.index(name)
        com_lvlh, body_to_lvlh = series["body_com_lvlh"][k, b], series["body_to_lvlh"][k, b]
        point_body = (point_lvlh - com_lvlh) @ body_to_lvlh
        distance = segment_box_distance(point_lvlh, point_lvlh, com_lvlh, body_to_lvlh, half)
        parts.append(f"{name}: {distance:.2f} m from its box, at {np.round(point_body, 2).tolist()} m (body frame)")
    return "; ".join(parts)


def node_at(net, node: int, t: float) -> tuple[float, np.ndarray]:
    """The tethered node's position (m, LVLH) at the net snapshot nearest ``t`` (s), with the snapshot's time."""
    j = int(np.argmin(np.abs(net["time"] - t)))
    return float(net["time"][j]), net["positions_lvlh"][j, node]


def print_windows(series, demand, window_s: float) -> None:
    """Per window: the largest tension (N), the largest demand (N m), the net's kinetic energy at its end (J)."""
    t, tension = series["time"], series["tether_tension"]
    print(f"  per {window_s:g} s: largest tension (N), largest demand (N m), net kinetic energy at the end (J)")
    for a in np.arange(0.0, t[-1], window_s):
        inside = (t >= a) & (t < a + window_s)
        if inside.any():
            k = np.flatnonzero(inside)[-1]
            print(f"    {a:7.1f} s: {tension[inside].max():9.2f}  {demand[inside].max():7.1f}  "
                  f"{series['energy_net_kinetic'][k]:8.3f}")


def print_run(folder: Path, joint: str, window_s: float) -> None:
    """Everything printed about the kept run in ``folder``."""
    series, net = np.load(folder / "timeseries.npz"), np.load(folder / "net.npz")
    summary = json.loads((folder / "summary.json").read_text())
    structures = json.loads((folder / "structures.json").read_text())
    tether = summary.get("tether")
    print(f"== {folder}")
    if tether is None:
        print("  no main tether in this run")
        return
    t, demand = series["time"], hinge_demand(series, joint)
    print(f"  node {tether['node']}, anchor {np.round(tether['anchor_lvlh_m'], 3).tolist()} m (LVLH); first contact "
          f"{tether['first_contact_s']} s; braked at {tether['braked_at_s']} s, natural length "
          f"{tether['rest_length_at_brake_m']} m (now {tether['rest_length_now_m']:.3f} m), k {tether['stiffness_N_per_m']} N/m")
    print(f"  peak tension {tether['peak_tension_N']:.2f} N at {tether['peak_tension_at_s']} s (chaser force then "
          f"{tether['peak_chaser_force_N']:.2f} N); largest sampled force on the chaser "
          f"{np.linalg.norm(series['tether_force_on_chaser_lvlh'], axis=1).max():.2f} N; damper took "
          f"{tether['dissipated_J']:.3f} J, reel work {tether['reel_work_J']:.3f} J")
    for label, when in (("first taut", tether["taut_at_s"]), ("peak tension", tether["peak_tension_at_s"])):
        if when is None:
            print(f"  {label}: never")
            continue
        snapshot_t, point_lvlh = node_at(net, tether["node"], when)
        k = int(np.argmin(np.abs(t - snapshot_t)))
        print(f"  {label} at {when:.4f} s (net snapshot {snapshot_t:.2f} s): node {node_against_boxes(point_lvlh, series, k)}")
    skip = structures["skip_initial_s"]
    braked = tether["braked_at_s"] if tether["braked_at_s"] is not None else np.inf
    judged = t >= skip
    print(f"  {joint} demand: before the brake {phase_peak(t[judged], demand[judged], 0.0, braked)}; after it "
          f"{phase_peak(t, demand, braked, np.inf)}; whole run {phase_peak(t[judged], demand[judged], 0.0, np.inf)}")
    print_windows(series, demand, window_s)
    window = structures.get("capture_window") or {}
    print(f"  capture: settled {window.get('settled')} at {window.get('settled_at_s')} s (cap {window.get('end_time_cap_s')} "
          f"s, stopped early {window.get('stopped_early')}); net relative energy at the end "
          f"{window.get('net_energy_relative_end_J')} J")
    drift = summary["checks"]["energy_balance_relative_drift"]
    print(f"  energy balance largest drift {100 * drift:.3f} % (reference {summary['health']['energy_reference_J']:.2f} J)")
    states = ", ".join(f"{row['name']} {row['state']}" for row in structures["locations"])
    print(f"  answer {structures['debris_state']}: {states}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", type=Path, help="kept run folders (bench_safe_velocity_history.py --keep)")
    parser.add_argument("--joint", default="solar_array_hinge", help="the case joint whose demand is printed")
    parser.add_argument("--window", type=float, default=5.0, help="the table's window (s)")
    args = parser.parse_args(argv)
    for folder in args.folders:
        print_run(folder, args.joint, args.window)


if __name__ == "__main__":
    main()
