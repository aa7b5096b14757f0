"""The decision rule of riskassess.diagnosis.selection on hand-made fits (BIC values and residual RMS)."""
from __future__ import annotations

import numpy as np
import pytest

from riskassess.diagnosis.fit import FitResult
from riskassess.diagnosis.selection import decide, posterior_weights

N = 3000   # training samples: ln N = 8.0 per parameter


def _fit(name, chi2, k):
    return FitResult(name, ["p"] * k, ["-"] * k, np.zeros(k), np.zeros(k), 0, chi2, 0.0, N, 0.0, 0, "")


def _score(train_rms, holdout_rms):
    return {"train": {"omega_x": {"rms_sigma": train_rms}}, "holdout": {"omega_x": {"rms_sigma": holdout_rms}},
            "train_rms_sigma": train_rms, "holdout_rms_sigma": holdout_rms}


def test_weights_are_the_bic_posterior():
    fits = {"nominal": _fit("nominal", 3000.0, 2), "a": _fit("a", 3000.0 - 2 * np.log(N), 3)}
    # one more parameter costs ln N, the chi^2 fell by 2 ln N: delta BIC = ln N, odds e^(ln N / 2)
    w = posterior_weights(fits)
    assert w["a"] / w["nominal"] == pytest.approx(np.sqrt(N)) and sum(w.values()) == pytest.approx(1.0)


def test_decisive_adequate_effect_is_named():
    fits = {"nominal": _fit("nominal", 9000.0, 2), "a": _fit("a", 3000.0, 3), "b": _fit("b", 8000.0, 3)}
    scores = {"nominal": _score(1.7, 1.8), "a": _score(1.0, 1.0), "b": _score(1.6, 1.7)}
    answer = decide(fits, scores, 10.0, 1.25)
    assert answer["cause"] == "a" and answer["confidence"] > 0.999


def test_two_effects_explaining_alike_are_ambiguous():
    fits = {"nominal": _fit("nominal", 9000.0, 2), "a": _fit("a", 3000.0, 3), "b": _fit("b", 3005.0, 3)}
    scores = {"nominal": _score(1.7, 1.8), "a": _score(1.0, 1.0), "b": _score(1.0, 1.0)}
    answer = decide(fits, scores, 10.0, 1.25)
    assert answer["cause"] == "unexplained" and "ambiguous" in answer["reason"]


def test_noise_like_nominal_residual_is_no_discrepancy():
    # a candidate better by 6 (< 10) is not decisive; the nominal residual is at the noise
    fits = {"nominal": _fit("nominal", 3000.0, 2), "a": _fit("a", 3000.0 - 6.0 - np.log(N), 3)}
    scores = {"nominal": _score(1.0, 1.01), "a": _score(0.999, 1.0)}
    assert decide(fits, scores, 10.0, 1.25)["cause"] == "none"


def test_partial_explanation_leaves_it_unexplained():
    # decisive but the residual stays at 2 sigma: the effect absorbs part of something else
    fits = {"nominal": _fit("nominal", 30000.0, 2), "a": _fit("a", 12000.0, 3)}
    scores = {"nominal": _score(3.2, 3.5), "a": _score(2.0, 2.4)}
    answer = decide(fits, scores, 10.0, 1.25)
    assert answer["cause"] == "unexplained" and answer["confidence"] is None


def test_tiny_decisive_improvement_is_not_a_cause():
    # 0.5 % better: a decisive BIC on many samples, but not material
    fits = {"nominal": _fit("nominal", 3100.0, 2), "a": _fit("a", 3060.0, 3)}
    scores = {"nominal": _score(1.02, 1.02), "a": _score(1.015, 1.015)}
    assert decide(fits, scores, 10.0, 1.25)["cause"] == "none"


def _channels(train: dict, holdout: dict):
    """Scores of several channels: per channel RMS (sigma), the aggregate as selection.aggregate_rms."""
    def total(rms):
        return float(np.sqrt(np.mean(np.square(list(rms.values())))))
    return {"train": {c: {"rms_sigma": v} for c, v in train.items()},
            "holdout": {c: {"rms_sigma": v} for c, v in holdout.items()},
            "train_rms_sigma": total(train), "holdout_rms_sigma": total(holdout)}


def test_effect_seen_in_one_of_many_channels_is_material():
    # twelve channels at the noise and the tension at 1.2 sigma: the aggregate RMS falls only from 1.0168 to
    # 1.0 (1.7 %, below MIN_GAIN_PERCENT), the tension's from 1.2 to 1.0 (16.7 %): material in that channel
    quiet = {f"c{i}": 1.0 for i in range(12)}
    fits = {"nominal": _fit("nominal", 3400.0, 2), "a": _fit("a", 3000.0, 3)}
    scores = {"nominal": _channels({**quiet, "tension": 1.2}, {**quiet, "tension": 1.2}),
              "a": _channels({**quiet, "tension": 1.0}, {**quiet, "tension": 1.0})}
    assert scores["nominal"]["holdout_rms_sigma"] == pytest.approx(np.sqrt((12 + 1.2 ** 2) / 13), abs=1e-12)
    assert decide(fits, scores, 10.0, 1.25)["cause"] == "a"
    # the same 0.5 % gain as above in that one channel is still not material
    scores["nominal"] = _channels({**quiet, "tension": 1.02}, {**quiet, "tension": 1.02})
    scores["a"] = _channels({**quiet, "tension": 1.015}, {**quiet, "tension": 1.015})
    assert decide(fits, scores, 10.0, 1.25)["cause"] == "none"


def test_model_step_error_widens_the_adequacy_bound():
    # a residual of 3 sigma left by a model whose own discretization error is 3 sigma in that channel is
    # what the model can do (3^2 <= 1.25^2 + 3^2); without the step error it is only a partial explanation
    fits = {"nominal": _fit("nominal", 3.0e6, 2), "a": _fit("a", 3.0e4, 3)}
    scores = {"nominal": _score(30.0, 30.0), "a": _score(3.0, 3.0)}
    assert decide(fits, scores, 10.0, 1.25)["cause"] == "unexplained"
    scores["a"]["train"]["omega_x"]["step_error_sigma"] = 3.0
    answer = decide(fits, scores, 10.0, 1.25)
    assert answer["cause"] == "a" and "step error (up to 3 sigma)" in answer["reason"]
    scores["a"]["train"]["omega_x"]["step_error_sigma"] = 2.5      # 9 > 1.5625 + 6.25
    assert decide(fits, scores, 10.0, 1.25)["cause"] == "unexplained"
