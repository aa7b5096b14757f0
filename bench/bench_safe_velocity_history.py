"""One run of a safe-velocity study, replayed with its load history: when the net reaches, wraps and loads the target.

    python3 bench/bench_safe_velocity_history.py CASE --store STORE --sample N [--velocity V] [--end-time T]
                                                 [--release never] [--keep DIR | --kept DIR] [--judge-until T ...]

The run of Monte Carlo sample ``N`` of a store written by ``bench/bench_safe_velocity.py`` (its uncertain inputs:
friction, Hunt-Crossley damping, aim point), at the store's velocity or ``--velocity``, over the case's end time or
``--end-time``, with ``structures.release`` = ``--release`` (default ``never``: every joint holds, its peak is the
demand it would see if it held), through the impact pipeline (:func:`riskassess.stages.run.run_case`) in a
temporary folder (or ``--keep DIR``; ``--kept DIR`` reads a folder kept so and runs nothing). Prints, with the CPU time and the load:

- the first contact of the net with each body (s): flight distance / velocity;
- per 0.5 s window: the largest demand of the weak location on ``--joint`` (default the solar-array hinge; the
  resultant of the joint-frame moment components h1 and h3, the axes a revolute joint's location judges by default)
  and the largest contact force on each body (1 ms impulse means);
- the peak demand and its time, and the samples around it (h1, h3, the contact force on the joint's child);
- with ``--judge-until T`` (repeatable): the peak demand over the judged part of [0, T] and its time, and its
  utilization against the decisive allowable of the location's moment criterion, so that a
  run continued past a row's end time shows the row's own peak (the same run up to T) next to the later load;
  then the peak over (T, end] the same way;
- the wrapping: the bullets' along-track position beyond the main body's centre and the net's kinetic energy relative
  to the debris' centre of mass, at 16 times;
- the capture (:mod:`structures.capture_window`): every 5 s, the net's kinetic energy relative to the debris' main
  body with its rigid motion removed and the hinge's demand so far; then, per pair of ``--capture-energy`` (J) and
  ``--capture-hold`` (s) (defaults: the case's threshold, ``structures.capture_energy_J`` or else
  ``capture_energy_fraction`` of the launch's relative energy, and its hold), the time
  t_s the capture is over (None: not over by the run's end) and the largest demand over the judged part of
  [0, t_s] and after it; the smallest relative energy at which the demand reached 0.25, 0.5 and 1 of its allowable;
  and per 1 s window the largest demand against the smallest relative energy in it (the demand a given relative
  energy has been seen to bring);
- the run's answer, each location's state and the energy balance's largest drift.
"""
from __future__ import annotations

import argparse
import json
import os
import sqlite3
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

from riskassess.cases.impact import validate_case
from riskassess.stages.run import run_case
from riskassess.models.impact import model_inputs, weak_locations
from riskassess.sweep.spec import case_with
from structures.capture_window import (energy_threshold, hold_time, judged_rise_times, reference_body,
                                      relative_energy_history, settle_time)

WINDOW_S = 0.5   # s, the load-history table's window
HALF_SPAN = 12   # samples either side of the peak printed (1 ms each at the case's 1 kHz output)


def sample_overrides(store: Path, sample: int) -> dict:
    """The overrides (dotted key -> SI value) of Monte Carlo sample ``sample`` at the store's first grid point."""
    with sqlite3.connect(store) as con:
        row = con.execute("select overrides from runs where sample = ? order by grid_index limit 1", (sample,)).fetchone()
    if row is None:
        raise SystemExit(f"{store}: no run of sample {sample}")
    return json.loads(row[0])


def first_contacts(series) -> dict:
    """Body name -> time of its first contact force (s), None if never touched."""
    force = np.linalg.norm(series["contact_force_lvlh"], axis=2)
    return {str(name): (float(series["time"][np.argmax(force[:, i] > 0)]) if (force[:, i] > 0).any() else None)
            for i, name in enumerate(series["body_names"])}


def hinge_demand(series, joint: str) -> np.ndarray:
    """(n,) resultant of the joint-frame moment components h1 and h3 (N m) of ``joint``."""
    moment_joint = series["joint_moment_joint"][:, list(series["joint_names"]).index(joint), :]
    return np.hypot(moment_joint[:, 0], moment_joint[:, 2])


def print_windows(series, demand: np.ndarray) -> None:
    """Per window: the largest demand and the largest contact force on each body."""
    t, names = series["time"], [str(n) for n in series["body_names"]]
    force = np.linalg.norm(series["contact_force_lvlh"], axis=2)
    for start in np.arange(0.0, t[-1], WINDOW_S):
        inside = (t >= start) & (t < start + WINDOW_S)
        forces = ", ".join(f"{n} {force[inside, i].max():.0f}" for i, n in enumerate(names))
        print(f"  {start:5.1f}-{start + WINDOW_S:5.1f} s: demand {demand[inside].max():7.1f} N m; contact force (N) {forces}")


