"""Where does a joint's judged load peak come from? The child's own contact with the net, or the parent's motion
transmitted through the joint, run by run, from a bench_peak_convergence cache.

    python3 bench/peak_sources.py CASE CACHE [--location asar_mount] [--criterion shear_stress] [--cutoff 3]
                                  [--windows 0-0.25,0.25-2,2-4,4-6,6-8,8-11] [--margin 1.0]
    python3 bench/peak_sources.py CASE CACHE --joint-modes 1e-4,5e-5,2.5e-5     (each joint's modes at these steps)

The cache must hold the runs' contact and body series (``bench/bench_peak_convergence.py`` keeps them since
helper asar20, ``HISTORY_KEYS``) and their filtered joint loads (``--load-filter``).

Newton-Euler on the joint's child body (rigid, mass ``m``, inertia ``I`` about its CoM ``C``), with the joint point
``P`` and the net's contact force ``F_c`` and moment ``M_c`` (about ``C``) on it:

.. math::

    F_j = m a_C - F_c,\\qquad M_j = I \\dot\\omega + \\omega \\times I \\omega - M_c + (C - P) \\times F_j

(``F_j``, ``M_j``: the load the parent exerts on the child at ``P``, as the recorder's ``joint_force_joint`` and
``joint_moment_joint``). Split the inertial term into the part a rigid joint imposes, the parent's angular
acceleration ``I \\dot\\omega_parent`` ("transmitted"), and the child's motion relative to it ("relative": the
joint's compliance); ``-M_c`` is the child's own contact ("contact"). Each term is passed through the same
causal Butterworth low-pass as the run's load filter (:mod:`multibody.load_filter`, here on the 1 kHz samples, the
contact loads being the impulse over each output interval), so the three filtered terms and the lever arm sum to
the filtered joint moment up to the sampling (printed as the closure). At the judged peak of ``--criterion``
(filtered loads, t >= the case's skip_initial) the script prints, per run: the peak, its time, its torsion and
transverse shares, the filtered torsion's three parts at the peak, the child's contact impulse in the ``--margin``
s before the peak and the parent's, and the child's contact impulse (integral of |F_c| dt, N s) and torsional
contact impulse (integral of |M_c . beam axis| dt, N m s) in each of ``--windows``; then the medians per variant.
"""
from __future__ import annotations

import argparse
import sys
import tomllib
from itertools import combinations
from pathlib import Path

import numpy as np
from scipy.stats import mannwhitneyu
from multibody.hinge import structural_modes_hz
from multibody.load_filter import butterworth_sections, filter_signal
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs, weak_locations
from structures.weak_location import demands

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_peak_convergence import quantile_change  # noqa: E402


def lowpass(series: np.ndarray, cutoff_hz: float, dt: float, order: int = 4) -> np.ndarray:
    """``series`` ((k,) or (k, 3) float, samples ``dt`` s apart) through the load filter's Butterworth, starting at
    rest under its first value as the run's filter does."""
    sections = butterworth_sections(cutoff_hz, dt, order)
    return np.apply_along_axis(lambda column: filter_signal(sections, column), 0, series)


def rate(series: np.ndarray, dt: float) -> np.ndarray:
    """Time derivative of samples ``dt`` apart (central differences, one-sided at the ends)."""
    return np.gradient(series, dt, axis=0)


