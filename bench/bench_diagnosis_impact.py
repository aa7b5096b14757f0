"""Impact-scenario diagnosis bench (docs/diagnosis.md, "Impact scenario"): a synthetic post-capture record
of the small Envisat case made by the coupled impact simulation itself with one impact-model parameter
changed by a known amount (and the launch speed perturbed by 3e-7, so the truth is not one of the
model's own draws) plus sensor noise, diagnosed by `riskassess diagnose`; prints the named cause, the
fitted parameter against the truth and the wall time.

    PYTHONPATH=$PWD .venv/bin/python bench/bench_diagnosis_impact.py                  # thread damping x 4, 20 s
    PYTHONPATH=$PWD .venv/bin/python bench/bench_diagnosis_impact.py --truth none     # no change: expect none
    PYTHONPATH=$PWD .venv/bin/python bench/bench_diagnosis_impact.py --truth launch_velocity_error=0.4 --start 1

Options: ``--truth EFFECT=VALUE`` (an impact catalog id and its parameter's value, SI) or ``none``;
``--start`` / ``--duration`` of the record (s from the launch); ``--rate`` (Hz); ``--seed``;
``--candidates`` (ids, default the catalog); ``--window``, ``--grid``, ``--ensemble`` (the case's ``[fit]``).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from riskassess.cases.impact import load_case  # noqa: E402
from riskassess.diagnosis.impact_effects import IMPACT_CATALOG  # noqa: E402
from riskassess.diagnosis.impact_plant import record_csv, simulate_record  # noqa: E402
from riskassess.diagnosis.synthetic import noisy  # noqa: E402
from riskassess.stages.diagnose import diagnose_case  # noqa: E402

IMPACT_CASE = ROOT / "cases" / "envisat_small.toml"
#: Relative launch-speed perturbation of the truth run: a draw of the capture's chaos the model does not share.
TRUTH_PERTURBATION = 3e-7


def make_record(folder: Path, truth: str, start: float, duration: float, rate: float, seed: int) -> tuple[Path, dict]:
    """The synthetic record CSV in ``folder`` and the truth (id, parameter name, value)."""
    impact = load_case(IMPACT_CASE)
    overrides, truth_info = {}, {"id": "none"}
    if truth != "none":
        effect_id, value = truth.split("=")
        effect = IMPACT_CATALOG[effect_id]
        overrides = effect.overrides(impact, float(value))
        truth_info = {"id": effect_id, "parameter": effect.parameter(impact).name, "value": float(value),
                      "case_value": effect.case_value(impact)}
    speed = float(overrides.get("launch.velocity", impact.launch.velocity))
    overrides["launch.velocity"] = speed * (1.0 + TRUTH_PERTURBATION)
    times, clean = simulate_record(IMPACT_CASE, overrides, start + duration, rate)
    keep = times >= start - 1e-9
    channels, sigma = noisy({c: v[keep] for c, v in clean.items()}, np.random.default_rng(seed))
    path = folder / "record.csv"
    path.write_text(record_csv(times[keep], channels))
    return path, {**truth_info, "noise": sigma}


def write_case(folder: Path, window: float, grid: int, ensemble: int) -> Path:
    shutil.copy(IMPACT_CASE, folder / IMPACT_CASE.name)
    path = folder / "diagnose_impact.toml"
    path.write_text(f'kind = "diagnosis"\nscenario = "impact"\nname = "bench_impact"\nimpact = "{IMPACT_CASE.name}"\n'
                    f"[fit]\nwindow = {window}\ngrid = {grid}\nensemble = {ensemble}\n")
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truth", default="thread_damping=6.32")
    parser.add_argument("--start", type=float, default=1.0)
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--rate", type=float, default=50.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--window", type=float, default=0.5)
    parser.add_argument("--grid", type=int, default=5)
    parser.add_argument("--ensemble", type=int, default=4)
    parser.add_argument("--candidates", nargs="*")
    parser.add_argument("--keep", help="folder to keep the record, case and diagnosis in")
    args = parser.parse_args(argv)
    folder = Path(args.keep or tempfile.mkdtemp(prefix="bench_impact_"))
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    record, truth = make_record(folder, args.truth, args.start, args.duration, args.rate, args.seed)
    record_s = time.perf_counter() - t0
    case = write_case(folder, args.window, args.grid, args.ensemble)
    t1 = time.perf_counter()
    answer = diagnose_case(case, record, folder / "diagnosis", candidates=args.candidates, figures=False,
                           overwrite=True)
    wall = time.perf_counter() - t1
    fitted = answer["parameters"]
    print(json.dumps({"truth": truth, "cause": answer["cause"], "confidence": answer["confidence"],
                      "statement": answer["statement"], "fitted": fitted,
                      "candidates": [{k: r[k] for k in ("id", "delta_bic", "parameters", "train_rms_sigma",
                                                          "holdout_rms_sigma", "adequate")} for r in answer["candidates"]],
                      "nominal": answer["nominal"], "chaos": answer["chaos"], "simulations": answer["simulations"],
                      "record_wall_s": record_s, "diagnosis_wall_s": wall, "diagnosis_cpu_s": answer["cpu_s"],
                      "load_average": os.getloadavg(), "folder": str(folder)}, indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
