"""A case's energy balance over time with the threads' contact on, and the threads' own energy record.

    python3 bench/thread_contact_drift.py [CASE] [--end-time T] [--velocity V] [--release never] [--key off]
                                          [--set contact.mu_static=0 ...]

Runs the case's simulation (no pipeline products) with ``contact.thread_segments`` set as ``--key`` says and the
health check's energy limit lifted (a drifting run is measured, not refused), and prints with the CPU time and the
load: the largest drift of the energy balance (share of the health check's reference energy) and when, the drift at
a few times, the ten largest gains between output samples and, with the key on, the thread contact's record
(:class:`multibody.contact_segment.SegmentBuffers`): the energy made between steps (each thread's contact energy at
a step's start less what its sub-cycle ended the last step with) in all and for the five threads with the most,
and the energy the threads' contacts dissipated. Helper thread12 (docs/model.md, "The deepest point followed inside
the step").
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script
from bench_thread_segments import case_text  # noqa: E402

from multibody.hinge import joint_damping_joint_frame, joint_stiffness_joint_frame  # noqa: E402
from multibody.impact import ImpactSimulation  # noqa: E402
from riskassess.cases.impact import load_case  # noqa: E402
from riskassess.models.impact import model_inputs  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def with_overrides(text: str, overrides: list) -> str:
    """The case text with each ``SECTION.KEY=VALUE`` replacing the key's line in that section, or added to it."""
    lines = text.splitlines()
    for item in overrides:
        name, value = item.split("=", 1)
        section, key = name.rsplit(".", 1)
        start = lines.index(f"[{section}]")
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("[")), len(lines))
        k = next((i for i in range(start + 1, end) if lines[i].split("=")[0].strip() == key), None)
        if k is None:
            lines.insert(start + 1, f"{key} = {value}")     # a key the case leaves at its default
        else:
            lines[k] = f"{key} = {value}"
    return "\n".join(lines) + "\n"


def print_energy_terms(series: dict, t: np.ndarray, reference: float) -> None:
    """Each energy term's change from 2 s (or the start) to the end, % of the reference energy: where the balance's
    drift sits among the terms it sums (multibody.recorder.ENERGY_TERMS)."""
    k0 = max(int(np.searchsorted(t, 2.0)) - 1, 0)
    terms = [key for key in series if key.startswith("energy_")]
    print(f"   energy terms, change {t[k0]:.3f} -> {t[-1]:.3f} s (% of the reference energy): " + ", ".join(
        f"{key[7:]} {100 * (series[key][-1] - series[key][k0]) / reference:+.3f}" for key in terms))


def gain_split(series: dict, k: int, reference: float, smallest: float = 5e-4) -> str:
    """The change of each energy term between samples ``k`` and ``k + 1`` (% of the reference energy), those of at
    least ``smallest`` % in size: which terms a one-sample gain of the total is made of."""
    parts = [(key[7:], 100 * (series[key][k + 1] - series[key][k]) / reference) for key in series
             if key.startswith("energy_") and key != "energy_total"]
    return ", ".join(f"{name} {change:+.3f}" for name, change in parts if abs(change) >= smallest)


