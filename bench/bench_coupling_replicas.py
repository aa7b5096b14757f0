"""Coupled against the paper's sequential method, measured statistically: replicas of each on the paper case.

    python3 bench/bench_coupling_replicas.py [--replicas 4] [--eps 1e-7] [--end-time 7.5] [--table-only]

The capture is round-off chaotic (docs/structures.md: runs 1e-7 apart in launch speed spread late peaks by
40-390 %), so one run of each method says nothing about their difference. This bench runs
``cases/envisat_paper_sequential.toml`` (the case bench/bench_paper_side_by_side.py uses: the paper's
parameters and net mass) as it is (``simulation.coupling = "sequential"``: the net against the target held
fixed, then the recorded loads on the free debris) and with ``coupling = "coupled"``, each with the launch
speed x (1 + k eps), k = 0, +1, -1, +2, ... (as bench/roundoff_spread.py perturbs), one run at a time, and
prints per figure and mode the mean, the sample standard deviation and the range over the replicas, the
difference of the means and Welch's t (difference / its standard error). Beside the paper's figures it
prints the measurements that explain the differences: the along-track contact impulse on the debris
(first 0.5 s and after), the net's mass-averaged along-track velocity and kinetic energy at the end (its
rebound), the time with contact after 0.5 s, the target's motion as the net sees it (along-track
displacement and turn of the main body; zero for the wall) and the debris' spin and the array's flexing.

Each finished run is stored in ``bench/results/coupling_replicas.json`` (resumable: a rerun skips the runs
it has; ``--table-only`` prints from the stored runs). CPU time per run and the load are stored with it.
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
from bench_paper_side_by_side import PAPER, figures  # noqa: E402

from multibody.maths.rotations import rotation_vector_from_matrix  # noqa: E402
from riskassess.cases.impact import load_case  # noqa: E402
from riskassess.products.summary import contact_totals_debris  # noqa: E402
from riskassess.stages.run import run_case  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "envisat_paper_sequential.toml"
STORE = ROOT / "bench" / "results" / "coupling_replicas.json"
MODES = ("sequential", "coupled")
FIRST_S = 0.5          # the first impact is over by then (docs/model.md, the side-by-side table)
CONTACT_N = 10.0       # a sample "in contact" when the total contact force on the debris exceeds this (N)
SKIP_S = 0.25          # the paper's judged window starts here [paper Sec. 3.3.3]


def explaining(run: Path) -> dict:
    """The measurements that explain a difference between the methods, from one run folder.

    The loads are read where the net met the target: the wall run's series (``wall_timeseries.npz``) of a
    sequential run, the run's own series of a coupled one; the debris' response from ``timeseries.npz``
    (the driven debris of a sequential run).

    Parameters
    ----------
    run : Path
        A finished run folder.

    Returns
    -------
    dict of str to float
    """
    s = np.load(run / "timeseries.npz")
    wall = run / "wall_timeseries.npz"
    loads = np.load(wall) if wall.exists() else s
    t = loads["time"]
    dt = np.diff(t, prepend=t[0])               # the series hold interval means: F dt is the interval's impulse
    force, moment = contact_totals_debris(loads)
    first = t <= FIRST_S
    impulse_y = force[:, 1] * dt
    net_momentum0 = float(loads["momentum_linear_lvlh"][0, 1])          # the debris is at rest at t = 0
    net_mass = net_momentum0 / json.loads((run / "case.json").read_text())["launch"]["velocity"]
    net_v_end = (net_momentum0 - impulse_y.sum()) / net_mass
    in_contact = np.linalg.norm(force, axis=1) > CONTACT_N
    main = list(s["body_names"]).index("main_body")
    turn = np.degrees(np.linalg.norm(rotation_vector_from_matrix(
        loads["body_to_lvlh"][-1, main] @ loads["body_to_lvlh"][0, main].T)))
    hinge = list(s["joint_names"]).index("solar_array_hinge")
    judged = s["time"] >= SKIP_S
    ka = [list(s["body_names"]).index(name) for name in ("ka_band_boom", "ka_band_dish")]
    ka_force = np.linalg.norm(loads["contact_force_lvlh"][:, ka].sum(axis=1), axis=1)
    rate = np.degrees(np.linalg.norm(s["body_omega_body"][:, main], axis=1))
    return {
        "angular impulse about the debris CoM, first 0.5 s (N m s, LVLH x y z)": (
            moment[first] * dt[first, None]).sum(axis=0).tolist(),
        "angular impulse about the debris CoM, after 0.5 s (N m s, LVLH x y z)": (
            moment[~first] * dt[~first, None]).sum(axis=0).tolist(),
        "contact on the Ka-band, first second: impulse sum |F| dt (N s)": float((ka_force * dt)[t <= 1.0].sum()),
        "contact on the Ka-band, first second: largest (N)": float(ka_force[t <= 1.0].max()),
        "debris main body rate, largest (deg/s)": float(rate.max()),
        "contact impulse along-track, first 0.5 s (N s)": float(impulse_y[first].sum()),
        "contact impulse along-track, after 0.5 s (N s)": float(impulse_y[~first].sum()),
        "net along-track velocity at the end, mass mean (m/s)": float(net_v_end),
        "net kinetic energy at the end (J)": float(loads["energy_net_kinetic"][-1]),
        "time in contact after 0.5 s (s)": float(dt[~first & in_contact].sum()),
        "target main body along-track travel, as the net sees it (mm)": float(
            1e3 * (loads["body_com_lvlh"][-1, main, 1] - loads["body_com_lvlh"][0, main, 1])),
        "target main body turn, as the net sees it (deg)": float(turn),
        "debris main body rate at the end (deg/s)": float(np.degrees(np.linalg.norm(s["body_omega_body"][-1, main]))),
        "array hinge rotation about h2, RMS after 0.25 s (deg)": float(
            np.degrees(np.sqrt(np.mean(s["joint_rotation_joint"][judged, hinge, 1] ** 2)))),
    }


def replica_case(mode: str, k: int, eps: float = 1e-7, **simulation):
    """The paper case (:data:`CASE`) in ``mode`` ("sequential" or "coupled") with the launch speed x (1 + k eps) and
    the ``simulation`` keys changed (e.g. ``end_time``, ``output_rate``)."""
    case = load_case(CASE)
    launch = case.launch.model_copy(update={"velocity": case.launch.velocity * (1.0 + k * eps)})
    update = {"coupling": mode} | simulation
    return case.model_copy(update={"launch": launch, "simulation": case.simulation.model_copy(update=update)})


def run_one(mode: str, k: int, eps: float, end_time: float | None) -> dict:
    """One run of the paper case in ``mode`` with the launch speed x (1 + k eps): its figures."""
    case = replica_case(mode, k, eps, **({"end_time": end_time} if end_time else {}))
    load = os.getloadavg()[0]
    cpu, wall = time.process_time(), time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        run_case(CASE, Path(tmp) / "run", case=case)
        row = figures(Path(tmp) / "run") | explaining(Path(tmp) / "run")
    row.pop("wall time (s)", None)
    return row | {"cpu (s)": time.process_time() - cpu, "wall (s)": time.perf_counter() - wall,
                  "load": [load, os.getloadavg()[0]]}


def scalar_rows(rows: list[dict]) -> list[str]:
    """The figures the runs hold, in their order (runs stored before a figure was added lack it)."""
    keys = []
    for row in rows:
        keys += [key for key in row if key not in keys and key not in ("cpu (s)", "wall (s)", "load")]
    return keys


def values_of(rows: list[dict], key: str) -> dict[str, np.ndarray]:
    """``key`` over the replicas that have it, one array per number (a tuple figure gives one array per element)."""
    rows = [r for r in rows if key in r]
    first = rows[0][key]
    if isinstance(first, (list, tuple)):
        return {f"{key} [{i}]": np.array([r[key][i] for r in rows]) for i in range(len(first))}
    return {key: np.array([r[key] for r in rows])}


def table(store: dict) -> None:
    """Print per figure and mode: mean, standard deviation, range; the difference of the means and Welch's t."""
    runs = {m: [v for key, v in sorted(store["runs"].items()) if key.split("|")[0] == m] for m in MODES}
    n = {m: len(r) for m, r in runs.items()}
    if min(n.values()) < 2:
        print(f"need 2 runs per mode, have {n}")
        return
    paper = {f: v for f, v, _, _ in PAPER}
    print(f"{n['sequential']} sequential and {n['coupled']} coupled runs, launch speed x (1 + k {store['eps']:g}); "
          f"CPU per run {min(r['cpu (s)'] for rs in runs.values() for r in rs):.0f}-"
          f"{max(r['cpu (s)'] for rs in runs.values() for r in rs):.0f} s, load "
          f"{min(r['load'][0] for rs in runs.values() for r in rs):.1f}-"
          f"{max(max(r['load']) for rs in runs.values() for r in rs):.1f}")
    print(f"\n{'figure':62s} {'paper':>8s} | {'sequential mean +- sd [min, max]':>36s} | "
          f"{'coupled mean +- sd [min, max]':>36s} | {'coupled - seq':>13s} {'Welch t':>8s}")
    for key in scalar_rows(runs["sequential"]):
        if min(sum(key in r for r in runs[m]) for m in MODES) < 2:
            continue
        for name, seq in values_of(runs["sequential"], key).items():
            cou = values_of(runs["coupled"], key)[name]
            diff = cou.mean() - seq.mean()
            se = np.sqrt(seq.var(ddof=1) / seq.size + cou.var(ddof=1) / cou.size)
            tval = diff / se if se > 0 else np.inf * np.sign(diff)
            ref = f"{paper[key]:8.4g}" if key in paper else f"{'':8s}"

            def cell(v):
                return f"{v.mean():9.4g} +- {v.std(ddof=1):8.3g} [{v.min():.3g}, {v.max():.3g}]"
            rel = f"{diff / abs(seq.mean()):+.0%}" if seq.mean() else ""
            print(f"{name[:62]:62s} {ref} | {cell(seq):>36s} | {cell(cou):>36s} | {diff:+8.3g} {rel:>5s} {tval:+8.1f}"
                  + (f"  (n = {seq.size}, {cou.size})" if (seq.size, cou.size) != (n["sequential"], n["coupled"]) else ""))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--replicas", type=int, default=4)
    parser.add_argument("--eps", type=float, default=1e-7)
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--table-only", action="store_true")
    parser.add_argument("--store", type=Path, default=STORE)
    args = parser.parse_args()
    store = json.loads(args.store.read_text()) if args.store.exists() else {"eps": args.eps, "runs": {}}
    if store["eps"] != args.eps:
        raise SystemExit(f"{args.store} holds runs at eps = {store['eps']:g}; use --store for another eps")
    ks = [0, 1, -1, 2, -2, 3, -3][:args.replicas]
    if not args.table_only:
        for k in ks:                     # alternate the modes so a cut-short bench still has both
            for mode in MODES:
                key = f"{mode}|{k:+d}"
                if key in store["runs"]:
                    continue
                row = run_one(mode, k, args.eps, args.end_time)
                store["runs"][key] = row
                tmp = args.store.with_suffix(".tmp")
                tmp.write_text(json.dumps(store, indent=1))
                tmp.replace(args.store)
                print(f"{key}: {row['cpu (s)']:.0f} s CPU, {row['wall (s)']:.0f} s wall, load {row['load'][0]:.1f}-"
                      f"{row['load'][1]:.1f}", flush=True)
    table(store)


if __name__ == "__main__":
    main()
