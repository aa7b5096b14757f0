"""How far round-off alone moves the step study's quantities (the first second of the reference case).

Usage: python3 bench/roundoff_spread.py [--eps 1e-12] [--end-time 1.0] [--step 1e-4]

Runs the reference case (``cases/envisat_net_impact.toml``) at the case's step and joints three times: as is
and with the net's launch velocity scaled by 1 + eps and 1 - eps, and prints the quantities of
``bench/step_convergence.py`` for each with their spread. A code change that should move results only at
round-off is judged against this spread (docs/model.md, Speed): the contacts amplify any difference in the
last bits, so the solar-array hinge peak, for one, moves by about 1 % between such runs.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from step_convergence import figures  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--eps", type=float, default=1e-12)
    parser.add_argument("--end-time", type=float, default=1.0)
    parser.add_argument("--step", type=float, default=1e-4)
    args = parser.parse_args()
    case = ROOT / "cases" / "envisat_net_impact.toml"
    scales = (1.0, 1.0 + args.eps, 1.0 - args.eps)
    rows = [figures(case, args.step, args.end_time, None, scale) for scale in scales]
    print(f"first {args.end_time:g} s at {args.step:g} s; launch velocity x 1, 1 + {args.eps:g}, 1 - {args.eps:g}")
    for key in rows[0]:
        values = [row[key] for row in rows]
        spread = (max(values) - min(values)) / abs(values[0]) * 100 if values[0] else 0.0
        print(f"{key:38s} " + " ".join(f"{v:12.6g}" for v in values) + f"   spread {spread:.2f} %")


if __name__ == "__main__":
    main()
