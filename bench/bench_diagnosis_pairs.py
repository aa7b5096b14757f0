"""Two effects at once: hidden pairs (and single effects) on the hinged panel, named set and
parameters against truth, with each selection step's BIC gain and RMS.

Run: ``PYTHONPATH=. python bench/bench_diagnosis_pairs.py`` (about 10 s per record on a quiet core).
Data: the Exudyn model with both effects (``simulate_exudyn``), 40 s at 10 Hz, default noise; the fit
uses the compiled model, so the data are not made by the fitted model itself.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from riskassess.diagnosis.composite import EffectPair
from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.exudyn_model import simulate_exudyn
from riskassess.diagnosis.plants.scenario import plant_of
from riskassess.diagnosis.synthetic import channel_noise, sample_times
from tests.riskassess.diagnosis.conftest import HINGED_CASE, case_with
from tests.riskassess.diagnosis.test_diagnose import DURATION, _diagnose, draw_effect

#: (effects hidden, seed): two pairs and one single effect (which must stay single).
RECORDS = [(("hinge_coulomb_friction", "sensor_bias"), 1),
           (("hinge_stiffness_hardening", "sensor_time_delay"), 3),
           (("hinge_coulomb_friction",), 5)]


def hidden_record(case, effect_ids, rng, times):
    """Noisy channels of the Exudyn model with ``effect_ids`` hidden, and the true parameters."""
    truth = {}
    for e in effect_ids:
        truth.update(draw_effect(case, e, rng))
    plant = plant_of(case)
    channels = list(simulate_exudyn(plant, times[:3]))
    model = (EffectPair(CATALOG[effect_ids[0]], CATALOG[effect_ids[1]], case, channels, plant)
             if len(effect_ids) == 2 else CATALOG[effect_ids[0]])
    names = [p.name for p in (model.parameter_specs(case, channels) if len(effect_ids) == 2
                              else model.parameter_specs(case))]
    clean = simulate_exudyn(plant, times, model, np.array([truth[n] for n in names]), names)
    measured = {c: v + rng.normal(0.0, channel_noise(c), v.shape) for c, v in clean.items()}
    return measured, truth


def main() -> None:
    case = case_with(HINGED_CASE)
    times = sample_times(DURATION, 10.0)
    print("| hidden (seed) | named | steps: added, delta BIC, train/held-out RMS [sigma] | worst |fit-truth|/std | wall [s] |")
    print("|---|---|---|---|---|")
    for effect_ids, seed in RECORDS:
        rng = np.random.default_rng(seed)
        measured, truth = hidden_record(case, effect_ids, rng, times)
        with tempfile.TemporaryDirectory() as tmp:
            start = time.perf_counter()
            answer = _diagnose(Path(tmp), HINGED_CASE, measured, times)
            wall = time.perf_counter() - start
        steps = "; ".join(f"{s['added']} {s['delta_bic_over_previous']:.3g}, {s['train_rms_sigma']:.2f}/"
                          f"{s['holdout_rms_sigma']:.2f}" for s in answer.get("selection_steps", []))
        pulls = [abs(answer["parameters"][n]["value"] - v) / answer["parameters"][n]["std"]
                 for n, v in truth.items() if n in answer.get("parameters", {})]
        worst = f"{max(pulls):.1f}" if pulls else "-"
        named = " + ".join(answer.get("effects") or [answer["cause"]])
        print(f"| {' + '.join(effect_ids)} ({seed}) | {named} | {steps} | {worst} | {wall:.1f} |")


if __name__ == "__main__":
    main()
