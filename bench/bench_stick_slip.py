"""Stick-slip check of the catalog's ``hinge_coulomb_friction`` (sticking hinges, docs/diagnosis.md).

    python bench/bench_stick_slip.py [--out DIR]

1. The analytic Coulomb ring-down of a 1-DOF hinged panel (the sample hinged case's panel on a main
   body 1e5 x heavier, no hinge damping, T = 2.5 N m): turning points theta_n = (-1)^n (theta0 - 2nT/k)
   at n pi/omega, stop at the first |k theta_n| <= T; printed against the compiled model and Exudyn.
2. `riskassess diagnose` on a 60 s record of the sample hinged case made in Exudyn with an independent
   elasto-plastic (bristle) stiction law (T = 3 N m, default noise): the named cause and fitted torque.
Results go under --out (default: a temporary folder).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from riskassess.cases.impact import read_toml  # noqa: E402
from riskassess.diagnosis.cases import diagnosis_case_from_dict  # noqa: E402
from riskassess.diagnosis.effects import CATALOG  # noqa: E402
from riskassess.diagnosis.effects.hinge_coulomb_friction import (ElastoPlasticFriction,  # noqa: E402
                                                                 analytic_turning_points, turning_points)
from riskassess.diagnosis.exudyn_model import ExudynScenario, simulate_exudyn  # noqa: E402
from riskassess.diagnosis.model import predict  # noqa: E402
from riskassess.diagnosis.plants.plant import Plant  # noqa: E402
from riskassess.diagnosis.synthetic import noisy, sample_times  # noqa: E402
from riskassess.products.measured import write_measured  # noqa: E402
from riskassess.stages.diagnose import diagnose_case  # noqa: E402

CASE = ROOT / "cases" / "diagnose_hinged_appendage.toml"


def _case(**changes):
    raw = read_toml(CASE)
    for key, value in changes.items():
        raw[key] = {**raw[key], **value}
    return diagnosis_case_from_dict(raw, CASE.parent)


def ring_down(torque=2.5):
    plant = Plant.from_case(_case(main_body={"mass": 1e8, "inertia": [[1e11, 0, 0], [0, 1e11, 0], [0, 0, 1e11]]},
                                  hinge={"torsional_damping": 0.0}, initial={"angular_velocity": [0.0, 0.0, 0.0]}))
    k, inertia = plant.stiffness, plant.effective_hinge_inertia()
    t_ref, th_ref = analytic_turning_points(plant.hinge_angle0, k, inertia, torque)
    print(f"ring-down: k = {k} N m/rad, J = {inertia:.1f} kg m^2, T = {torque} N m, theta0 = {plant.hinge_angle0} rad; "
          f"2T/k = {2 * torque / k:.5f} rad per half cycle, sticks if |theta| <= T/k = {torque / k:.5f} rad")
    times = np.arange(0.0, 60.0, 0.01)
    runs = {}
    for name, simulate in (("compiled", predict), ("exudyn", simulate_exudyn)):
        start = time.perf_counter()
        out = simulate(plant, times, CATALOG["hinge_coulomb_friction"], np.array([torque]), ["friction_torque"])
        runs[name] = (out, time.perf_counter() - start)
    print(f"{'n':>2} {'t analytic':>10} {'theta analytic':>14} | " + " | ".join(f"{n:>8} t {n:>8} theta" for n in runs))
    turns = {n: turning_points(times, out["hinge_angle"]) for n, (out, _) in runs.items()}
    for i, (t, th) in enumerate(zip(t_ref[:-1], th_ref[:-1])):
        row = " | ".join(f"{turns[n][0][i]:10.2f} {turns[n][1][i]:14.5f}" for n in runs)
        print(f"{i + 1:>2} {t:10.2f} {th:14.5f} | {row}")
    for name, (out, wall) in runs.items():
        rate, angle = out["hinge_rate"], out["hinge_angle"]
        last_moving = times[np.abs(rate) > 1e-4][-1]
        print(f"{name}: stops (|rate| <= 1e-4 rad/s) at {last_moving:.2f} s (analytic {t_ref[-1]:.2f} s) at "
              f"{angle[-1]:.6f} rad (analytic {th_ref[-1]:.6f} rad); angle change over the last 17 s "
              f"{np.ptp(angle[times > t_ref[-1] + 2.0]):.1e} rad; {wall:.2f} s wall")


def sticking_record(out: Path, torque=3.0):
    case = _case()
    plant = Plant.from_case(case)
    times = sample_times(60.0, 10.0)
    scenario = ExudynScenario(plant)
    scenario.add_hinge_torque(ElastoPlasticFriction(torque, plant.effective_hinge_inertia(), plant.hinge_angle0))
    channels, _ = noisy(scenario.simulate(times), np.random.default_rng(24))
    out.mkdir(parents=True, exist_ok=True)
    data, case_copy = out / "sticking_hinge.csv", out / CASE.name
    write_measured(data, times, channels)
    case_copy.write_text(CASE.read_text())
    start = time.perf_counter()
    answer = diagnose_case(case_copy, data, out / "diagnosis", figures=False)
    fitted = answer["parameters"].get("friction_torque", {})
    print(f"diagnose, elasto-plastic stiction record (T = {torque} N m, sticks at "
          f"{channels['hinge_angle'][-1]:.4f} rad): cause = {answer['cause']}, confidence "
          f"{answer.get('confidence')}, friction_torque = {fitted.get('value')} +- {fitted.get('std')} N m; "
          f"{time.perf_counter() - start:.1f} s wall")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    ring_down()
    with tempfile.TemporaryDirectory() as tmp:
        sticking_record(args.out or Path(tmp) / "stick_slip")


if __name__ == "__main__":
    main()