def torsion_parts(run: dict, joint, index: int, parent, child, beam_joint: np.ndarray) -> dict:
    """The joint moment about the beam axis (N m, (k,)) from the child's Newton-Euler balance (module doc): parts
    "transmitted" (the parent's angular acceleration on the child's inertia), "relative" (the child's own angular
    acceleration relative to the parent, with the gyroscopic term), "contact" (minus the net's contact moment on the
    child about its CoM) and "lever" ((C - P) x F_j with the recorded joint force)."""
    t = run["time"]
    dt = float(np.median(np.diff(t)))
    body_to_lvlh = run["body_to_lvlh"].astype(float)
    joint_to_parent = np.linalg.solve(parent.body_to_lvlh, joint.hinge_to_lvlh)       # fixed in the parent
    joint_to_lvlh = body_to_lvlh[:, joint.parent] @ joint_to_parent
    beam_lvlh = joint_to_lvlh @ beam_joint
    child_to_lvlh = body_to_lvlh[:, joint.child]
    omega_child_lvlh = np.einsum("kij,kj->ki", child_to_lvlh, run["body_omega_body"][:, joint.child])
    omega_parent_lvlh = np.einsum("kij,kj->ki", body_to_lvlh[:, joint.parent],
                                  run["body_omega_body"][:, joint.parent])
    inertia_lvlh = child_to_lvlh @ child.inertia_body @ np.transpose(child_to_lvlh, (0, 2, 1))
    spin = np.einsum("kij,kj->ki", inertia_lvlh, omega_child_lvlh)
    gyro = np.cross(omega_child_lvlh, spin)
    accel_parent = rate(omega_parent_lvlh, dt)
    accel_child = rate(omega_child_lvlh, dt)
    transmitted = np.einsum("kij,kj->ki", inertia_lvlh, accel_parent)
    relative = np.einsum("kij,kj->ki", inertia_lvlh, accel_child - accel_parent) + gyro
    force_lvlh = np.einsum("kij,kj->ki", joint_to_lvlh, run["force"][:, index])
    point_lvlh = run["body_com_lvlh"][:, joint.parent] + np.einsum(
        "kij,j->ki", body_to_lvlh[:, joint.parent], parent.body_to_lvlh.T @ (joint.point_lvlh - parent.com_lvlh))
    lever = np.cross(run["body_com_lvlh"][:, joint.child] - point_lvlh, force_lvlh)
    parts = {"transmitted": transmitted, "relative": relative, "contact": -run["contact_moment_lvlh"][:, joint.child],
             "lever": lever}
    return {name: np.einsum("ki,ki->k", value, beam_lvlh) for name, value in parts.items()}


def force_parts(run: dict, joint, parent, child) -> dict:
    """The joint force on the child (N, (k, 3) LVLH) from its Newton balance ``F_j = m a_C - F_c`` (module doc): parts
    "transmitted" (m times the acceleration the child's CoM would have rigidly attached to the parent), "relative"
    (m times the rest of its acceleration: the joint's compliance) and "contact" (minus the net's contact force on
    the child)."""
    dt = float(np.median(np.diff(run["time"])))
    parent_to_lvlh = run["body_to_lvlh"][:, joint.parent].astype(float)
    omega_lvlh = np.einsum("kij,kj->ki", parent_to_lvlh, run["body_omega_body"][:, joint.parent])
    arm_lvlh = run["body_com_lvlh"][:, joint.child] - run["body_com_lvlh"][:, joint.parent]
    rigid = (rate(run["body_velocity_lvlh"][:, joint.parent], dt) + np.cross(rate(omega_lvlh, dt), arm_lvlh)
             + np.cross(omega_lvlh, np.cross(omega_lvlh, arm_lvlh)))
    own = rate(run["body_velocity_lvlh"][:, joint.child], dt)
    return {"transmitted": child.mass * rigid, "relative": child.mass * (own - rigid),
            "contact": -run["contact_force_lvlh"][:, joint.child].astype(float)}


def contact_impulses(run: dict, body: int, axis_lvlh: np.ndarray, windows) -> list:
    """[(integral |F_c| dt (N s), integral |M_c . axis| dt (N m s))] of the net's contact on ``body`` per window."""
    t = run["time"]
    dt = float(np.median(np.diff(t)))
    force = np.linalg.norm(run["contact_force_lvlh"][:, body], axis=1)
    torque = np.abs(run["contact_moment_lvlh"][:, body] @ axis_lvlh)
    return [(float(force[(t >= lo) & (t < hi)].sum() * dt), float(torque[(t >= lo) & (t < hi)].sum() * dt))
            for lo, hi in windows]


