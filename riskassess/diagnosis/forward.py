"""Forward selection: a second catalog effect when the best single one is not enough.

When the single-effect selection (:func:`riskassess.diagnosis.selection.decide`) answers "unexplained"
but its best candidate is decisive against the nominal model, the record may hold two effects at
once: the best single effect is fitted again together with each of the next :data:`PAIR_PARTNERS`
candidates (by BIC, :class:`riskassess.diagnosis.composite.EffectPair`), and the selection runs again
over every model. A pair is then named only under the same rules as a single effect: decisive
against the nominal model and against the runner-up (the best single effect alone, or another pair,
by ``decisive_delta_bic``), adequate (RMS and no structure left, training and held-out), no prior
pulled too far, material. One effect is never replaced by two without that evidence: a single-effect
record keeps its single answer (the pair gains less than the threshold over it).
"""
from __future__ import annotations

from riskassess.diagnosis.composite import EffectPair, can_pair
from riskassess.diagnosis.fit import FitResult

#: How many of the next-best single effects are each fitted together with the best one (3 pairs:
#: the fits cost about what 3 single candidates do).
PAIR_PARTNERS = 3


def pair_candidates(fits: dict[str, FitResult], effects: dict, decisive: float) -> list[tuple[str, str]]:
    """(best, partner) pairs to fit: the best single effect, if decisive against the nominal model,
    with each of the next :data:`PAIR_PARTNERS` effects it can be paired with.

    Parameters
    ----------
    fits : dict of str to FitResult
        Fitted single models by id (with "nominal").
    effects : dict of str to Effect
        The candidates by id.
    decisive : float
        BIC difference counted as decisive (-).

    Returns
    -------
    pairs : list of (str, str)
    """
    ranked = sorted((k for k in fits if k != "nominal" and "+" not in k), key=lambda k: fits[k].bic)
    if not ranked or fits["nominal"].bic - fits[ranked[0]].bic <= decisive:
        return []
    best = ranked[0]
    partners = [k for k in ranked[1:] if can_pair(effects[best], effects[k])][:PAIR_PARTNERS]
    return [(best, k) for k in partners]


def make_pairs(pairs, fits: dict[str, FitResult], effects: dict, problem) -> list[EffectPair]:
    """The pair models, each starting from both effects' single fits.

    Parameters
    ----------
    pairs : list of (str, str)
        Effect ids (:func:`pair_candidates`).
    fits : dict of str to FitResult
        Their single fits (the starting values, SI).
    effects : dict of str to Effect
        The candidates by id.
    problem : Problem
        The fit problem (case, channels, plant).

    Returns
    -------
    models : list of EffectPair
    """
    return [EffectPair(effects[a], effects[b], problem.case, problem.channels, problem.plant,
                       (fits[a].effect_values, fits[b].effect_values)) for a, b in pairs]


def selection_steps(fits: dict[str, FitResult], scores: dict, chosen: str) -> list[dict]:
    """The forward path to ``chosen``: each step's model, its BIC gain over the previous step, and
    its training and held-out RMS (sigmas).

    Parameters
    ----------
    fits : dict of str to FitResult
        Fitted models by id.
    scores : dict of str to dict
        Their :func:`riskassess.diagnosis.selection.score` figures.
    chosen : str
        The answer's model id ("nominal", an effect id or a pair "a+b").

    Returns
    -------
    steps : list of dict
        ``model``, ``added``, ``delta_bic_over_previous`` (-), ``train_rms_sigma`` and
        ``holdout_rms_sigma`` (-).
    """
    path = ["nominal"] + ([chosen.split("+")[0], chosen] if "+" in chosen else [chosen] if chosen != "nominal" else [])
    steps = []
    for before, after in zip(path, path[1:]):
        steps.append({"model": after, "added": after.split("+")[-1],
                      "delta_bic_over_previous": float(fits[before].bic - fits[after].bic),
                      "train_rms_sigma": scores[after]["train_rms_sigma"],
                      "holdout_rms_sigma": scores[after]["holdout_rms_sigma"]})
    return steps
