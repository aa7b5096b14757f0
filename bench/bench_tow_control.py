"""Main-tether control over the Table 3 rate range: open-loop ramp against MRAC-1 and MRAC-2
(multibody/control/mrac.py) on the lower-order towing model or the full-net model, in Exudyn
(cases/zenit2_towing.toml).

    python bench/bench_tow_control.py [--case cases/zenit2_towing.toml] [--rates training|validation|all]
                                      [--plant lower-order|full-net] [--max-rates N]

The full-net plant (multibody/net_towing.py, from the wrapped start) takes ~40 s a run: use --max-rates.

For every thrust law and spin rate prints (riskassess.products.towing_figures.tautness): the engagement time t_e (first
sample with main-tether tension > 1 N: before it the sub-tethers are still slack and only P hangs
on the main tether),
the smallest main-tether tension after t_e (> 0: taut), the slack time after t_e, the peak
tension, the final elongation and its RMS error over the last 100 s against the MRAC reference
model's steady elongation (riskassess.products.towing_figures.reference_elongation); then the worst over the rates per law.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from multibody.net_towing import run_exudyn as run_full_net
from multibody.towing import run_exudyn
from riskassess.cases.impact import load_model
from riskassess.products.towing_figures import reference_elongation, tautness
from riskassess.models.towing import towing_model
from riskassess.models.towing_fullnet import full_net_model, wrapped_net
from riskassess.cases.towing import TowingCase

def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--rates", choices=("training", "validation", "all"), default="training")
    parser.add_argument("--plant", choices=("lower-order", "full-net"), default="lower-order")
    parser.add_argument("--max-rates", type=int, default=None)
    args = parser.parse_args()
    case = load_model(args.case, TowingCase)
    rates = {"training": case.rates.training_deg_s, "validation": case.rates.validation_deg_s,
             "all": sorted(case.rates.training_deg_s + case.rates.validation_deg_s)}[args.rates][:args.max_rates]
    wrapped = wrapped_net(case) if args.plant == "full-net" else None

    def run(law, rate):
        if args.plant == "full-net":
            return run_full_net(full_net_model(law, rate, wrapped=wrapped)).series()
        return run_exudyn(towing_model(law, rate)).series()

    desired = reference_elongation(case)
    print(f"plant: {args.plant}; MRAC target: the reference model's steady elongation {desired:.4f} m (eq. 13, z_d = "
          f"{case.mrac.desired_elongation} m); the ramp has no target (its error shown for comparison)")
    print(f"{'law':6} {'rate deg/s':>10} {'t_e s':>7} {'min T N':>9} {'slack s':>8} {'peak T N':>9} "
          f"{'z_end m':>8} {'rms(z-z_m) m':>12} {'wall s':>7}")
    worst = {}
    for kind in ("ramp", "mrac1", "mrac2"):
        law = case.model_copy(update=dict(thrust=case.thrust.model_copy(update=dict(kind=kind))))
        for rate in rates:
            start = time.perf_counter()
            f = tautness(run(law, rate), desired)
            wall = time.perf_counter() - start
            print(f"{kind:6} {rate:10.2f} {f['engaged_at_s']:7.1f} {f['min_tension_after_engagement_N']:9.3f} "
                  f"{f['slack_after_engagement_s']:8.1f} {f['peak_tension_N']:9.2f} {f['final_elongation_m']:8.4f} "
                  f"{f['rms_elongation_error_m']:12.4f} {wall:7.2f}", flush=True)
            w = worst.setdefault(kind, {"min_tension": np.inf, "slack_s": 0.0})
            w["min_tension"] = min(w["min_tension"], f["min_tension_after_engagement_N"])
            w["slack_s"] = max(w["slack_s"], f["slack_after_engagement_s"])
    for kind, w in worst.items():
        print(f"{kind}: over {len(rates)} rates, min tension after engagement {w['min_tension']:.3f} N, "
              f"longest slack after engagement {w['slack_s']:.1f} s")


if __name__ == "__main__":
    main()
