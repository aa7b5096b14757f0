"""What the energy left at a capture's end is: the net riding on a swinging appendage, or the net still moving.

    python3 bench/bench_capture_residual.py DIR [DIR ...] [--window 5] [--late 10] [--free-distance 0.5]

DIR is a kept run folder (``bench_safe_velocity_history.py ... --keep DIR``) of an impact case judged over the
capture (``structures.window = "capture"``). At every ``--window`` s of net snapshots it prints the net's kinetic energy
relative to the main body (E_main, the capture rule's T_rel, :mod:`structures.capture_window`) and relative to each
node's nearest body (E_near, the body whose convex mesh is nearest, :mod:`multibody.relative_motion`), the part the
nearest body's own motion relative to the main body carries (carried), bullets against net nodes, E_main by nearest
body, the energy of nodes more than ``--free-distance`` m from every body, the nodes touching (a contact force on the
node), each appendage's kinetic energy relative to the main body, the joints' elastic energy, and E_main as the
net's centre of mass's, a rigid rotation's and the net's own deformation's. Then, over the last ``--late`` s, the
mean of each; an exponential fit of E_main over the run's second half with the time it would cross the threshold
(an extrapolation, not a run), and the appendages' largest relative energy after the first 5 s and its decay
(largest value per ``--window`` s, an exponential fit from its peak).
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from multibody.relative_motion import (appendage_energy_relative_to_body, convex_distance, face_planes,
                                       nearest_body_relative_energy, rigid_split, velocity_field)
from structures.capture_window import omega_lvlh


def load_run(folder: Path) -> dict:
    """The run's net snapshots and, at the snapshot times, the bodies' states (LVLH) and the joints' elastic energy."""
    series, net = np.load(folder / "timeseries.npz"), np.load(folder / "net.npz")
    case = json.loads((folder / "case.json").read_text())
    t_net, t = net["time"], series["time"]
    rows = np.clip(np.searchsorted(t, t_net - 1e-9), 0, t.size - 1)
    if np.max(np.abs(t[rows] - t_net)) > 1e-6:
        raise ValueError(f"{folder}: net snapshots are not at series samples")
    body_to_lvlh = series["body_to_lvlh"][rows]
    return {"time": t_net, "x": net["positions_lvlh"], "v": net["velocities_lvlh"].astype(float),
            "masses": net["masses"], "n_bullets": int(net["n_bullets"]),
            "touching": np.linalg.norm(net["contact_force_lvlh"], axis=2) > 0,
            "com": series["body_com_lvlh"][rows], "velocity": series["body_velocity_lvlh"][rows],
            "body_to_lvlh": body_to_lvlh, "omega": omega_lvlh(body_to_lvlh, series["body_omega_body"][rows]),
            "names": [str(n) for n in series["body_names"]], "body_masses": series["body_masses"],
            "inertia": [np.array(b["inertia"], float) for b in case["target"]["bodies"]],
            "joint_elastic": series["energy_joint_elastic"][rows],
            "bodies": np.load(folder / "bodies.npz"),
            "capture": json.loads((folder / "structures.json").read_text()).get("capture_window", {})}


def distances(run: dict) -> np.ndarray:
    """(k, n, b) each node's signed distance (m) to each body's convex mesh (:func:`convex_distance`)."""
    k, n = run["x"].shape[:2]
    out = np.empty((k, n, len(run["names"])))
    for b in range(len(run["names"])):
        normals, offsets = face_planes(run["bodies"][f"vertices_{b}"], run["bodies"][f"faces_{b}"])
        points_body = np.einsum("kji,knj->kni", run["body_to_lvlh"][:, b], run["x"] - run["com"][:, b, None])
        out[:, :, b] = convex_distance(points_body, normals, offsets)
    return out


def decompose(run: dict, free_distance: float) -> dict:
    """Per snapshot and node: the energies (J) of :func:`nearest_body_relative_energy`, the nearest body, whether
    free; per snapshot: each appendage's relative energy (J) and :func:`rigid_split` of the net's relative motion."""
    d = distances(run)
    nearest = d.argmin(axis=2)
    fields = np.stack([velocity_field(run["x"], run["com"][:, b], run["velocity"][:, b], run["omega"][:, b])
                       for b in range(len(run["names"]))], axis=2)
    energy = nearest_body_relative_energy(run["masses"], run["v"], fields, nearest)
    appendages = np.stack([appendage_energy_relative_to_body(
        run["body_masses"][b], run["inertia"][b], run["com"][:, b], run["velocity"][:, b], run["omega"][:, b],
        run["body_to_lvlh"][:, b], run["com"][:, 0], run["velocity"][:, 0], run["omega"][:, 0])
        for b in range(1, len(run["names"]))], axis=1)
    split = rigid_split(run["masses"], run["x"], run["v"] - fields[:, :, 0])
    return {**energy, "nearest": nearest, "free": d.min(axis=2) > free_distance, "appendages": appendages, **split}


