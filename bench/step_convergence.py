"""Step-size convergence study of the coupled reference case.

Runs the first ``--end-time`` seconds of the 35 x 35 Envisat case at several steps and
prints, against the finest step, the peak total contact force and moment (averaged over
the 1 ms output interval, the quantity the structures stage uses), the peak hinge moments
and the debris velocity at the end. Usage: python3 bench/step_convergence.py [--end-time 1.0]
[--steps 1.25e-5,2.5e-5,5e-5,1e-4] [--own-tuning] (joints tuned to each run's step: "A larger step?" in
docs/model.md, with --steps 1e-4,1.5e-4,2e-4).
"""
from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from multibody.impact import ImpactSimulation
from riskassess.models.impact import model_inputs
from riskassess.cases.impact import load_case
from riskassess.products.summary import contact_totals_debris

ROOT = Path(__file__).resolve().parents[1]


def figures(case_path, step, end_time, joint_tuning_step, launch_scale=1.0):
    """The study's quantities for one run; ``launch_scale`` multiplies the net's initial velocity (a
    perturbation of round-off size shows how far round-off alone moves them: bench/roundoff_spread.py)."""
    case = load_case(case_path)
    inputs = model_inputs(case, Path(case_path).parent)
    a = inputs.assembly
    # The automatic penalty joints are tuned to one step for every run, so all runs integrate
    # the same model and the deviations measure the integration error alone.
    a.solver = dataclasses.replace(a.solver, step=step, end_time=end_time, joint_tuning_step=joint_tuning_step)
    a.net_velocity = np.asarray(a.net_velocity, float) * launch_scale
    sim = ImpactSimulation(a, inputs.rest_attitudes, inputs.rest_coms)
    t0 = time.perf_counter()
    rec = sim.run()
    wall = time.perf_counter() - t0
    s = rec.series
    force, moment = contact_totals_debris(s)
    hinge = np.abs(s["joint_moment_joint"]).max(axis=0)  # (nj, 3)
    return {
        "peak force (N)": np.linalg.norm(force, axis=1).max(),
        "peak moment (N m)": np.linalg.norm(moment, axis=1).max(),
        **{f"{j.name} |M| max (N m)": np.linalg.norm(hinge[k]) for k, j in enumerate(a.joints)},
        "debris v_y end (m/s)": s["debris_velocity_lvlh"][-1, 1],
        "energy balance drift (%)": 100 * np.abs(s["energy_total"] - s["energy_total"][0]).max() / s["energy_total"][0],
        "wall (s)": wall,
    }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default=str(ROOT / "cases" / "envisat_net_impact.toml"))
    parser.add_argument("--end-time", type=float, default=1.0)
    parser.add_argument("--steps", default="2.5e-5,5e-5,1e-4,2e-4")
    parser.add_argument("--own-tuning", action="store_true",
                        help="tune the automatic penalty joints to each run's own step, as the case would run "
                             "(docs/model.md, 'A larger step?'); default: to the largest step in every run")
    args = parser.parse_args()
    steps = sorted(float(x) for x in args.steps.split(","))
    rows = {h: figures(args.case, h, args.end_time, joint_tuning_step=h if args.own_tuning else max(steps))
            for h in steps}
    ref = rows[steps[0]]
    print(f"step-size study, {args.end_time:g} s simulated; deviations relative to step {steps[0]:g} s;"
          + (" joints tuned to each run's own step" if args.own_tuning else f" joints tuned to {max(steps):g} s in every run"))
    for key in ref:
        line = f"{key:38s}" + "".join(f"{rows[h][key]:12.5g}" for h in steps)
        if key not in ("wall (s)", "energy balance drift (%)"):
            line += "   dev: " + " ".join(f"{(rows[h][key] - ref[key]) / abs(ref[key]) * 100:+.2f}%" for h in steps[1:])
        print(line)


if __name__ == "__main__":
    main()
