"""What thread bending stiffness changes in the reference case (the paper's recommendation 2).

Runs the first ``--end-time`` seconds of the reference case without and with bending
(EI of the 2 mm thread from the case's axial stiffness: E = k l0 / A) and prints the peak
contact force and moment, the solar-array hinge peak moment, the debris velocity and the
net's bending energy. Usage: python3 bench/bending_effect.py [--end-time 1.0] [--factor 1]
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

from multibody.impact import ImpactSimulation
from riskassess.models.impact import model_inputs
from riskassess.cases.impact import load_case
from riskassess.products.summary import contact_totals_debris

ROOT = Path(__file__).resolve().parents[1]


def run(case, end_time, bending_rigidity):
    thread = case.net.thread.model_copy(update={"bending": bending_rigidity > 0,
                                                "bending_rigidity": bending_rigidity or None})
    case = case.model_copy(update={"net": case.net.model_copy(update={"thread": thread})})
    inputs = model_inputs(case, ROOT / "cases")
    inputs.assembly.solver = dataclasses.replace(inputs.assembly.solver, end_time=end_time)
    rec = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms).run()
    s = rec.series
    force, moment = contact_totals_debris(s)
    return {
        "peak contact force (N)": np.linalg.norm(force, axis=1).max(),
        "peak contact moment (N m)": np.linalg.norm(moment, axis=1).max(),
        "solar-array hinge |M| max (N m)": np.linalg.norm(np.abs(s["joint_moment_joint"][:, 0]).max(axis=0)),
        "debris v_y end (m/s)": s["debris_velocity_lvlh"][-1, 1],
        "net bending energy max (J)": s["energy_net_bending"].max(),
    }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--end-time", type=float, default=1.0)
    parser.add_argument("--factor", type=float, default=1.0, help="multiply the thread EI (sensitivity)")
    args = parser.parse_args()
    case = load_case(ROOT / "cases" / "envisat_net_impact.toml")
    t = case.net.thread
    area = np.pi * t.diameter**2 / 4
    modulus = t.stiffness * case.net.mesh_size / area
    ei = modulus * np.pi * t.diameter**4 / 64 * args.factor
    print(f"thread E = {modulus:.4g} Pa, EI = {ei:.4g} N m^2, k_b = EI/l0 = {ei / case.net.mesh_size:.4g} N m/rad")
    off, on = run(case, args.end_time, 0.0), run(case, args.end_time, ei)
    for key in off:
        change = (on[key] - off[key]) / abs(off[key]) * 100 if off[key] else float("nan")
        print(f"{key:34s} {off[key]:12.5g} {on[key]:12.5g}   {change:+.2f}%")


if __name__ == "__main__":
    main()
