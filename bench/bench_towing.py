"""Towing benchmark: the 275 s lower-order run of cases/zenit2_towing.toml (Boonrath et al. 2024:
about 1 min in MATLAB) and the step-size study behind its default step.

    python bench/bench_towing.py [--case cases/zenit2_towing.toml] [--repeat 3] [--no-convergence]

Prints, for the Exudyn model and its compiled twin, the wall time, steps per second and the
step at the case's s, at the paper's MADS start s0 = [1, 6, 3, 0.25] and at the stiffest corner
of eq. (24) (the connection point is implicit: the cost must not depend on s); then the step
study at the case's s and at the stiff corner: RMSE against a 0.25 ms run of the quantities the
identification compares (r_D/C, both angular velocities, main-tether tension).
Timings are upper bounds when other jobs share the machine.
"""
from __future__ import annotations

import argparse

import numpy as np

from multibody.towing import run_exudyn, run_twin, stable_step
from riskassess.cases.impact import load_model
from riskassess.stages.identify import COMPARED, compared_series, rmse
from riskassess.models.towing import case_decision_vector, towing_model
from riskassess.cases.towing import TowingCase


def compared(result) -> tuple:
    """The quantities the identification compares (r_D/C, omega_C, omega_D, T_MT), eqs. (17)-(21)."""
    series = compared_series(result)
    return tuple(series[name] for name in COMPARED)


def decision_vectors(case) -> dict:
    """s of the case, the paper's MADS start and the stiffest corner of eq. (24) (largest k_ST and
    c_ST, smallest m_P: an explicit step for P would be ~20 us there)."""
    ident = case.identification
    lower, upper = ident.lower_bounds, ident.upper_bounds
    return {"case s": list(case_decision_vector(case)), "s0 (MADS start)": list(ident.initial_guess),
            "stiff corner": [upper[0], lower[1], upper[2], lower[3]]}


def speed(case, repeat):
    run_twin(towing_model(case)), run_exudyn(towing_model(case, end_time=case.simulation.start_time + 1.0))  # compile
    for label, s in decision_vectors(case).items():
        model = towing_model(case, s=s)
        print(f"275 s lower-order run at {label} = {np.round(s, 3).tolist()}: step {model.step * 1e3:.3f} ms "
              f"({model.n_steps} steps; an explicit P would need < {stable_step(model) * 2e3:.3f} ms)")
        for name, run in (("Exudyn", run_exudyn), ("twin", run_twin)):
            walls = [run(towing_model(case, s=s)).wall_time for _ in range(repeat)]
            best = min(walls)
            print(f"  {name:6s} wall {best:6.3f} s (best of {repeat}; all {', '.join(f'{w:.3f}' for w in walls)}), "
                  f"{model.n_steps / best:9.0f} steps/s")


def convergence(case):
    interval = case.simulation.output_interval
    steps = [interval / k for k in (400, 200, 100, 50, 25)]
    for label in ("case s", "stiff corner"):
        s = decision_vectors(case)[label]
        reference = compared(run_twin(towing_model(case, s=s, step=steps[0])))
        print(f"step study at {label} (twin = Exudyn's scheme), RMSE against 0.25 ms:")
        print(f"  {'step ms':>8} {'r_D/C m':>10} {'w_C rad/s':>10} {'w_D rad/s':>10} {'T_MT N':>10}")
        for h in steps[1:]:
            values = compared(run_twin(towing_model(case, s=s, step=h)))
            errors = [rmse(a, b) for a, b in zip(values, reference)]
            print(f"  {h * 1e3:8.3f} " + " ".join(f"{e:10.2e}" for e in errors))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-convergence", action="store_true")
    args = parser.parse_args()
    case = load_model(args.case, TowingCase)
    speed(case, args.repeat)
    if not args.no_convergence:
        convergence(case)


if __name__ == "__main__":
    main()