def print_peak(series, demand: np.ndarray, joint: str, child: int, skip_s: float) -> None:
    """The judged peak (after ``skip_s``) and the samples around it."""
    t = series["time"]
    k = int(np.argmax(np.where(t >= skip_s, demand, -np.inf)))
    moment_joint = series["joint_moment_joint"][:, list(series["joint_names"]).index(joint), :]
    force_child = np.linalg.norm(series["contact_force_lvlh"][:, child, :], axis=1)
    print(f"peak demand {demand[k]:.1f} N m at {t[k]:.3f} s; around it (h1, h3 N m; contact force on the child N):")
    for j in range(max(k - HALF_SPAN, 0), min(k + HALF_SPAN + 1, len(t))):
        print(f"  {t[j]:.3f} s  {moment_joint[j, 0]:8.1f} {moment_joint[j, 2]:8.1f}  {force_child[j]:7.1f}")


def print_peaks_until(series, demand: np.ndarray, skip_s: float, ends_s: list, allowable: float) -> None:
    """Per T in ``ends_s``: the peak demand (N m) over [skip_s, T] and over (T, end], each with its time and
    utilization (/ ``allowable``, N m)."""
    t = series["time"]
    for end in ends_s:
        for label, inside in ((f"[{skip_s:g}, {end:g}] s", (t >= skip_s) & (t <= end)),
                              (f"({end:g}, {t[-1]:.2f}] s", t > end)):
            if inside.any():
                k = int(np.argmax(np.where(inside, demand, -np.inf)))
                print(f"peak demand over {label}: {demand[k]:.1f} N m at {t[k]:.3f} s, "
                      f"utilization {demand[k] / allowable:.3f}")


def location_utilization(row: dict) -> float:
    """A location's utilization in ``structures.json``: its largest judged peak over decisive allowable (-)."""
    return max((c["peak"] / c["decisive_allowable"] for c in row["criteria"].values() if c["peak"] is not None),
               default=float("nan"))


def decisive_allowable(structures: dict, joint: str) -> float:
    """The decisive allowable (N m) of the weak location on ``joint`` (its moment criterion, as the demand here)."""
    row = next(r for r in structures["locations"] if r["joint"] == joint)
    return row["criteria"]["moment"]["decisive_allowable"]


def print_wrapping(net, series) -> None:
    """The bullets' along-track position beyond the main body's centre (m) and the net's kinetic energy relative to
    the debris' centre of mass (J), at 16 times."""
    t, x, v, m = net["time"], net["positions_lvlh"], net["velocities_lvlh"], net["masses"]
    body = list(series["body_names"]).index("main_body")
    y_body = np.interp(t, series["time"], series["body_com_lvlh"][:, body, 1])
    v_debris = np.stack([np.interp(t, series["time"], series["debris_velocity_lvlh"][:, k]) for k in range(3)], axis=1)
    kinetic = 0.5 * np.einsum("n,tnk->t", m, (v - v_debris[:, None, :]) ** 2)
    bullets = slice(x.shape[1] - int(net["n_bullets"]), None)
    for k in np.linspace(0, len(t) - 1, 16).astype(int):
        beyond = np.round(x[k, bullets, 1] - y_body[k], 1)
        print(f"  {t[k]:6.2f} s: bullets beyond the body centre (m) {beyond}; net kinetic energy {kinetic[k]:6.2f} J")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("--store", required=True)
    parser.add_argument("--sample", type=int, default=0)
    parser.add_argument("--velocity", type=float, default=None)
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--release", default="never")
    parser.add_argument("--joint", default="solar_array_hinge")
    parser.add_argument("--keep", default=None)
    parser.add_argument("--kept", default=None, help="a folder kept by --keep: print its history, run nothing")
    parser.add_argument("--judge-until", type=float, action="append", default=[],
                        help="also print the peak demand up to this time (s); repeatable")
    parser.add_argument("--capture-energy", type=float, action="append", default=[],
                        help="settle threshold (J) of the capture window to evaluate; repeatable")
    parser.add_argument("--capture-hold", type=float, action="append", default=[],
                        help="settle hold (s) of the capture window to evaluate; repeatable")
    args = parser.parse_args()
    overrides = sample_overrides(Path(args.store), args.sample) | {"structures.release": args.release}
    if args.velocity is not None:
        overrides["launch.velocity"] = args.velocity
    if args.end_time is not None:
        overrides["simulation.end_time"] = args.end_time
    case = validate_case(case_with(tomllib.loads(Path(args.case).read_text()), overrides), args.case)
    print(f"{args.case}, sample {args.sample}: {overrides}")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(args.kept or args.keep or Path(tmp) / "run")
        if args.kept is None:
            load, start = os.getloadavg()[0], time.process_time()
            run_case(args.case, out, case=case, overwrite=True)
            print(f"CPU {time.process_time() - start:.1f} s, load average {load:.1f} -> {os.getloadavg()[0]:.1f}")
        else:
            print(f"read from {out} (kept by an earlier run of the same command with --keep); nothing run")
        print_history(out, next(j for j in case.target.joints if j.name == args.joint), args.judge_until)
        energies = args.capture_energy or [case.structures.capture_energy_J]      # None: the case's energy fraction
        holds = args.capture_hold or [hold_time(case.structures.capture_hold_s, case.launch.velocity)]
        print_capture(out, case, args.case, next(j for j in case.target.joints if j.name == args.joint), energies, holds)


