"""Is the diagnosis' confidence calibrated? Out-of-catalog records against catalog records.

    python3 bench/bench_diagnosis_calibration.py [--draws N] [--seed S] [--duration T]

(a) ``N`` records with an effect outside the catalog, drawn from several physical families the catalog
does not contain (a constant torque fixed in the body, a constant torque fixed in inertial space, a
quadratic (aerodynamic-like) damping of the body rates, a periodic torque at a random frequency, a
short torque impulse at a random time, a quadratic hinge damping), on the tumbling body or the hinged
panel of cases/diagnose_*.toml, scaled so that the largest channel departs from the nominal model by
3 to 100 noise sigmas RMS (log-uniform), default noise: the rate at which a catalog cause is named with
confidence >= 0.5 (goal <= 5 %).
(b) ``N`` records with one catalog effect (the fast tests' draw, tests/riskassess/diagnosis/test_diagnose.py):
the rate at which the right cause is named (goal >= 95 %).
Prints both rates with the number of draws, every miss, the wall time and the load. The two parts run
interleaved (one draw of each in turn, each part with its own generator: the same draws as one part
after the other), so a run stopped early has both rates over the same number of draws; each line gives
the running count and, when the catalog selection named a cause, its BIC margin over the best generic
"none of these" form (riskassess.diagnosis.discrepancy). The data come from the Exudyn model
(riskassess.diagnosis.exudyn_model), the fit from the compiled model.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from riskassess.diagnosis.exudyn_model import ExudynScenario  # noqa: E402
from riskassess.diagnosis.model import predict  # noqa: E402
from riskassess.diagnosis.plants.plant import Plant  # noqa: E402
from riskassess.diagnosis.synthetic import channel_noise, sample_times  # noqa: E402
from riskassess.products.measured import write_measured  # noqa: E402
from riskassess.stages.diagnose import diagnose_case  # noqa: E402
from tests.riskassess.diagnosis.conftest import HINGED_CASE, TUMBLING_CASE, case_with  # noqa: E402
from tests.riskassess.diagnosis.test_diagnose import FAST_EFFECTS, hidden_effect_data  # noqa: E402

#: Out-of-catalog families: name -> (scenarios, builder(scenario, rng, duration) -> adds a unit-strength load).
FAMILIES = ("body_fixed_torque", "inertial_torque", "quadratic_rate_damping", "periodic_torque", "torque_impulse",
            "quadratic_hinge_damping")


def add_family(scenario: ExudynScenario, family: str, strength: float, rng, duration: float) -> None:
    """Add ``family`` at ``strength`` (N m, or N m s^2 for the quadratic dampings) to the scenario."""
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    if family == "body_fixed_torque":
        scenario.add_body_torque(lambda t, k, rot, omega: strength * direction if k == 0 else np.zeros(3))
    elif family == "inertial_torque":
        scenario.add_body_torque(lambda t, k, rot, omega: strength * rot.T @ direction if k == 0 else np.zeros(3))
    elif family == "quadratic_rate_damping":
        scenario.add_body_torque(lambda t, k, rot, omega: -strength * np.linalg.norm(omega) * np.asarray(omega)
                                 if k == 0 else np.zeros(3))
    elif family == "periodic_torque":
        frequency, phase = rng.uniform(0.05, 0.5), rng.uniform(0, 2 * np.pi)
        scenario.add_body_torque(lambda t, k, rot, omega: strength * np.sin(2 * np.pi * frequency * t + phase)
                                 * direction if k == 0 else np.zeros(3))
    elif family == "torque_impulse":
        start = rng.uniform(0.2, 0.6) * duration
        scenario.add_body_torque(lambda t, k, rot, omega: strength * direction if k == 0 and start <= t < start + 0.5
                                 else np.zeros(3))
    elif family == "quadratic_hinge_damping":
        scenario.add_hinge_torque(lambda t, angle, rate: -strength * rate * abs(rate))


def departure_sigmas(clean: dict, nominal: dict) -> float:
    """Largest channel RMS departure of ``clean`` from ``nominal`` in noise sigmas; the quaternion taken
    with the sign nearest the nominal one (q and -q are one attitude, as the fit aligns them)."""
    clean = dict(clean)
    q = [c for c in ("q_w", "q_x", "q_y", "q_z") if c in clean]
    if len(q) == 4:
        sign = np.sign(sum(clean[c] * nominal[c] for c in q))
        sign[sign == 0] = 1.0
        clean.update({c: clean[c] * sign for c in q})
    return max(np.sqrt(np.mean((clean[c] - nominal[c]) ** 2)) / channel_noise(c) for c in nominal)


def out_of_catalog_record(rng, duration: float):
    """(case path, times, measured channels, description) of one out-of-catalog draw."""
    family = str(rng.choice(FAMILIES))
    path = HINGED_CASE if family == "quadratic_hinge_damping" or rng.random() < 0.5 else TUMBLING_CASE
    case = case_with(path)
    plant = Plant.from_case(case)
    times = sample_times(duration, 10.0)
    nominal = predict(plant, times)
    target = 10 ** rng.uniform(np.log10(3.0), 2.0)           # sigmas, log-uniform 3-100
    state = rng.bit_generator.state

    def departure(strength):
        rng.bit_generator.state = state                       # the same draw of direction, frequency, time
        scenario = ExudynScenario(plant)
        add_family(scenario, family, strength, rng, duration)
        clean = scenario.simulate(times)
        return clean, departure_sigmas(clean, nominal)

    strength = 1e-3
    clean, sigmas = departure(strength)
    for _ in range(4):                                        # the response is near-linear in the strength
        strength *= target / max(sigmas, 1e-12)
        clean, sigmas = departure(strength)
        if abs(np.log(sigmas / target)) < 0.2:
            break
    measured = {c: v + rng.normal(0.0, channel_noise(c), v.shape) for c, v in clean.items()}
    return path, times, measured, f"{family} on {path.stem} ({sigmas:.0f} sigma)"


def catalog_record(rng, duration: float):
    path = TUMBLING_CASE if rng.random() < 0.5 else HINGED_CASE
    case = case_with(path)
    effect_id = str(rng.choice(FAST_EFFECTS[case.kind]))
    times = sample_times(duration, 10.0)
    values, _, measured = hidden_effect_data(case, effect_id, rng, times)
    return path, times, measured, effect_id


def diagnose(path, times, measured, workdir: Path) -> dict:
    workdir.mkdir()
    data = workdir / "measured.csv"
    write_measured(data, times, measured)
    case = workdir / path.name
    case.write_text(path.read_text())
    return diagnose_case(case, data, workdir / "out", figures=False)


def generic_margin(answer: dict) -> str:
    """The best catalog model's BIC margin over the best generic form, when every form was fitted (a
    cause was named by the catalog selection), as text for the log."""
    entry = answer.get("none_of_these") or {}
    if len(entry.get("forms", {})) < 2 or not answer["candidates"]:
        return ""
    best = max(answer["candidates"], key=lambda c: c["delta_bic"])
    return f" (catalog {best['id']} vs generic {entry['best']}: {best['delta_bic'] - entry['delta_bic']:+.1f} in BIC)"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--draws", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--duration", type=float, default=40.0)
    parser.add_argument("--skip", type=int, default=0, help="draw but do not diagnose the first SKIP pairs "
                        "(to continue a stopped run: the rates then count the remaining draws only)")
    args = parser.parse_args()
    start, load = time.perf_counter(), os.getloadavg()[0]
    false_claims, misses = [], []
    with tempfile.TemporaryDirectory() as tmp:
        # the two parts interleaved (each with its own generator, so the draws are those of running them
        # one after the other): a run stopped early has both rates over the same number of draws
        rng_out, rng_in = np.random.default_rng(args.seed), np.random.default_rng(args.seed + 10_000)
        for k in range(args.draws):
            path, times, measured, what = out_of_catalog_record(rng_out, args.duration)
            if k < args.skip:
                catalog_record(rng_in, args.duration)
                continue
            answer = diagnose(path, times, measured, Path(tmp) / f"out-of-catalog-{k}")
            claimed = answer["cause"] not in ("none", "unexplained") and (answer["confidence"] or 0) >= 0.5
            if claimed:
                false_claims.append(f"{what}: named {answer['cause']} ({answer['confidence']:.2f})")
            print(f"out-of-catalog {k + 1}/{args.draws}: {what} -> {answer['cause']}"
                  f"{' CLAIMED' if claimed else ''}{generic_margin(answer)} [{len(false_claims)} claims]", flush=True)
            path, times, measured, effect_id = catalog_record(rng_in, args.duration)
            answer = diagnose(path, times, measured, Path(tmp) / f"catalog-{k}")
            if answer["cause"] != effect_id:
                misses.append(f"{effect_id} on {path.stem}: answered {answer['cause']}")
            print(f"catalog {k + 1}/{args.draws}: {effect_id} on {path.stem} -> {answer['cause']}"
                  f"{'' if answer['cause'] == effect_id else ' MISS'}{generic_margin(answer)} [{len(misses)} misses]",
                  flush=True)
    n = args.draws - args.skip
    print(f"\n{2 * n} diagnoses of {args.duration:g} s records in {time.perf_counter() - start:.0f} s, "
          f"load average {load:.1f} -> {os.getloadavg()[0]:.1f}")
    print(f"out of catalog: a catalog cause named with confidence >= 0.5 in {len(false_claims)} of {n} "
          f"({100 * len(false_claims) / n:.1f} %; goal <= 5 %)")
    for line in false_claims:
        print(f"  {line}")
    print(f"catalog: the right cause named in {n - len(misses)} of {n} ({100 * (n - len(misses)) / n:.1f} %; "
          f"goal >= 95 %)")
    for line in misses:
        print(f"  {line}")


if __name__ == "__main__":
    main()