def run_sources(run: dict, location, criterion: str, joint, bodies, skip: float, cutoff: float, margin: float,
                windows) -> dict:
    """One run's judged peak of the location (filtered loads) and where it comes from (module doc)."""
    t = run["time"]
    dt = float(np.median(np.diff(t)))
    force, moment = run["force_filtered"][:, location.joint], run["moment_filtered"][:, location.joint]
    demand = demands(location, force, moment)
    k = int(np.argmax(np.where(t >= skip - 0.5 * dt, demand[criterion], -np.inf)))
    beam_joint = location.section_to_joint[:, 0]
    parts = torsion_parts(run, joint, location.joint, bodies[joint.parent], bodies[joint.child], beam_joint)
    filtered = {name: float(lowpass(series, cutoff, dt)[k]) for name, series in parts.items()}
    joint_to_lvlh = run["body_to_lvlh"][k, joint.parent] @ np.linalg.solve(bodies[joint.parent].body_to_lvlh,
                                                                            joint.hinge_to_lvlh)
    beam_lvlh = joint_to_lvlh @ beam_joint
    force_lvlh = joint_to_lvlh @ force[k]
    transverse_lvlh = force_lvlh - (force_lvlh @ beam_lvlh) * beam_lvlh
    direction = transverse_lvlh / max(np.linalg.norm(transverse_lvlh), 1e-300)
    shear_parts = {name: float(lowpass(series, cutoff, dt)[k] @ direction)
                   for name, series in force_parts(run, joint, bodies[joint.parent], bodies[joint.child]).items()}
    before = (t >= t[k] - margin) & (t <= t[k])
    impulse = {name: float(np.linalg.norm(run["contact_force_lvlh"][before, b], axis=1).sum() * dt)
               for name, b in (("child", joint.child), ("parent", joint.parent))}
    axis_lvlh = joint.hinge_to_lvlh @ beam_joint
    return {"peak": float(demand[criterion][k]), "time": float(t[k]),
            "torsion": float(demand["torsion_stress"][k]), "transverse": float(demand["transverse_shear_stress"][k]),
            "torque": float(moment[k] @ beam_joint), "parts": filtered,
            "shear_force": float(np.linalg.norm(transverse_lvlh)), "shear_parts": shear_parts,
            "impulse_before": impulse, "energy_drift": float(run["energy_total"][-1] - run["energy_total"][0]),
            "net_kinetic_late": float(run["energy_net_kinetic"][t >= t[-1] - 2.0].mean()), "windows": contact_impulses(run, joint.child, axis_lvlh, windows)}



def print_joint_modes(assembly, steps) -> None:
    """Each joint's modes (Hz; x, y, z, rot h1, h2, h3, each axis alone) with the springs a run at each of ``steps``
    (s) uses: the automatic penalty follows the step only below its caps (:mod:`multibody.hinge`)."""
    for step in steps:
        for joint in assembly.joints:
            modes = structural_modes_hz(joint, assembly.bodies[joint.parent], assembly.bodies[joint.child], step)
            print(f"step {step:g} s  {joint.name:20s} " + " ".join(f"{f:7.1f}" for f in modes))


def print_run(variant: str, replica: str, out: dict, margin: float) -> None:
    """One run's line: its judged peak, the torque's and the shear force's parts (:func:`run_sources`)."""
    p, f = out["parts"], out["shear_parts"]
    print(f"{variant:12s} r{replica:>2s} {out['peak']:7.1f} Pa at {out['time']:6.3f} s (torsion {out['torsion']:6.1f}, "
          f"transverse {out['transverse']:5.1f}); torque {out['torque']:+6.2f} = {p['transmitted']:+6.2f} "
          f"{p['relative']:+6.2f} {p['contact']:+6.2f} {p['lever']:+6.2f} "
          f"(closure {out['torque'] - sum(p.values()):+.2f}); shear force {out['shear_force']:5.1f} N = "
          + " ".join(f"{v:+6.1f}" for v in f.values())
          + f" (closure {out['shear_force'] - sum(f.values()):+.1f}); contact impulse in the {margin:g} s "
          f"before: child {out['impulse_before']['child']:.2f}, parent {out['impulse_before']['parent']:.2f} N s")


def compare(name: str, values: dict, rng) -> None:
    """Print, for each pair of variants (a, b), the change of the median of ``values[b]`` against ``values[a]`` with
    its 90 % bootstrap interval (both resampled) and the two-sided Mann-Whitney U p-value (the same distribution?)."""
    cells = []
    for a, b in combinations(values, 2):
        x, y = np.asarray(values[a]), np.asarray(values[b])
        if np.median(x) == 0.0 or len(x) < 2 or len(y) < 2:
            continue
        change, low, high = quantile_change(x, y, rng)
        cells.append(f"{b} vs {a}: {change:+.1%} [{low:+.0%}, {high:+.0%}] p={mannwhitneyu(x, y).pvalue:.3f}")
    print(f"  {name:34s} " + "; ".join(cells))


