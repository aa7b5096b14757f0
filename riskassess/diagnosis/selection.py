"""Model selection: which effect, if any, the data decisively call for.

Each model (the nominal and nominal + one effect) is scored by the Bayesian information
criterion with the Gaussian noise model on the training part,
BIC = chi^2 + k ln n (Schwarz 1978; the common constants dropped), and by its prediction of the
held-out part it was not fitted on. A cause is named only when all of these hold:

1. decisive against the nominal: BIC_nominal - BIC_best > ``decisive_delta_bic`` (10: "very
   strong" evidence, Kass & Raftery 1995, J. Am. Stat. Assoc. 90, 773, Sec. 3.2);
2. decisive against the runner-up effect (same threshold), otherwise the data cannot tell them
   apart and the answer is "unexplained" (ambiguous); a runner-up counts only if it meets the
   held-out condition of item 4 itself (it does not predict the held-out part worse than the
   nominal model): an effect that makes the unseen data worse explains nothing there, however
   close its training BIC (named in the reason as "not rivals");
3. adequate: the extended model's training residual RMS is within ``adequate_rms`` sigma in every
   channel (what is left is noise), otherwise the effect only absorbs part of something else; a
   model's own discretization error e (noise sigmas, when given) widens that to
   sqrt(adequate_rms^2 + e^2): no model can be asked to fit better than it integrates; and what
   is left has no structure, on the training and on the held-out part (:func:`structure`: not
   white by Ljung-Box with a material autocorrelation, or a material trend). A model whose
   residuals keep structure explains part of the data, not its cause: an effect outside the
   catalog was once named with confidence 1.00 while its residual RMS passed (1.04 / 1.09 sigma)
   and Ljung-Box gave p = 0;
3b. plausible: no nominal parameter fitted more than ``PRIOR_PULL_LIMIT`` prior sigmas from its
   prior centre; a fit that needs one there is evidence of a missing effect (a body rate fitted at
   44 sigma once soaked up a sensor bias), so the answer is "unexplained" with the pull named;
4. material: it improves the residual RMS by at least ``MIN_GAIN_PERCENT``, over all channels or in
   the channel where the nominal model departs most (training or held-out part), and does not
   predict the held-out part worse overall.

Otherwise the answer is "none" (no significant discrepancy: the nominal model is adequate) or
"unexplained" (the nominal model is not, and no single catalog effect explains it).
Confidence is the BIC posterior weight of the answer's model among all fitted models
(equal prior odds): exp(-BIC/2) normalized.
"""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.fit import FitResult, Problem
from riskassess.diagnosis.residuals import LJUNG_BOX_LAGS, ljung_box, normalized_residuals, trend

#: Smallest gain (normalized RMS, %, training or held-out; over all channels or in the nominal model's
#: worst channel) for a named cause: an effect that is decisive but improves the fit by less than 5 %
#: absorbs a small model difference (a residual excess below ~0.3 sigma RMS), it is not the cause the
#: user is after. The worst channel counts on its own because an aggregate over a dozen channels
#: dilutes an effect seen in one of them: a soft, fast viscoelastic tether (2000 N/m, 10 s) moves only
#: the tension and gained 3 % overall with a delta BIC of 1231 (docs/diagnosis.md).
MIN_GAIN_PERCENT = 5.0

#: A residual is "not white" at a Ljung-Box p-value below this. Per test; with a dozen channels, two
#: parts and two tests a model faces ~50 tests, so 1e-6 keeps the chance that noise alone rejects a
#: right model below 1e-4 (Bonferroni).
STRUCTURE_P = 1e-6
#: ... and only when the autocorrelation is material: its RMS over the Ljung-Box lags above 0.05
#: (white noise gives ~1/sqrt(n): 0.018 for 3000 samples). The failure this guards against had
#: 0.08-0.3; a right model whose noise estimate is a little off stays near the white level.
STRUCTURE_ACF_RMS = 0.05
#: A trend is material when the straight line through the residual moves by more than this over
#: the part (sigmas), at p < STRUCTURE_P.
STRUCTURE_TREND_SIGMA = 0.5
#: A channel whose model step error is above this (sigmas) is not tested for structure: the
#: model's own discretization error is structured by nature (fit.step_error_sigma).
STRUCTURE_STEP_ERROR = 0.5
#: Largest pull of a fitted nominal parameter from its prior centre (prior sigmas) for a named
#: answer. With ~10 nominal parameters drawn from their priors, all lie within 3.5 sigma with
#: probability 0.995.
PRIOR_PULL_LIMIT = 3.5