def print_capture(out: Path, case, case_path: str, joint, energies: list, holds: list) -> None:
    """The capture window of the run in ``out`` (module docstring)."""
    series, net = dict(np.load(out / "timeseries.npz")), dict(np.load(out / "net.npz"))
    structures = json.loads((out / "structures.json").read_text())
    assembly = model_inputs(case, Path(case_path).parent).assembly
    locations = weak_locations(case, assembly)
    body = reference_body(assembly.bodies, assembly.joints, assembly.debris_indices)
    t_energy, energy = relative_energy_history(net, net["masses"], series, body)
    skip = structures["skip_initial_s"]
    rises, _ = judged_rise_times(locations, series, skip)
    t, demand = series["time"], hinge_demand(series, joint.name)
    allowable = decisive_allowable(structures, joint.name)
    print(f"capture: net kinetic energy relative to {assembly.bodies[body].name} (its rigid motion removed), "
          f"and {joint.name}'s largest demand so far:")
    for k in np.flatnonzero(np.isclose(np.mod(t_energy + 1e-9, 5.0), 0.0, atol=1e-6)):
        so_far = demand[(t >= skip) & (t <= t_energy[k])]
        print(f"  {t_energy[k]:6.2f} s: {energy[k]:8.2f} J; demand so far {so_far.max() if so_far.size else 0.0:7.1f} N m")
    print(f"  last judged running-peak rise (any location) at {rises[-1] if rises.size else float('nan'):.3f} s")
    for threshold in energies:
        threshold = energy_threshold(energy[0], case.structures.capture_energy_fraction, threshold)
        for hold in holds:
            t_s = settle_time(t_energy, energy, rises, threshold, hold, skip)
            if t_s is None:
                print(f"  threshold {threshold:g} J, hold {hold:g} s: not over by {t[-1]:.2f} s "
                      f"(relative energy {energy[-1]:.1f} J)")
                continue
            before, after = (t >= skip) & (t <= t_s), t > t_s
            late = f"{demand[after].max():.1f} N m" if after.any() else "-"
            print(f"  threshold {threshold:g} J, hold {hold:g} s: t_s = {t_s:.2f} s; peak up to t_s "
                  f"{demand[before].max():.1f} N m ({demand[before].max() / allowable:.3f}), after it {late}")
    energy_at = np.interp(t, t_energy, energy)
    for fraction in (0.25, 0.5, 1.0):
        hit = np.flatnonzero((t >= skip) & (demand >= fraction * allowable))
        if hit.size:
            k = hit[np.argmin(energy_at[hit])]
            print(f"  smallest relative energy with the demand at {fraction:g} of the allowable: {energy_at[k]:.1f} J at "
                  f"{t[k]:.2f} s ({demand[k]:.0f} N m)")
    print("  per 1 s window: smallest relative energy (J) and largest demand (N m):")
    for start in np.arange(0.0, t[-1], 1.0):
        inside_e = (t_energy >= start) & (t_energy < start + 1.0)
        inside_d = (t >= max(start, skip)) & (t < start + 1.0)
        if inside_e.any() and inside_d.any():
            print(f"    {start:5.1f} s: {energy[inside_e].min():8.2f} J  {demand[inside_d].max():7.1f} N m")


def print_history(out: Path, joint, judge_until: list) -> None:
    """Everything printed about the run in folder ``out``, for the weak location on ``joint`` (a case joint)."""
    series, net = np.load(out / "timeseries.npz"), np.load(out / "net.npz")
    structures = json.loads((out / "structures.json").read_text())
    drift = json.loads((out / "summary.json").read_text())["checks"]["energy_balance_relative_drift"]
    child = [str(n) for n in series["body_names"]].index(joint.child)
    demand = hinge_demand(series, joint.name)
    print("first contact (s):", {n: (None if t is None else round(t, 3)) for n, t in first_contacts(series).items()})
    print(f"{joint.name}: demand (h1, h3 resultant) and contact forces per {WINDOW_S} s window:")
    print_windows(series, demand)
    print_peak(series, demand, joint.name, child, structures["skip_initial_s"])
    print_peaks_until(series, demand, structures["skip_initial_s"], judge_until,
                      decisive_allowable(structures, joint.name))
    print("wrapping:")
    print_wrapping(net, series)
    states = ", ".join(f"{row['name']} {row['state']} (utilization {location_utilization(row):.3f})"
                       for row in structures["locations"])
    print(f"answer {structures['debris_state']}: {states}; energy balance largest drift {100 * drift:.2f} %")

if __name__ == "__main__":
    main()