def joint_rotation_damping_work(series: dict, assembly) -> list:
    """Per joint, the work its rotational dampers took (J), estimated from the sampled relative angular velocity:
    the sum over the joint frame's axes of c_k times the trapezoid integral of (rate_k)^2 (the hinge axis h2 of a
    revolute joint carries its torsional damping, the other axes the penalty damping,
    :func:`multibody.hinge.joint_damping_joint_frame`). A cross-check of the balance's ``dissipated_joints`` (booked
    every step since helper joints15, multibody.recorder_kernel.book_joint_dampers). An estimate only: the sampled rate resolves the
    slow hinge motion, not the penalty springs' ringing at the step's frequency, and the translational dampers
    (the joint point's relative velocity is not recorded) are left out. Returns (name, hinge-axis J, other J)."""
    t, rate = series["time"], series["joint_rate_joint"]
    step = assembly.solver.joint_tuning_step or assembly.solver.step
    out = []
    for k, joint in enumerate(assembly.joints):
        parent, child = assembly.bodies[joint.parent], assembly.bodies[joint.child]
        damping = joint_damping_joint_frame(joint, parent, child, joint_stiffness_joint_frame(joint, parent, child,
                                                                                              step))[3:]
        squared = rate[:, k, :] ** 2
        integral = np.sum(0.5 * (squared[1:] + squared[:-1]) * np.diff(t)[:, None], axis=0)
        work = damping * integral
        out.append((joint.name, float(work[1]), float(work[0] + work[2])))
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--velocity", type=float, default=None)
    parser.add_argument("--release", default=None, help='structures.release override, e.g. "never"')
    parser.add_argument("--key", default="on", choices=("on", "off"))
    parser.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                        help="a case value overridden, e.g. contact.mu_static=0 (an experiment, repeatable)")
    parser.add_argument("--save", default=None, metavar="NPZ",
                        help="write the run's time series (every key of Recorder.series) to this .npz file")
    args = parser.parse_args(argv)
    case_path = Path(args.case)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / case_path.name
        text = case_text(case_path.read_text(), args.key == "on", args.end_time, args.velocity, args.release)
        path.write_text(with_overrides(text, args.set))
        assembly = model_inputs(load_case(path), case_path.parent).assembly
    simulation = ImpactSimulation(assembly)
    reference = simulation.health.reference_energy
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    start = time.process_time()
    series = simulation.run().series
    cpu = time.process_time() - start
    t, total = series["time"], series["energy_total"]
    drift = (total - total[0]) / reference
    worst = int(np.abs(drift).argmax())
    print(f"{case_path.name} thread_segments {args.key}, end {t[-1]:.3f} s: CPU {cpu:.1f} s, load "
          f"{os.getloadavg()[0]:.1f}; largest |drift| {100 * abs(drift[worst]):.2f} % at {t[worst]:.3f} s, at the end "
          f"{100 * drift[-1]:+.2f} % of the reference energy {reference:.0f} J", flush=True)
    for when in (0.1, 0.2, 0.5, 1, 2, 2.5, 3, 4, 5, 6, 7, 7.5):
        k = int(np.searchsorted(t, when)) - 1
        if 0 <= k < len(t) and t[k] > when - 0.01:
            print(f"   t {t[k]:.3f} s  drift {100 * drift[k]:+.3f} %")
    print_energy_terms(series, t, reference)
    if args.save:
        np.savez_compressed(args.save, reference_energy=reference, **series)
    if "energy_dissipated_joints" in series:
        print(f"   joints' dampers, booked every step (energy_dissipated_joints, all joints, all axes): "
              f"{100 * series['energy_dissipated_joints'][-1] / reference:.3f} % of the reference energy")
    print("   joints' rotational dampers, work estimated from the samples (a cross-check; % of the reference energy): "
          + ", ".join(f"{name} hinge axis {100 * hinge / reference:.3f}, other axes {100 * other / reference:.3f}"
                      for name, hinge, other in joint_rotation_damping_work(series, assembly)))
    gains = np.diff(drift)
    for k in np.argsort(-gains)[:10]:
        print(f"   gain at t {t[k + 1]:.4f} s: {100 * gains[k]:+.3f} %; " + gain_split(series, k, reference))
    segments = simulation.system.kernel.buffers.segments
    if segments.enabled:
        jump = segments.energy_jump
        top = np.argsort(-np.abs(jump))[:5]
        print(f"   threads' contacts: made between steps {100 * jump.sum() / reference:+.3f} %, dissipated "
              f"{100 * segments.dissipated.sum() / reference:.2f} %; most: threads {top.tolist()} "
              f"{(100 * jump[top] / reference).round(3).tolist()} %")
        by_sharing = segments.jump_by_sharing
        print("   made between steps by the threads' sharing the step before (most threads in contact at either node): "
              + ", ".join(f"{label} {100 * by_sharing[0, k] / reference:+.3f} % ({int(by_sharing[1, k])} thread-steps)"
                          for k, label in enumerate(("arrivals (nodes free)", "1", "2", "3", "4+",
                                                                     "arrivals (a node in its own contact)"))))


if __name__ == "__main__":
    main()
