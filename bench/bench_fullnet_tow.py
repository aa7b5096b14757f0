"""Full-net towing benchmark (goal: the 300 s full-net tow in under 10 min on 2 cores).

    python bench/bench_fullnet_tow.py                      # the case's full run (25 -> 300 s)
    python bench/bench_fullnet_tow.py --study --end 60     # step study over 35 s of towing
    python bench/bench_fullnet_tow.py --capture --end 40   # capture start: ejection at 0 s, closing 15 s, tow 25 s

Prints the wrapped-state preparation time, the run's wall time, steps per second, the step and
sub-step, and sanity figures: momentum balance (|P(t) - P(t0) - external impulse|, N s, against the
external impulse), main-tether and closing-loop tension, debris spin. The study runs the case at
the case's step and net sub-step, both halved and both quartered, and prints the RMSE of r_D/C,
omega_C, omega_D and T_MT (the identification's channels, eqs. 19 and 21) against the quartered
one; then the sensitivity floor: the case's step with the spin rate changed by 1e-9 of itself.
Timings are upper bounds on a shared machine.
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from multibody.net_towing import run_exudyn
from riskassess.cases.impact import load_model
from riskassess.stages.identify import rmse
from riskassess.stages.identify_fullnet import CHANNELS
from riskassess.models.towing_fullnet import full_net_model, wrapped_net
from riskassess.stages.tow_fullnet import momentum_residual
from riskassess.cases.towing import TowingCase

CASE = os.path.join(os.path.dirname(__file__), "..", "cases", "zenit2_towing.toml")


def run(case, wrapped, rate, end, step=None, substeps=None):
    model = full_net_model(case, rate, wrapped=wrapped, end_time=end, step=step, substeps=substeps)
    return model, run_exudyn(model)


def report(model, result):
    s = result.series()
    t, tension = s["time"], s["main_tether_tension"]
    impulse = np.linalg.norm(s["external_impulse_inertial"][-1] - s["external_impulse_inertial"][0])
    print(f"simulated {model.end_time - model.start_time:g} s: {model.n_steps} steps of {model.step * 1e3:g} ms, "
          f"{model.substeps} net sub-steps each ({model.step / model.substeps * 1e6:g} us), {len(model.node_positions)} nodes")
    print(f"wall {result.wall_time:.1f} s, {model.n_steps / result.wall_time:.0f} steps/s, "
          f"{model.n_steps * model.substeps / result.wall_time:.0f} net sub-steps/s")
    print(f"momentum balance: max |P - P0 - J_ext| = {momentum_residual(s):.3e} N s against |J_ext| = {impulse:.4e} N s")
    thrust = s["thrust"] > 0
    print(f"main tether: peak {tension.max():.1f} N, final {tension[-1]:.1f} N, slack while thrusting "
          f"{np.sum(np.diff(t, prepend=t[0])[thrust & (tension <= 0)]):.2f} s; closing loop peak "
          f"{s['closing_thread_peak_tension'].max():.1f} N; mean nodes in contact {s['net_contacts'].mean():.1f}")
    w = np.degrees(np.linalg.norm(s["debris_omega_body"], axis=1))
    sep = np.linalg.norm(s["debris_com_inertial"] - s["chaser_com_inertial"], axis=1)
    print(f"debris spin {w[0]:.3f} -> {w[-1]:.3f} deg/s; chaser-debris distance {sep[0]:.3f} -> {sep[-1]:.3f} m "
          f"(min {sep.min():.3f}, max {sep.max():.3f})")


def compared(series):
    """The identification's channels (eqs. 19, 21) of a run's series."""
    return {"relative_position": series["debris_com_inertial"] - series["chaser_com_inertial"],
            **{k: series[k] for k in CHANNELS[1:]}}


def study_row(label, series, reference, wall):
    e = [rmse(series[k], reference[k]) for k in CHANNELS]
    print(f"| {label} | {e[0]:.2e} | {e[1]:.2e} | {e[2]:.2e} | {e[3]:.2e} | {wall:.1f} |")


def study(case, wrapped, rate, end, pairs):
    """Run every (step, sub-steps) pair to ``end``; print each pair's RMSE per channel against the last
    (finest) pair and, for scale, the RMS of the finest run's channel. Then the sensitivity floor: the
    first pair again with the initial spin rate changed by 1e-9 of itself, against the first pair."""
    rows = []
    rate = case.debris.spin_rate_deg_s if rate is None else rate
    for step, substeps in pairs + [pairs[0]]:
        model, result = run(case, wrapped, rate * (1.0 + 1e-9 * (len(rows) == len(pairs))), end, step, substeps)
        series = result.series()
        tension = series["main_tether_tension"]
        print(f"step {step * 1e3:g} ms x {substeps}: wall {result.wall_time:.1f} s, T_MT peak {tension.max():.1f} N "
              f"at {series['time'][tension.argmax()]:.1f} s, slack samples {np.mean(tension <= 0):.2f}", flush=True)
        rows.append((f"{step * 1e3:g} | {substeps} | {step / substeps * 1e6:g}", compared(series), result.wall_time))
    reference = rows[len(pairs) - 1][1]
    print("| step (ms) | sub-steps | net step (us) | r_D/C (m) | omega_C (rad/s) | omega_D (rad/s) | T_MT (N) | wall (s) |")
    print("|---|---|---|---|---|---|---|---|")
    scale = [rmse(reference[k], 0.0 * reference[k]) for k in CHANNELS]
    print(f"| RMS of the finest run | | | {scale[0]:.3g} | {scale[1]:.3g} | {scale[2]:.3g} | {scale[3]:.3g} | |")
    for label, series, wall in rows[:len(pairs) - 1]:
        study_row(label, series, reference, wall)
    print(f"| {rows[len(pairs) - 1][0]} | reference | | | | {rows[len(pairs) - 1][2]:.1f} |")
    label, series, wall = rows[-1]
    study_row(label + " (rate x (1 + 1e-9), against the first row's run)", series, rows[0][1], wall)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default=CASE)
    parser.add_argument("--rate", type=float, default=None, help="debris spin (deg/s); default the case's")
    parser.add_argument("--end", type=float, default=None, help="end time (s); default the case's")
    parser.add_argument("--study", action="store_true", help="step-convergence study instead of one run")
    parser.add_argument("--capture", action="store_true", help="capture start (full_net.start = 'capture')")
    args = parser.parse_args()
    case = load_model(args.case, TowingCase)
    if args.capture:
        case = case.model_copy(update={"full_net": case.full_net.model_copy(update={"start": "capture"})})
        report(*run(case, None, args.rate, args.end))
        return
    start = time.perf_counter()
    wrapped = wrapped_net(case)
    print(f"wrapped state prepared in {time.perf_counter() - start:.1f} s (drape and close, compiled)")
    if args.study:
        h, m = case.full_net.step, case.full_net.substeps     # the case's step, halved, quartered (finest last)
        study(case, wrapped, args.rate, args.end or 60.0, [(h, m), (h / 2, m), (h / 4, m)])
        return
    report(*run(case, wrapped, args.rate, args.end))


if __name__ == "__main__":
    main()
