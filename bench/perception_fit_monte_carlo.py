"""Is the smallest principal moment's stated 1-sigma honest? On captured perception runs
(bench/perception_capture.py): the free-flight fits' Monte Carlo (perception.fit_bootstrap: the registered
attitudes' residuals block-resampled, the before fit (shape estimated) and the after fit (that draw's shape)
redone, DRAWS draws) gives the covariance of the spin change per C, h1 - h0, in place of the fits' first-order
covariances; the angular balance is solved again with it (the other terms' covariances as the stage's), and the
net's angular momentum term is printed beside: its error against the truth and the share of it carried by the
nodes no return touched (their momentum, taken from the estimate).

    python bench/perception_fit_monte_carlo.py /tmp/percep17/capchain/none_obs20_seed*.pkl [--draws 50]

Columns: C error (% of the true C); the stage's stated 1-sigma (replayed); the 1-sigma with the Monte Carlo
covariance of h1 - h0; error / that 1-sigma; the spread of C over the draws alone (the balance solved per draw,
the other terms fixed); the first-order and Monte Carlo 1-sigma of |h1 - h0| along the balance (rad/s); CPU.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).parent))
import perception_substitution as substitution  # noqa: E402
from perception.fit_bootstrap import DRAWS, spin_change_monte_carlo  # noqa: E402
from perception.motion import attitude_sqrt_information, isotropic_attitude_weights  # noqa: E402


def _attitudes_and_weights(cap, motion):
    """The registered attitudes B->W and the fit's isotropic weights at the frames of ``motion``."""
    times = np.asarray(cap["frames"]["time"])
    indices = [int(np.argmin(np.abs(times - t))) for t in motion.times]
    alignments = [cap["alignments"][i] for i in indices]
    attitudes = Rotation.from_matrix(np.array([a.body_to_world[:3, :3] for a in alignments]))
    weights = isotropic_attitude_weights(attitude_sqrt_information([a.information for a in alignments]))
    return attitudes, weights


def monte_carlo_row(path, draws, seed=0) -> dict:
    cap = substitution.load(path)
    c_true = substitution.true_c(cap)
    c, sigma, mass, before, after, origin, step, others_before, others = substitution.replay(cap)
    tic = time.process_time()
    h0, h1, _ = spin_change_monte_carlo(before, after, *_attitudes_and_weights(cap, before),
                                        *_attitudes_and_weights(cap, after), np.random.default_rng(seed), draws)
    cpu = time.process_time() - tic
    estimate = substitution.estimated_terms(before, after, origin, others_before, others)
    cov_spin, cov_orbital, mass_sigma, cov_others = substitution.stage_covariances(before, after, origin, step, others)
    cov_mc = np.cov((h1 - h0).T)
    balance = substitution.momentum.smallest_moment_from_angular_momentum(
        estimate["h1"] - estimate["h0"], estimate["orbital1"] - estimate["orbital0"], mass,
        estimate["others_after_angular"] - others_before[1], cov_mc, cov_orbital, mass_sigma, cov_others)
    per_draw = [substitution.c_from_terms(dict(estimate, h0=a, h1=b), others_before[1], mass,
                                          (cov_spin, cov_orbital, mass_sigma, cov_others))[0] for a, b in zip(h0, h1)]
    direction = (estimate["h1"] - estimate["h0"]) / np.linalg.norm(estimate["h1"] - estimate["h0"])
    return {"seed": cap["answer"]["bench_seed"], "error": 100 * (c / c_true - 1), "stated": 100 * sigma / c,
            "mc": 100 * balance.sigma / balance.value, "mc_value_error": 100 * (balance.value / c_true - 1),
            "draws_spread": 100 * np.std(per_draw, ddof=1) / c, "draws_mean_shift": 100 * (np.mean(per_draw) / c - 1),
            "dh_first_order": float(np.sqrt(direction @ cov_spin @ direction)),
            "dh_mc": float(np.sqrt(direction @ cov_mc @ direction)), "chi2": balance.chi2, "cpu": cpu,
            "flight": (after.times[0], after.times[-1]), "tau": (before.fit.correlation_time_, after.fit.correlation_time_)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--draws", type=int, default=DRAWS)
    args = parser.parse_args(argv)
    print("| capture | seed | free flight | C error (%) | stated 1-sigma (%) | 1-sigma with the Monte Carlo h1 - h0 (%) "
          "| error / it | C spread over the draws (%) | mean shift of the draws (%) | 1-sigma of h1 - h0 along it, "
          "first order / Monte Carlo (rad/s) | tau before / after (frames) | angular chi2 | CPU (s) |")
    print("|---" * 14 + "|")
    for path in args.captures:
        r = monte_carlo_row(path, args.draws)
        print(f"| {path} | {r['seed']} | {r['flight'][0]:.1f}-{r['flight'][1]:.1f} s | {r['error']:+.3f} | "
              f"{r['stated']:.3f} | {r['mc']:.3f} | {abs(r['error']) / r['mc']:.1f} | {r['draws_spread']:.3f} | "
              f"{r['draws_mean_shift']:+.3f} | {r['dh_first_order']:.2e} / {r['dh_mc']:.2e} | "
              f"{r['tau'][0]:.1f} / {r['tau'][1]:.1f} | {r['chi2']:.2f} | {r['cpu']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