def posterior_weights(fits: dict[str, FitResult], temper: float = 1.0) -> dict[str, float]:
    """BIC posterior weight of every model, equal prior odds: exp(-temper BIC/2) normalized.

    ``temper`` < 1 widens the weights where BIC differences are inflated by something the likelihood
    does not hold, as chaotic draws of the same model are: with a decisive threshold raised from D to T
    by the chaos, a difference of T carries the evidence a difference of D carries without it, so the
    differences are scaled by D/T and "decisive" keeps meaning odds of exp(D/2) on either scale.

    Parameters
    ----------
    fits : dict of str to FitResult
        Fitted models by id ("nominal", effect ids, pairs "a+b").
    temper : float, optional
        Factor on every BIC difference, in (0, 1] (-); 1 is the plain BIC weight.

    Returns
    -------
    weights : dict of str to float
        Per model id, summing to 1 (-).
    """
    if not 0.0 < temper <= 1.0:
        raise ValueError(f"temper must be in (0, 1], got {temper}")
    bic = {k: f.bic for k, f in fits.items()}
    low = min(bic.values())
    w = {k: np.exp(-0.5 * temper * (b - low)) for k, b in bic.items()}
    total = sum(w.values())
    return {k: float(v / total) for k, v in w.items()}


def channel_rms(problem: Problem, model: dict, part: np.ndarray) -> dict:
    """Per channel: normalized RMS residual and RMSE (channel units) over the samples ``part``, and
    the residual's structure (:func:`structure`).

    Parameters
    ----------
    problem : Problem
        The measured channels, their noise (channel units) and times (s).
    model : dict of str to (k,) float
        Predicted channels at every sample of the record.
    part : (k,) bool
        Mask of the samples to score.

    Returns
    -------
    figures : dict of str to dict
        Per channel: ``rms_sigma`` (-), ``rmse`` (channel unit) and :func:`structure`'s figures.
    """
    measured = {c: v[part] for c, v in problem.values.items()}
    r = normalized_residuals({c: v[part] for c, v in model.items()}, measured, problem.noise)
    out = {}
    for c, res in r.items():
        ok = np.isfinite(res)
        rms = float(np.sqrt(np.mean(res[ok] ** 2)))
        out[c] = {"rms_sigma": rms, "rmse": rms * problem.noise[c], **structure(problem.time[part], res)}
    return out


