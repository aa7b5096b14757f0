"""Do the first-window load peaks converge as the step is refined (step, step / 2, step / 4), over replicas?
And which part of a joint's reaction carries the peak: its springs (the elastic load) or its dashpots?

    python3 bench/bench_step_refinement.py [CASE] [--replicas R] [--end-time T] [--steps 1e-4,5e-5,2.5e-5]
        [--first-mode HZ] [--member JOINT:LENGTH ...] [--output-rate HZ] [--edge-margin S] [--cache DIR]
        [--report-only] [--history LOCATION] [--window-end T] [--judged]

The case (default ``cases/envisat_small.toml``, release off) is built as ``bench_peak_convergence.py`` builds
it (``--first-mode`` on every numerical joint, ``--member`` on the Ka-band joints, ``--output-rate``), and each
replica (launch velocity x (1 + k 1e-7)) runs at every step of ``--steps`` to ``--end-time``. Automatic
penalty springs are tuned to each run's step, as the case would run, or with ``--tune-to STEP`` to one step in
every run (then only the integration error changes); with ``--first-mode`` and members the target has no
step-tuned spring left. Each run keeps the joints' recorded reactions (spring + dashpot) and their elastic
part, the springs' load alone, ``-k (offset, rotation)`` in the joint frame from the sampled body poses (the
root load a structure's strain carries; the dashpot stands in for its damping).

Per location and criterion, in both readings: the first window (from t = 0 until ``--edge-margin`` before the
coarsest step's replicas part, as in bench_peak_convergence.py), the median peak over the replicas at each step,
the change of the median from each step to the next with its 90 % bootstrap interval, and the largest paired
change (the same replica at both steps). ``--history LOCATION`` prints replica 0's load around its peak at
every step. Runs are cached one file each (resumable); ``--report-only`` reads the cache.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_peak_convergence as pc  # noqa: E402  (the case building, windows and statistics of the study)

from multibody.impact import ImpactSimulation  # noqa: E402
from riskassess.cases.impact import validate_case  # noqa: E402
from riskassess.models.impact import model_inputs, weak_locations  # noqa: E402
from structures.reproducibility import parting_time  # noqa: E402
from structures.weak_location import judged_demands  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def elastic_reaction_joint(system, parent_child, stiffness, series) -> tuple[np.ndarray, np.ndarray]:
    """The springs' share of every joint's reaction, ``-k (offset, rotation)`` (the load the parent exerts on
    the child through the springs alone), joint frame (parent side), from the sampled body poses.

    Parameters
    ----------
    system : multibody.impact.BuiltSystem
        The run's system (joint frames and points in the bodies' frames).
    parent_child : list of (int, int)
        Each joint's parent and child body indices.
    stiffness : (nj, 6) float
        The connectors' springs [x, y, z, rot h1, h2, h3] (N/m, N m/rad).
    series : dict
        The recorder's series: ``body_com_lvlh`` (k, nb, 3), ``body_to_lvlh`` (k, nb, 3, 3),
        ``joint_rotation_joint`` (k, nj, 3).

    Returns
    -------
    force, moment : (k, nj, 3) float
        N and N m, joint frame.
    """
    com, rot = series["body_com_lvlh"], series["body_to_lvlh"]
    nj = len(system.joint_to_parent)
    force, moment = np.zeros((len(com), nj, 3)), np.zeros((len(com), nj, 3))
    for j, (p, c) in enumerate(parent_child):
        frame = rot[:, p] @ np.asarray(system.joint_to_parent[j])                  # joint frame in LVLH
        offset = (rot[:, c] @ np.asarray(system.joint_point_child_body[j]) + com[:, c]
                  - rot[:, p] @ np.asarray(system.joint_point_parent_body[j]) - com[:, p])
        force[:, j] = -stiffness[j, :3] * np.einsum("kij,ki->kj", frame, offset)
        moment[:, j] = -stiffness[j, 3:] * series["joint_rotation_joint"][:, j]
    return force, moment


def run_one(text: str, base: Path, out: Path, tune_to: float | None = None) -> Path:
    """Run one case text; keep time, recorded and elastic reactions and the CPU time in ``out`` (.npz).
    ``tune_to``: the step (s) the automatic penalty joints are tuned to (None: the run's own step)."""
    if out.exists():
        return out
    start = time.process_time()
    case = validate_case(tomllib.loads(text), base / "case.toml")
    inputs = model_inputs(case, base)
    if tune_to:
        inputs.assembly.solver = replace(inputs.assembly.solver, joint_tuning_step=tune_to)
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    series = sim.run().series
    system = sim.system
    stiffness = np.array([np.diag(system.mbs.GetObjectParameter(o, "stiffness")) for o in system.joint_objects])
    force_el, moment_el = elastic_reaction_joint(
        system, [(j.parent, j.child) for j in inputs.assembly.joints], stiffness, series)
    np.savez(str(out) + ".tmp.npz", time=series["time"], force=series["joint_force_joint"],
             moment=series["joint_moment_joint"], force_elastic=force_el, moment_elastic=moment_el,
             cpu=time.process_time() - start)
    os.replace(str(out) + ".tmp.npz", out)
    return out


def demands(locations, run, elastic: bool, in_dynamics: set) -> dict:
    """{"location / criterion": demand history} of one run, as recorded or from the springs alone."""
    force, moment = (run["force_elastic"], run["moment_elastic"]) if elastic else (run["force"], run["moment"])
    out = {}
    for loc in locations:
        loc = replace(loc, structural_modes_hz=())
        series = judged_demands(loc, run["time"], force[:, loc.joint], moment[:, loc.joint])
        out.update({f"{loc.name} / {c}": series[c] for c in loc.criteria()})
    return out


def report(runs: dict, steps: list, replicas: int, locations, in_dynamics: set, margin: float, history: str | None,
           window_end: float | None = None):
    """Print the first-window table, both readings (``window_end``: one fixed window end for every location, s)."""
    rng = np.random.default_rng(0)
    for reading, elastic in (("as recorded (springs + dashpots)", False), ("elastic (springs alone)", True)):
        hist = {(h, r): demands(locations, runs[(h, r)], elastic, in_dynamics) for (h, r) in runs}
        print(f"\n=== {reading}: first window, median over {replicas} replicas; change to the next step "
              "[90 % bootstrap]; largest paired change (same replica)")
        for key in hist[(steps[0], 0)]:
            coarse = [hist[(steps[0], r)][key] for r in range(replicas)]
            t0 = runs[(steps[0], 0)]["time"]
            parting = min(parting_time(t0, coarse), float(t0[-1]) + 1.0) if window_end is None else window_end + margin
            peaks = {h: np.array([pc.window_peaks(runs[(h, r)]["time"], hist[(h, r)][key], 0.0, parting, margin)
                                  ["deterministic"] for r in range(replicas)]) for h in steps}
            cells = [f"{np.median(peaks[steps[0]]):.4g}"]
            for a, b in zip(steps, steps[1:]):
                change, low, high = pc.median_change(peaks[a], peaks[b], rng)
                paired = peaks[b] / peaks[a] - 1.0
                worst = paired[np.abs(paired).argmax()]
                cells.append(f"{b:g}: {change:+.1%} [{low:+.1%}, {high:+.1%}] (paired max {worst:+.1%})"
                             f"{pc.MARKS[pc.verdict(change, low, high)]}")
            print(f"  {key:36s} t < {parting - margin:.3f} s: {steps[0]:g}: " + "; ".join(cells))
            if history and key.startswith(history):
                for h in steps:
                    t, d = runs[(h, 0)]["time"], hist[(h, 0)][key]
                    w = t < parting - margin
                    k = int(np.argmax(np.where(w, d, -np.inf)))
                    around = slice(max(k - 5, 0), k + 6)
                    print(f"      step {h:g}, replica 0, peak {d[k]:.4g} at {t[k]:.4f} s; around it: "
                          + " ".join(f"{x:.3g}" for x in d[around]))


def judged_comparison(runs: dict, steps: list, replicas: int, locations, in_dynamics: set, skip: float) -> None:
    """Per location and step: the judged peak (t >= ``skip``) as recorded and from the springs alone, median
    over the replicas, and their ratio: how much of a judged peak the joints' dashpots carry."""
    print(f"\n=== judged window (t >= {skip:g} s): median peak as recorded, springs alone, ratio (median over replicas)")
    for h in steps:
        rec = [demands(locations, runs[(h, r)], False, in_dynamics) for r in range(replicas)]
        ela = [demands(locations, runs[(h, r)], True, in_dynamics) for r in range(replicas)]
        for key in rec[0]:
            pr, pe = ([float(d[key][runs[(h, r)]["time"] >= skip].max()) for r, d in enumerate(x)] for x in (rec, ela))
            ratio = np.median(np.array(pe) / np.array(pr))
            print(f"  step {h:g}  {key:36s} recorded {np.median(pr):.4g}  springs alone {np.median(pe):.4g}  "
                  f"ratio {ratio:.3f} [{min(np.array(pe) / np.array(pr)):.3f}, {max(np.array(pe) / np.array(pr)):.3f}]")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--replicas", type=int, default=8)
    parser.add_argument("--end-time", type=float, default=0.3)
    parser.add_argument("--steps", default="1e-4,5e-5,2.5e-5")
    parser.add_argument("--first-mode", type=float, default=None, help="every numerical joint's first_mode_hz (Hz)")
    parser.add_argument("--member", action="append", default=[], metavar="JOINT:LENGTH")
    parser.add_argument("--member-moduli", default="114e9,44e9")
    parser.add_argument("--member-damping", type=float, default=0.02)
    parser.add_argument("--output-rate", type=float, default=None)
    parser.add_argument("--edge-margin", type=float, default=0.01)
    parser.add_argument("--cache", required=True)
    parser.add_argument("--report-only", action="store_true")
    parser.add_argument("--history", default=None, metavar="LOCATION")
    parser.add_argument("--judged", action="store_true",
                        help="also compare the judged peaks (t >= skip_initial) as recorded and from the springs alone")
    parser.add_argument("--window-end", type=float, default=None, metavar="T",
                        help="end every first window at T (s) instead of --edge-margin before the coarsest step's "
                             "parting (the same window for runs whose replicas part at other times)")
    parser.add_argument("--tune-to", type=float, default=None, metavar="STEP",
                        help="tune the automatic penalty joints to this step (s) in every run, so that only the "
                             "integration error changes (default: each run's own step, as the case would run)")
    args = parser.parse_args()
    case_path = Path(args.case).resolve()
    text = case_path.read_text().replace('release = "low"', 'release = "never"', 1)
    if args.member:
        modulus, shear = (float(v) for v in args.member_moduli.split(","))
        text = pc.with_members(text, args.member, modulus, shear, args.member_damping)
    if args.output_rate:
        text = pc._sub(r"^output_rate = [0-9.e]+", f"output_rate = {args.output_rate:g}", text)
    text = pc._sub(r"^end_time = [0-9.e]+", f"end_time = {args.end_time:g}", text)
    steps = [float(s) for s in args.steps.split(",")]
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    start, load = time.perf_counter(), os.getloadavg()[0]
    runs = {}
    for r in range(args.replicas):          # replica by replica: a partial cache already pairs the steps
        for h in steps:
            t = pc._sub(r"^step = ([0-9.e-]+)", f"step = {h:g}", pc.case_text(text, "baseline", r, args.first_mode))
            out = cache / f"step{h:g}-{r}.npz"
            if not args.report_only:
                run_one(t, case_path.parent, out, args.tune_to)
                print(f"replica {r} step {h:g}: {float(np.load(out)['cpu']):.1f} s CPU, "
                      f"{time.perf_counter() - start:.0f} s wall, load {os.getloadavg()[0]:.1f}", flush=True)
            if out.exists():
                runs[(h, r)] = dict(np.load(out))
    done = sorted({r for (_, r) in runs if all((h, r) in runs for h in steps)})
    runs = {(h, i): runs[(h, r)] for i, r in enumerate(done) for h in steps}
    print(f"{args.case}, release off, " + (f"first_mode_hz = {args.first_mode:g}, " if args.first_mode else "")
          + (f"members {', '.join(args.member)}, " if args.member else "")
          + (f"automatic penalty tuned to {args.tune_to:g} s, " if args.tune_to else "")
          + f"{len(done)} replicas complete at steps {args.steps} to {args.end_time:g} s; cache {cache}; "
          f"load {load:.1f} -> {os.getloadavg()[0]:.1f}; CPU per run (median) "
          + ", ".join(f"{h:g}: {np.median([float(runs[(h, i)]['cpu']) for i in range(len(done))]):.1f} s"
                      for h in steps if done))
    if not done:
        return
    case = validate_case(tomllib.loads(text), case_path)
    locations = weak_locations(case, model_inputs(case, case_path.parent).assembly)
    in_dynamics = {i for i, j in enumerate(case.target.joints) if j.member is not None}
    report(runs, steps, len(done), locations, in_dynamics, args.edge_margin, args.history, args.window_end)
    if args.judged:
        judged_comparison(runs, steps, len(done), locations, in_dynamics, case.structures.skip_initial)


if __name__ == "__main__":
    main()