def summary(rows: dict, windows) -> None:
    """Medians per variant, and each pair of variants compared (:func:`compare`): the judged peak, its torsion, the
    contact part of its torque, and the child's contact impulses per window."""
    rng = np.random.default_rng(0)
    print("\nmedians per variant: peak (Pa), its time (s); child's contact impulse |F| (N s) / torsional (N m s) "
          "per window")
    for variant, outs in rows.items():
        cells = "  ".join(f"{lo:g}-{hi:g}: {np.median([o['windows'][i][0] for o in outs]):.2f} / "
                          f"{np.median([o['windows'][i][1] for o in outs]):.3f}" for i, (lo, hi) in enumerate(windows))
        print(f"{variant:12s} n={len(outs):2d} peak {np.median([o['peak'] for o in outs]):6.1f} at "
              f"{np.median([o['time'] for o in outs]):5.2f} s; energy drift "
              f"{np.median([o['energy_drift'] for o in outs]):+.2f} J, net kinetic last 2 s "
              f"{np.median([o['net_kinetic_late'] for o in outs]):.2f} J;  {cells}")
    print("\npairs of variants: change of the median [90 % bootstrap interval], Mann-Whitney p")
    compare("judged peak", {v: [o["peak"] for o in outs] for v, outs in rows.items()}, rng)
    compare("its torsion", {v: [o["torsion"] for o in outs] for v, outs in rows.items()}, rng)
    compare("|contact part of its torque|", {v: [abs(o["parts"]["contact"]) for o in outs] for v, outs in rows.items()},
            rng)
    compare("energy balance drift (J)", {v: [abs(o["energy_drift"]) for o in outs] for v, outs in rows.items()}, rng)
    compare("net kinetic energy, last 2 s (J)", {v: [o["net_kinetic_late"] for o in outs] for v, outs in rows.items()},
            rng)
    for i, (lo, hi) in enumerate(windows):
        for j, label in ((0, "|F|"), (1, "torsional")):
            compare(f"contact impulse {label} {lo:g}-{hi:g} s",
                    {v: [o["windows"][i][j] for o in outs] for v, outs in rows.items()}, rng)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("cache")
    parser.add_argument("--location", default="asar_mount")
    parser.add_argument("--criterion", default="shear_stress")
    parser.add_argument("--cutoff", type=float, default=3.0, help="the location's load-filter cut-off (Hz)")
    parser.add_argument("--margin", type=float, default=1.0, help="contact impulse window before the peak (s)")
    parser.add_argument("--windows", default="0-0.25,0.25-2,2-4,4-6,6-8,8-11", help="comma list of LOW-HIGH (s)")
    parser.add_argument("--joint-modes", default=None, metavar="STEP,STEP",
                        help="only print each joint's modes (Hz) at these steps (s) and stop")
    args = parser.parse_args()
    case_path = Path(args.case).resolve()
    text = case_path.read_text().replace('release = "low"', 'release = "never"', 1)
    case = validate_case(tomllib.loads(text), case_path)
    assembly = model_inputs(case, case_path.parent).assembly
    if args.joint_modes:
        print_joint_modes(assembly, [float(v) for v in args.joint_modes.split(",")])
        return
    location = next(loc for loc in weak_locations(case, assembly) if loc.name == args.location)
    joint = assembly.joints[location.joint]
    windows = [tuple(float(v) for v in w.split("-")) for w in args.windows.split(",")]
    rows: dict = {}
    print(f"{args.location} / {args.criterion}, filtered loads, judged t >= {case.structures.skip_initial:g} s; "
          f"torsion parts (N m about the beam axis, {args.cutoff:g} Hz): transmitted / relative / contact / lever; "
          f"transverse force parts (N, along the filtered transverse force): transmitted / relative / contact")
    for path in sorted(p for p in Path(args.cache).glob("*.npz") if ".tmp" not in p.name):
        variant, replica = path.stem.rsplit("-", 1)
        with np.load(path) as data:
            run = dict(data)
        if "contact_moment_lvlh" not in run or "force_filtered" not in run:
            print(f"{path.name}: no contact series or filtered loads (an older cache); skipped")
            continue
        out = run_sources(run, location, args.criterion, joint, assembly.bodies, case.structures.skip_initial,
                          args.cutoff, args.margin, windows)
        rows.setdefault(variant, []).append(out)
        print_run(variant, replica, out, args.margin)
    summary(rows, windows)


if __name__ == "__main__":
    main()
