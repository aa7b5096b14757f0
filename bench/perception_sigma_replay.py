"""The momentum step of captured perception runs (bench/perception_capture.py) redone with this checkout's
code: the mass and smallest principal moment C, their errors and stated 1-sigma, and the balances' chi2, to
compare a change of the momentum step's uncertainties with the stage's answers without rerunning the stage
(the estimates are those of the stage; only code after the capture's inputs is rerun).

    python bench/perception_sigma_replay.py /tmp/percep16/cap*/none_obs20_seed*.pkl
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import perception_substitution as substitution  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args(argv)
    print("| capture | seed | C error (%) | stated 1-sigma of C (%), capture's / now | error / 1-sigma now | angular chi2 "
          "| mass error (%) | stated 1-sigma of the mass (%), capture's / now | linear chi2 |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in args.captures:
        cap = substitution.load(path)
        answer = cap["answer"]
        c_true, mass_true = substitution.true_c(cap), cap["truth"]["mass"]
        c, sigma, mass, *_, step, _, _ = substitution.replay(cap)
        stage_sigma = 100 * answer["principal_moments_std_kg_m2"][2] / answer["principal_moments_kg_m2"][2]
        stage_mass_sigma = 100 * answer["mass_std_kg"] / answer["mass_kg"]
        error = 100 * (c / c_true - 1)
        print(f"| {path} | {answer['bench_seed']} | {error:+.2f} | {stage_sigma:.2f} / {100 * sigma / c:.2f} | "
              f"{abs(error) / (100 * sigma / c):.1f} | {step['c'].chi2:.2f} | {100 * (mass / mass_true - 1):+.3f} | "
              f"{stage_mass_sigma:.3f} / {100 * step['mass'].sigma / mass:.3f} | {step['mass'].chi2:.2f} |")


if __name__ == "__main__":
    main()
