"""Does the smallest principal moment's stated 1-sigma cover its error, term by term? On a captured
perception run (bench/perception_capture.py), each term of the angular balance
``m d(p x v) + C (h1 - h0) = -(dL_chaser + dL_net)`` is given two numbers in C (% of the true C): its
**error's share** (the sensitivity of C to the term times the term's error against the simulated truth,
first order) and its **stated 1-sigma share** (the same sensitivity applied to the covariance the stage
weighted it with). A term whose error share is several times its stated share is what the stated
1-sigma leaves out.

    python bench/perception_sigma_budget.py /tmp/percep16/cap*/none_obs20_seed*.pkl

Terms: h0 and h1 (spin per C before and after, rad/s, world; covariances of the free-flight fits), the
debris' orbital term per mass after (p x v, m^2/s; the CoM line's covariance), the chaser's and net's
angular momentum after (N m s; the covariance of the mean over the frames) and the mass (kg; its 1-sigma).
The sensitivities are central differences of the stage's weighted least squares with its weights held.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import perception_substitution as substitution  # noqa: E402

TERMS = ("h0", "h1", "orbital1", "others_after_angular")


def _c(terms, others_before, mass, covariances) -> float:
    return substitution.c_from_terms(terms, others_before, mass, covariances)[0]


def _gradient(terms, key, others_before, mass, covariances, step) -> np.ndarray:
    """dC/d(term) (3,) by central differences of ``step`` (the term's unit)."""
    gradient = np.zeros(3)
    for axis in range(3):
        plus, minus = dict(terms), dict(terms)
        plus[key] = terms[key] + step * np.eye(3)[axis]
        minus[key] = terms[key] - step * np.eye(3)[axis]
        gradient[axis] = (_c(plus, others_before, mass, covariances) - _c(minus, others_before, mass, covariances)) / (2 * step)
    return gradient


def budget(path) -> dict:
    """Per term: (error share, stated 1-sigma share) in % of the true C; and the stage's C error and 1-sigma."""
    cap = substitution.load(path)
    c_true = substitution.true_c(cap)
    _, sigma, mass, before, after, origin, step, others_before, others = substitution.replay(cap)
    truth = substitution.true_terms(cap, before, after, origin)
    estimate = substitution.estimated_terms(before, after, origin, others_before, others)
    covariances = substitution.stage_covariances(before, after, origin, step, others)
    cov_spin, cov_orbital, mass_sigma, cov_others = covariances
    stated = {"h0": before.spin_per_c_cov, "h1": after.spin_per_c_cov, "orbital1": cov_orbital,
              "others_after_angular": cov_others}
    steps = {"h0": 1e-5, "h1": 1e-5, "orbital1": 1e-4, "others_after_angular": 1e-2}
    rows = {}
    for key in TERMS:
        gradient = _gradient(estimate, key, others_before[1], mass, covariances, steps[key])
        rows[key] = (100 * gradient @ (estimate[key] - truth[key]) / c_true,
                     100 * np.sqrt(gradient @ stated[key] @ gradient) / c_true)
    slope = (_c(estimate, others_before[1], mass + 1e-3, covariances)
             - _c(estimate, others_before[1], mass - 1e-3, covariances)) / 2e-3
    rows["mass"] = (100 * slope * (mass - truth["mass"]) / c_true, 100 * abs(slope) * mass_sigma / c_true)
    c_value = _c(estimate, others_before[1], mass, covariances)
    return {"seed": cap["answer"]["bench_seed"], "c_error": 100 * (c_value / c_true - 1), "c_sigma": 100 * sigma / c_true,
            "free_flight": (after.times[0], after.times[-1]), "frames": len(after.times), "rows": rows}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args(argv)
    print("| capture | seed | free flight (frames) | C error / stated 1-sigma (%) | "
          + " | ".join(f"{key}: error / stated (%)" for key in (*TERMS, "mass")) + " |")
    print("|---" * (5 + len(TERMS)) + "|")
    for path in args.captures:
        b = budget(path)
        cells = " | ".join(f"{error:+.2f} / {stated:.2f}" for error, stated in b["rows"].values())
        print(f"| {path} | {b['seed']} | {b['free_flight'][0]:.1f}-{b['free_flight'][1]:.1f} s ({b['frames']}) | "
              f"{b['c_error']:+.2f} / {b['c_sigma']:.2f} | {cells} |")


if __name__ == "__main__":
    main()