def structure(time, r) -> dict:
    """What is left in a normalized residual ``r`` beyond white noise: Ljung-Box p-value and the RMS
    of the autocorrelation over its lags, the trend's p-value and its rise over the part (sigmas);
    ``structured`` when either is significant (p < :data:`STRUCTURE_P`) and material.

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    r : (k,) float
        Normalized residual (-), NaN where missing.

    Returns
    -------
    figures : dict
        ``white_p``, ``acf_rms`` (-), ``trend_p``, ``trend_rise_sigma`` (sigma), ``structured`` (bool).
    """
    ok = np.isfinite(r)
    if ok.sum() < 16:
        return {"white_p": 1.0, "acf_rms": 0.0, "trend_p": 1.0, "trend_rise_sigma": 0.0, "structured": False}
    q, p_white = ljung_box(r)
    lags = min(LJUNG_BOX_LAGS, int(ok.sum()) // 4)
    n = int(ok.sum())
    # Q = n (n + 2) sum acf_k^2 / (n - k): recover the RMS autocorrelation over the lags
    acf_rms = float(np.sqrt(q / (n * (n + 2)) * (n - 0.5 * (lags + 1)) / lags))
    slope, p_trend = trend(time, r)
    rise = abs(slope) * float(np.ptp(time[ok]))
    structured = bool((p_white < STRUCTURE_P and acf_rms > STRUCTURE_ACF_RMS)
                      or (p_trend < STRUCTURE_P and rise > STRUCTURE_TREND_SIGMA))
    return {"white_p": p_white, "acf_rms": acf_rms, "trend_p": p_trend, "trend_rise_sigma": rise,
            "structured": structured}


def structured_channels(model_scores: dict) -> list[str]:
    """'channel (part)' of every channel whose residual keeps structure, training or held-out, leaving
    out channels dominated by the model's own step error (:data:`STRUCTURE_STEP_ERROR`).

    Parameters
    ----------
    model_scores : dict
        One model's :func:`score` figures (``train`` and ``holdout`` per channel).

    Returns
    -------
    channels : list of str
        Descriptions for the report.
    """
    out = []
    for part in ("train", "holdout"):
        for c, v in model_scores[part].items():
            step_error = model_scores["train"][c].get("step_error_sigma", 0.0)
            if v.get("structured") and step_error <= STRUCTURE_STEP_ERROR:
                out.append(f"{c} ({'training' if part == 'train' else 'held-out'}: {_structure_text(v)})")
    return out


def _structure_text(v: dict) -> str:
    parts = []
    if v["white_p"] < STRUCTURE_P and v["acf_rms"] > STRUCTURE_ACF_RMS:
        parts.append(f"not white, autocorrelation {v['acf_rms']:.2f}")
    if v["trend_p"] < STRUCTURE_P and v["trend_rise_sigma"] > STRUCTURE_TREND_SIGMA:
        parts.append(f"trend of {v['trend_rise_sigma']:.2g} sigma")
    return ", ".join(parts)


def prior_pulls(fit: FitResult, problem: Problem) -> dict[str, float]:
    """Fitted nominal parameters more than :data:`PRIOR_PULL_LIMIT` prior sigmas from their centre:
    name -> pull (sigmas, signed).

    Parameters
    ----------
    fit : FitResult
        A fitted model (its nominal values first, in their units).
    problem : Problem
        The priors: centres (parameter units) and 1-sigma.

    Returns
    -------
    pulls : dict of str to float
        (value - centre) / sigma (-), only beyond the limit.
    """
    n = fit.nominal_count
    z = (np.asarray(fit.values[:n], float) - problem.nominal_center) / problem.nominal_sigma
    return {name: float(v) for name, v in zip(fit.names[:n], z) if abs(v) > PRIOR_PULL_LIMIT}


def aggregate_rms(per_channel: dict) -> float:
    """RMS over channels of their normalized RMS (sigma units).

    Parameters
    ----------
    per_channel : dict of str to dict
        :func:`channel_rms` figures (their ``rms_sigma``).

    Returns
    -------
    rms : float
        (-).
    """
    return float(np.sqrt(np.mean([v["rms_sigma"] ** 2 for v in per_channel.values()])))


def score(problem: Problem, predictions: dict[str, dict], step_errors: dict | None = None) -> dict[str, dict]:
    """Training and held-out figures of every model's prediction over the whole record; ``step_errors``:
    model -> channel -> its discretization error on the training part (sigmas, fit.step_error_sigma).

    Parameters
    ----------
    problem : Problem
        The measured record and its training mask.
    predictions : dict of str to dict
        Per model id, its channels at every sample (channel units).
    step_errors : dict of str to dict of str to float, optional
        Per model id and channel, the discretization error (-).

    Returns
    -------
    scores : dict of str to dict
        Per model id: ``train`` and ``holdout`` per-channel figures (:func:`channel_rms`) and their
        aggregates ``train_rms_sigma``, ``holdout_rms_sigma`` (-).
    """
    test = ~problem.train
    out = {}
    for key, model in predictions.items():
        train, held = channel_rms(problem, model, problem.train), channel_rms(problem, model, test)
        for c, error in (step_errors or {}).get(key, {}).items():
            train[c]["step_error_sigma"] = error
        out[key] = {"train": train, "holdout": held, "train_rms_sigma": aggregate_rms(train),
                    "holdout_rms_sigma": aggregate_rms(held)}
    return out


def gain_percent(before: float, after: float) -> float:
    """Relative improvement from ``before`` to ``after`` (%); 0 when ``before`` is 0.

    Parameters
    ----------
    before, after : float
        RMS values (same unit, here sigma).

    Returns
    -------
    gain : float
        (%).
    """
    return float(100.0 * (before - after) / before) if before > 0 else 0.0


def material_gain(scores: dict[str, dict], key: str) -> float:
    """Largest gain (%) of model ``key`` over the nominal model: overall or in the channel the nominal
    model fits worst, on the training or the held-out part.

    Parameters
    ----------
    scores : dict of str to dict
        Per model id, :func:`score`'s figures.
    key : str
        The model's id.

    Returns
    -------
    gain : float
        (%).
    """
    gains = []
    for part in ("train", "holdout"):
        nominal, model = scores["nominal"][part], scores[key][part]
        worst = max(nominal, key=lambda c: nominal[c]["rms_sigma"])
        gains += [gain_percent(scores["nominal"][f"{part}_rms_sigma"], scores[key][f"{part}_rms_sigma"]),
                  gain_percent(nominal[worst]["rms_sigma"], model[worst]["rms_sigma"])]
    return max(gains)


def _no_rival_note(ranked: list[str], rivals: list[str]) -> str:
    """' (not rivals: ...)' naming the candidates left out of the margin because their held-out prediction was
    worse than the nominal model's, or ''."""
    left = [k for k in ranked[1:] if k not in rivals]
    return f" (not rivals, held-out prediction worse than the nominal model's: {', '.join(left)})" if left else ""


def _step_note(scores: dict) -> str:
    """What the statement adds when the model's own step error widened the adequacy bound."""
    error = max(v.get("step_error_sigma", 0.0) for v in scores["train"].values())
    return f" plus the model's own step error (up to {error:.2g} sigma)" if error > 0.1 else ""


def _rms_adequate(model_scores: dict, adequate_rms: float) -> bool:
    return all(v["rms_sigma"] ** 2 <= adequate_rms ** 2 + v.get("step_error_sigma", 0.0) ** 2
               for v in model_scores["train"].values())


def decide(fits: dict[str, FitResult], scores: dict[str, dict], decisive: float, adequate_rms: float,
           problem: Problem | None = None, temper: float = 1.0) -> dict:
    """The answer: cause (an effect id, "none" or "unexplained"), confidence, and why (module
    docstring). ``problem`` gives the priors for the pull check (3b); without it the check is off.

    Parameters
    ----------
    fits : dict of str to FitResult
        Fitted models by id ("nominal", effect ids, pairs "a+b").
    scores : dict of str to dict
        Per model id, :func:`score`'s figures.
    decisive : float
        BIC difference counted as decisive (-).
    adequate_rms : float
        Largest training residual RMS of an adequate model (noise sigmas, -).
    problem : Problem, optional
        The priors of the nominal parameters.
    temper : float, optional
        :func:`posterior_weights`' factor on BIC differences, so that the confidence is on the same
        scale as ``decisive`` (the impact scenario passes its case threshold over the chaos-widened one).

    Returns
    -------
    answer : dict
        ``cause``, ``model``, ``confidence`` (-, or None), ``reason`` and the figures behind them
        (``weights``, ``ranked``, ``adequate``, ``structure``, ``prior_pulls``).
    """
    weights = posterior_weights(fits, temper)
    nominal = fits["nominal"]
    ranked = sorted((k for k in fits if k != "nominal"), key=lambda k: fits[k].bic)
    structure_left = {k: structured_channels(s) for k, s in scores.items()}
    pulls = {k: prior_pulls(f, problem) if problem is not None else {} for k, f in fits.items()}
    adequate = {k: _rms_adequate(s, adequate_rms) and not structure_left[k] for k, s in scores.items()}
    answer = {"weights": weights, "ranked": ranked, "adequate": adequate, "structure": structure_left,
              "prior_pulls": pulls}
    if ranked:
        best = ranked[0]
        delta = nominal.bic - fits[best].bic
        gain = gain_percent(scores["nominal"]["holdout_rms_sigma"], scores[best]["holdout_rms_sigma"])
        # a rival explanation must meet the held-out condition the best one must meet: a candidate that
        # predicts the held-out data worse than the nominal model explains nothing there, however close its BIC
        rivals = [k for k in ranked[1:]
                  if gain_percent(scores["nominal"]["holdout_rms_sigma"], scores[k]["holdout_rms_sigma"]) >= 0]
        runner_up = rivals[0] if rivals else "-"
        margin = fits[runner_up].bic - fits[best].bic if rivals else np.inf
        gain_train = gain_percent(scores["nominal"]["train_rms_sigma"], scores[best]["train_rms_sigma"])
        decisive_and_material = (delta > decisive and material_gain(scores, best) >= MIN_GAIN_PERCENT
                                 and gain >= 0 and _rms_adequate(scores[best], adequate_rms))
        if decisive_and_material and structure_left[best]:
            return {**answer, "cause": "unexplained", "model": best, "confidence": None,
                    "reason": f"the best candidate ({best}, BIC lower by {delta:.1f} than the nominal model) leaves "
                              f"structure in its residuals, so it explains part of the data, not its cause: "
                              f"{'; '.join(structure_left[best])}"}
        if decisive_and_material and pulls[best]:
            return {**answer, "cause": "unexplained", "model": best, "confidence": None,
                    "reason": f"the best candidate ({best}) needs {_pull_text(pulls[best])} from the case's priors: "
                              f"evidence of a missing effect, not of {best} alone"}
        if decisive_and_material:
            if margin > decisive:
                return {**answer, "cause": best, "model": best, "confidence": weights[best],
                        "reason": f"{best}: BIC lower by {delta:.1f} than the nominal model and by {margin:.1f} than "
                                  f"the runner-up {runner_up}{_no_rival_note(ranked, rivals)}; residual within "
                                  f"{adequate_rms:g} sigma{_step_note(scores[best])} and white, training and "
                                  f"held-out; fit {gain_train:.0f} % and held-out prediction {gain:.0f} % better"}
            close = [best] + [k for k in rivals if fits[k].bic - fits[best].bic <= decisive]
            return {**answer, "cause": "unexplained", "model": best, "confidence": None,
                    "reason": f"ambiguous: {', '.join(close)} explain the data about equally (BIC within "
                              f"{decisive:g}); no single cause is decisive"}
    if adequate["nominal"] and not pulls["nominal"]:
        return {**answer, "cause": "none", "model": "nominal", "confidence": weights["nominal"],
                "reason": f"no significant discrepancy: the nominal model's residual is within {adequate_rms:g} "
                          f"sigma and white in every channel and no effect is decisively better"}
    best = ranked[0] if ranked else "nominal"
    if adequate["nominal"]:
        why = f"it needs {_pull_text(pulls['nominal'])} from the case's priors (evidence of a missing effect)"
        return {**answer, "cause": "unexplained", "model": "nominal", "confidence": None,
                "reason": f"the nominal model fits only because {why}, and no catalog effect is decisively better"}
    why = "no candidate is decisively better" if not ranked or nominal.bic - fits[best].bic <= decisive else (
        f"the best candidate ({best}) leaves a residual above {adequate_rms:g} sigma or does not predict the "
        f"held-out data better")
    left = f"; what is left: {'; '.join(structure_left['nominal'])}" if structure_left["nominal"] else ""
    return {**answer, "cause": "unexplained", "model": "nominal", "confidence": None,
            "reason": f"the nominal model departs from the data and {why}{left}"}


def _pull_text(pulls: dict[str, float]) -> str:
    return ", ".join(f"{name} at {z:+.1f} sigma" for name, z in sorted(pulls.items(), key=lambda kv: -abs(kv[1])))