def print_table(run: dict, parts: dict, window_s: float) -> None:
    """The per-window rows."""
    t, n_b = run["time"], run["n_bullets"]
    bullets = np.arange(run["masses"].size - n_b, run["masses"].size)
    nodes = np.arange(run["masses"].size - n_b)
    names = run["names"]
    every = max(1, int(round(window_s / (t[1] - t[0]))))
    print("     t  E_main  E_near carried | bullets main near | net main near | E_main by nearest body: "
          + " ".join(names) + " | free n, E_main | touching n | appendages rel. main: " + " ".join(names[1:])
          + " | joints elastic | centre rotation deformation (J)")
    for k in range(0, t.size, every):
        e_main, e_near = parts["main"][k], parts["near"][k]
        by_body = " ".join(f"{e_main[parts['nearest'][k] == b].sum():.3f}" for b in range(len(names)))
        print(f"{t[k]:6.1f} {e_main.sum():7.3f} {e_near.sum():7.3f} {parts['carried'][k].sum():7.3f} | "
              f"{e_main[bullets].sum():.3f} {e_near[bullets].sum():.3f} | {e_main[nodes].sum():.3f} {e_near[nodes].sum():.3f} | "
              f"{by_body} | {parts['free'][k].sum()} {e_main[parts['free'][k]].sum():.3f} | {run['touching'][k].sum()} | "
              + " ".join(f"{a:.4f}" for a in parts["appendages"][k])
              + f" | {run['joint_elastic'][k]:.4f} | {parts['centre'][k]:.3f} {parts['rotation'][k]:.3f} {parts['deformation'][k]:.3f}")


def exponential_fit(t, energy):
    """(energy time constant (s), log-linear intercept) of energy(t) ~ exp(-t / tau)."""
    slope, intercept = np.polyfit(t, np.log(np.maximum(energy, 1e-12)), 1)
    return -1.0 / slope, intercept


def print_late(run: dict, parts: dict, late_s: float, window_s: float) -> None:
    """Means over the last ``late_s``; the decay fit and its threshold crossing; the appendages' decay."""
    t = run["time"]
    late = t >= t[-1] - late_s
    n_b = run["n_bullets"]
    total = parts["main"].sum(axis=1)
    mean = {name: parts[name][late].sum(axis=1).mean() for name in ("main", "near", "carried")}
    bullets = parts["main"][late][:, -n_b:].sum(axis=1).mean()
    largest_bullet = parts["main"][late][:, -n_b:].max() if n_b else 0.0
    bullet_mass = run["masses"][-1] if n_b else np.nan
    free = (parts["main"] * parts["free"])[late].sum(axis=1).mean()
    touching = (parts["main"] * run["touching"])[late].sum(axis=1).mean()
    print(f"  last {late_s:g} s, means (J): E_main {mean['main']:.3f}, E_near {mean['near']:.3f}, carried {mean['carried']:.4f}; "
          f"bullets {bullets:.3f} ({bullets / mean['main']:.0%}; the largest single bullet {largest_bullet:.3f} J, "
          f"{np.sqrt(2.0 * largest_bullet / bullet_mass):.2f} m/s); nodes > free distance {free:.3f} ({free / mean['main']:.0%}); "
          f"touching {touching:.3f} ({touching / mean['main']:.1%}); centre {parts['centre'][late].mean():.3f}, rotation "
          f"{parts['rotation'][late].mean():.3f}, deformation {parts['deformation'][late].mean():.3f}; appendages "
          + " ".join(f"{a:.4f}" for a in parts["appendages"][late].mean(axis=0)))
    threshold = run["capture"].get("energy_threshold_J", 0.005 * total[0])
    hold = run["capture"].get("hold_s", float("nan"))
    half = t >= t[-1] / 2
    tau, intercept = exponential_fit(t[half], total[half])
    crossing = (intercept - np.log(threshold)) * tau
    print(f"  E_main at the end {total[-1]:.3f} J against the threshold {threshold:.4f} J (hold {hold:g} s); exponential fit over "
          f"[{t[-1] / 2:.0f}, {t[-1]:.0f}] s: energy time constant {tau:.1f} s, below the threshold at {crossing:.0f} s, "
          f"over with the hold at {crossing + hold:.0f} s (extrapolated)")
    for b, name in enumerate(run["names"][1:]):
        energy = parts["appendages"][:, b]
        after = t > 5.0
        k_peak = np.flatnonzero(after)[np.argmax(energy[after])]
        every = max(1, int(round(window_s / (t[1] - t[0]))))
        starts = np.arange(k_peak, t.size - every, every)
        if energy[k_peak] <= 0 or starts.size < 3:
            continue
        peaks = np.array([energy[s:s + every].max() for s in starts])
        tau_b, _ = exponential_fit(t[starts], peaks)
        print(f"  {name} relative to the main body: largest after 5 s {energy[k_peak]:.4f} J at {t[k_peak]:.2f} s; "
              f"largest per {window_s:g} s from there decays with an energy time constant {tau_b:.1f} s; "
              f"{energy[late].mean():.5f} J over the last {late_s:g} s")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", type=Path, help="kept run folders")
    parser.add_argument("--window", type=float, default=5.0, help="the table's interval (s)")
    parser.add_argument("--late", type=float, default=10.0, help="the late means' span before the run's end (s)")
    parser.add_argument("--free-distance", type=float, default=0.5, help="a node farther than this from every body is free (m)")
    args = parser.parse_args(argv)
    for folder in args.folders:
        run = load_run(folder)
        parts = decompose(run, args.free_distance)
        print(f"{folder}: {run['masses'].size} nodes ({run['n_bullets']} bullets), launch relative energy "
              f"{parts['main'][0].sum():.3f} J; capture window: {json.dumps({k: v for k, v in run['capture'].items() if k != 'net_energy_relative_J'})}")
        print_table(run, parts, args.window)
        print_late(run, parts, args.late, args.window)


if __name__ == "__main__":
    main()
