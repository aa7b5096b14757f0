"""`riskassess diagnose`: where the simulation departs from measured data, the missing effect, its gain.

Steps: read the case (:mod:`riskassess.cases.diagnosis`) and the measured CSV
(:mod:`riskassess.diagnosis.measured`); fit the nominal model and nominal + each applicable catalog effect
on the training part (:mod:`riskassess.diagnosis.fit`, two worker processes); score every model on the
held-out part and select (:mod:`riskassess.diagnosis.selection`); analyse the residuals before and after
(:mod:`riskassess.diagnosis.residuals`) and hint at the form of what is left (:mod:`riskassess.diagnosis.hint`).
The impact scenario (the net capture, ``scenario = "impact"``) has its own fit and catalog
(:mod:`riskassess.diagnosis.impact_fit`); its answer is selected by the same rules.

Writes into the output folder (default ``runs/<case name>-diagnosis``), each file atomically:
``diagnosis.json`` (the answer), ``diagnosis.npz`` (time series behind the plots), PNG plots,
``case.toml`` (the input case) and, when a cause is named, the extended case
``<case stem>.extended.toml`` (only there: nothing is written beside the input case). The folder is
claimed before the fits start (:func:`riskassess.products.outfolder.claim`), its manifest ``running`` until
the last file is written.
"""
from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

import numpy as np

from riskassess.diagnosis.composite import EffectPair
from riskassess.diagnosis.discrepancy import generic_forms, none_of_these
from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.forward import make_pairs, pair_candidates, selection_steps
from riskassess.diagnosis.fit import (CandidateFit, FitResult, Problem, first_unpredicted_time, prediction,
                           step_error_sigma)
from multibody.health import SimulationFailed
from riskassess.diagnosis.impact_fit import diagnose_impact
from riskassess.diagnosis.hint import describe_terms, library, sparse_terms
from riskassess.diagnosis.plants.channels import CHANNELS
from riskassess.diagnosis.measured import read_measured
from riskassess.diagnosis.observation import scenario_channels
from riskassess.diagnosis.residuals import analyse, describe
from riskassess.diagnosis.selection import decide, gain_percent, posterior_weights, score
from riskassess.diagnosis.threads import single_threaded_blas
from riskassess.products import results
from riskassess.cases.impact import read_toml
from riskassess.cases.diagnosis import scenario_form, toml_text
from riskassess.diagnosis.cases import load_diagnosis_case
from riskassess.products.outfolder import OutputFolder, claim, default_out, safe_name
from riskassess.products.report.diagnosis import write_figures

#: Worker processes fitting candidates in parallel (the issue's 2-core machine).
WORKERS = 2
_PROBLEM: Problem | None = None    # what the forked workers fit (inherited, not pickled)


def _fit_one(task) -> FitResult:
    effect_id, nominal = task
    return CandidateFit(_PROBLEM, CATALOG[effect_id]).fit(nominal)


def _residuals_of(task):
    """One finite-difference column's residual vector, in a worker."""
    effect_id, z, use = task
    return CandidateFit(_PROBLEM, CATALOG.get(effect_id)).residuals(z, use)


def _cost_order(problem: Problem, effect_ids: list[str]) -> list[str]:
    """Candidates, the dearest first (starts x parameters): the workers then finish together (LPT)."""
    def cost(effect_id):
        effect = CATALOG[effect_id]
        specs = effect.parameter_specs(problem.case, problem.channels)
        return (len(effect.starts(specs)) + 1) * (len(problem.nominal_center) + len(specs))
    return sorted(effect_ids, key=cost, reverse=True)


def fit_candidates(problem: Problem, effect_ids: list[str], workers: int = WORKERS, progress=None) -> dict:
    """The nominal model (its finite-difference Jacobian columns in the worker processes), then every
    effect from the nominal fit, one per worker process (forked when ``workers`` > 1); returns
    id -> :class:`FitResult`.

    Parameters
    ----------
    problem : riskassess.diagnosis.fit.Problem
        The case, measured channels and the train / hold-out split.
    effect_ids : list of str
        Catalog ids of the effects to fit beside the nominal model.
    workers : int
        Worker processes (1: everything in this process).
    progress : callable or None
        ``progress("fitting", done, total)`` after each fitted model.

    Returns
    -------
    dict
        ``"nominal"`` and each effect id -> :class:`~riskassess.diagnosis.fit.FitResult`.
    """
    global _PROBLEM
    single_threaded_blas()
    _PROBLEM = problem
    total = len(effect_ids) + 1
    order = _cost_order(problem, effect_ids)
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        fits = {"nominal": CandidateFit(problem).fit()}
        for effect_id in order:
            if progress:
                progress("fitting", len(fits), total)
            fits[effect_id] = _fit_one((effect_id, fits["nominal"]))
        if progress:
            progress("fitting", len(fits), total)
        return fits
    with multiprocessing.get_context("fork").Pool(workers, initializer=single_threaded_blas) as pool:
        def columns(vectors, use):
            return pool.map(_residuals_of, [(None, z, use) for z in vectors])

        fits = {"nominal": CandidateFit(problem, columns=columns).fit()}
        if progress:
            progress("fitting", 1, total)
        for fit in pool.imap_unordered(_fit_one, [(k, fits["nominal"]) for k in order]):
            fits[fit.id] = fit
            if progress:
                progress("fitting", len(fits), total)
    return fits


def _parameters(fit: FitResult, nominal: bool) -> dict:
    rows = zip(fit.names, fit.values, fit.std, fit.units)
    picked = list(rows)[:fit.nominal_count] if nominal else list(rows)[fit.nominal_count:]
    return {n: {"value": float(v), "std": float(s), "unit": u} for n, v, s, u in picked}


def _candidate_rows(fits, scores, decision) -> list[dict]:
    nominal = fits["nominal"]
    return [{"id": k, "delta_bic": float(nominal.bic - fits[k].bic), "weight": decision["weights"][k],
             "parameters": _parameters(fits[k], nominal=False), "train_rms_sigma": scores[k]["train_rms_sigma"],
             "holdout_rms_sigma": scores[k]["holdout_rms_sigma"], "adequate": bool(decision["adequate"][k]),
             "fit_seconds": fits[k].seconds, "evaluations": fits[k].evaluations} for k in decision["ranked"]]


def _gain(scores, chosen: str) -> tuple[dict, dict, dict]:
    before = {c: v["rmse"] for c, v in scores["nominal"]["holdout"].items()}
    after = {c: v["rmse"] for c, v in scores[chosen]["holdout"].items()}
    gain = {c: gain_percent(before[c], after[c]) for c in before}
    gain["overall"] = gain_percent(scores["nominal"]["holdout_rms_sigma"], scores[chosen]["holdout_rms_sigma"])
    return before, after, gain


def _hint(problem: Problem, analysis: dict, nominal_prediction: dict) -> dict:
    worst = max(analysis, key=lambda c: analysis[c]["rms"])
    model = {c: v for c, v in nominal_prediction.items() if c in problem.values}
    kept = sparse_terms(analysis[worst]["residual"], library(problem.time, analysis[worst]["dominant_hz"], model))
    return {"channel": worst, "terms": kept, "statement": describe_terms(worst, kept)}


def effect_entries(fit: FitResult, effect) -> list[dict]:
    """The ``[[effects]]`` entries of a fitted model: one for a single effect, one per effect for a
    pair (:class:`~riskassess.diagnosis.composite.EffectPair`; a name the two shared loses its prefix).

    Parameters
    ----------
    fit : FitResult
        The fitted model (its effect parameters follow the nominal ones).
    effect : Effect or EffectPair
        The catalog effect (or pair) that was fitted.

    Returns
    -------
    list of dict
        ``{"id": ..., "parameters": {name: value (the parameter's SI unit)}}`` per effect.
    """
    values = {n: p["value"] for n, p in _parameters(fit, nominal=False).items()}
    if not isinstance(effect, EffectPair):
        return [{"id": fit.id, "parameters": values}]
    names = list(values)
    parts = ((effect.first.id, names[:effect.n_first]), (effect.second.id, names[effect.n_first:]))
    return [{"id": eid, "parameters": {n.removeprefix(f"{eid}."): values[n] for n in part}} for eid, part in parts]


def extended_case(case_path: Path, problem: Problem, fit: FitResult, effect=None) -> str:
    """The input case with the named effect(s) and fitted parameters (and the fitted nominal values).

    Parameters
    ----------
    case_path : Path
        The diagnosis case file.
    problem : riskassess.diagnosis.fit.Problem
        The diagnosis problem (its plant's initial attitude, main body -> inertial, composes a fitted
        attitude change).
    fit : FitResult
        The chosen model's fit: initial state (rad, rad/s, m, m/s), hinge values and effect parameters, SI.
    effect : Effect or EffectPair or None
        The chosen catalog effect(s).

    Returns
    -------
    str
        TOML text of the extended case, with a comment header.
    """
    from scipy.spatial.transform import Rotation

    raw = read_toml(case_path)
    scenario = scenario_form(raw).get("kind")
    nominal = _parameters(fit, nominal=True)
    initial = raw.setdefault("initial", {})
    value = {n: p["value"] for n, p in nominal.items()}
    if scenario == "towing":
        _towing_initial(raw, case_path, value)
    elif "attitude_x" in value:
        delta = Rotation.from_rotvec([value[f"attitude_{a}"] for a in "xyz"])
        initial["attitude_rotation_vector"] = (Rotation.from_matrix(problem.plant.attitude0) * delta).as_rotvec().tolist()
    for key, field in (("angular_velocity", "angular_velocity"), ("position", "position_lvlh"),
                       ("velocity", "velocity_lvlh")):
        if f"{key}_x" in value:
            initial[field] = [value[f"{key}_{a}"] for a in "xyz"]
    header_note = ""
    if scenario == "towing":
        header_note = ("# The towing case is referenced relative to this file, as in the input case; the output\n"
                       "# folder holds a copy of it beside this file.\n")
    for key, field in (("hinge_angle", "initial_angle"), ("hinge_rate", "initial_rate"),
                       ("torsional_stiffness", "torsional_stiffness"), ("torsional_damping", "torsional_damping")):
        if key in value:
            raw["hinge"][field] = value[key]
    entries = effect_entries(fit, effect)
    ids = {e["id"] for e in entries}
    raw["effects"] = [e for e in raw.get("effects", []) if e.get("id") not in ids] + entries
    named = " and ".join(f"'{e['id']}'" for e in entries)
    header = (f"# Extended by 'riskassess diagnose' from {case_path.name}: effect {named} added with fitted\n"
              f"# parameters; the initial state and hinge values are the fitted nominal ones.\n") + header_note
    return header + toml_text(raw) + "\n"


def _towing_initial(raw: dict, case_path: Path, value: dict) -> None:
    """The towing case's fitted debris state into ``raw['initial']`` (TowingInitial keys); the attitude
    change composed after the case's own. The towing reference stays relative (case files name no
    absolute path); :func:`_write` copies the towing case into the output folder beside the extended case."""
    from scipy.spatial.transform import Rotation

    initial = raw.setdefault("initial", {})
    if "attitude_x" in value:
        delta = Rotation.from_rotvec([value[f"attitude_{a}"] for a in "xyz"])
        before = Rotation.from_rotvec(initial.get("attitude_change", [0.0, 0.0, 0.0]))
        initial["attitude_change"] = (before * delta).as_rotvec().tolist()


def _without_diverged(problem: Problem, fits: dict, predictions: dict):
    """Drop candidates whose fitted prediction is not finite where data exist (they cannot be the
    cause); a nominal model that diverges stops the diagnosis (:class:`SimulationFailed`)."""
    diverged = {k: t for k, pred in predictions.items()
                if (t := first_unpredicted_time(problem.time, pred, problem.values)) is not None}
    if "nominal" in diverged:
        raise SimulationFailed(diverged["nominal"], "the nominal model's prediction is not finite",
                               "the scenario's own simulation diverges: check the case's parameters and step")
    keep = [k for k in fits if k not in diverged]
    return {k: fits[k] for k in keep}, {k: predictions[k] for k in keep}, diverged


def diagnose_case(case_path, measured_path, out_dir=None, noise: dict | None = None, workers: int = WORKERS,
                  progress=None, candidates: list[str] | None = None, figures: bool = True,
                  overwrite: bool = False) -> dict:
    """Run the diagnosis; returns the answer (also written to ``diagnosis.json``). ``candidates``: the
    effect ids to fit (default: the whole catalog; the applicable ones among them are fitted);
    ``figures``: write the PNG plots (the report needs them; tests about the answer leave them out);
    ``out_dir`` default ``runs/<safe case name>-diagnosis``.

    Parameters
    ----------
    case_path : str or Path
        The diagnosis case file.
    measured_path : str or Path
        The measured-data CSV (``time`` in s, then channels in SI).
    out_dir : str or Path or None
        The output folder.
    noise : dict or None
        Channel -> 1-sigma measurement noise (the channel's SI unit), overriding the estimate.
    workers : int
        Worker processes for the fits.
    progress : callable or None
        ``progress(stage, done, total)``.
    candidates : list of str or None
        Effect ids to fit.
    figures : bool
        Write the PNG plots.
    overwrite : bool
        Replace an earlier diagnosis in the output folder.

    Returns
    -------
    dict
        The answer: cause, confidence, fitted parameters (SI, with units), RMSE before and after per
        channel, candidates, residual analyses, hint.
    """
    case_path = Path(case_path)
    case = load_diagnosis_case(case_path)
    measured = read_measured(measured_path, noise)
    if case.kind == "impact":
        return _diagnose_impact_case(case, case_path, measured, measured_path, out_dir, workers, progress, candidates,
                                     overwrite)
    problem = Problem.build(case, measured, case.diagnosis.holdout_fraction)
    if not problem.channels:
        raise ValueError(f"{measured_path}: none of its channels ({', '.join(measured.channels)}) is predicted by the "
                         f"'{case.kind}' scenario ({', '.join(scenario_channels(problem.plant))})")
    folder = claim(out_dir or default_out(case.name, "-diagnosis"), case.name, "diagnose", overwrite, stage="diagnose")
    with folder.recording():
        results.atomic_write_bytes(folder.path / "case.toml", case_path.read_bytes())
        folder.add_files("case.toml", *_copy_towing_reference(folder.path, case_path))
        answer, data = _diagnose(case, case_path, measured, measured_path, problem, workers, progress, candidates)
        _write(folder, case_path, answer, data, figures)
    folder.finish("complete")
    return answer


def _diagnose(case, case_path: Path, measured, measured_path, problem: Problem, workers, progress,
              candidates) -> tuple[dict, tuple]:
    """Fit, score, select and analyse (module docstring); returns the answer and the data behind the
    files (problem, predictions, chosen model, residuals before and after, extended case text)."""
    wall = time.perf_counter()
    not_applicable = {k: e.not_applicable(case, problem.channels) for k, e in CATALOG.items()}
    not_applicable = {k: v for k, v in not_applicable.items() if v}
    fitted = [k for k in CATALOG if k not in not_applicable and (candidates is None or k in candidates)]
    fits = fit_candidates(problem, fitted, workers, progress)
    effects = dict(CATALOG)
    predictions, step_errors, diverged = {}, {}, {}
    fits, predictions, scores = _predicted_and_scored(problem, fits, effects, predictions, step_errors, diverged,
                                                      list(fits))
    decision = decide(fits, scores, case.diagnosis.decisive_delta_bic, case.diagnosis.adequate_rms, problem)
    if decision["cause"] == "unexplained":
        # two effects at once? (riskassess.diagnosis.forward)
        pairs = make_pairs(pair_candidates(fits, effects, case.diagnosis.decisive_delta_bic), fits, effects, problem)
        for pair in pairs:
            effects[pair.id] = pair
            fits[pair.id] = CandidateFit(problem, pair).fit(fits["nominal"])
        if pairs:
            fits, predictions, scores = _predicted_and_scored(problem, fits, effects, predictions, step_errors,
                                                              diverged, [p.id for p in pairs])
            decision = decide(fits, scores, case.diagnosis.decisive_delta_bic, case.diagnosis.adequate_rms, problem)
    alternatives = _none_of_these_fits(problem, fits, workers, every_form=decision["cause"] not in ("none", "unexplained"))
    if alternatives:
        decision = none_of_these(decision, {**fits, **alternatives}, posterior_weights({**fits, **alternatives}),
                                 case.diagnosis.decisive_delta_bic)
    chosen = decision["model"]
    before = analyse(problem.time, predictions["nominal"], problem.values, problem.noise)
    after = analyse(problem.time, predictions[chosen], problem.values, problem.noise)
    rmse_before, rmse_after, gain = _gain(scores, chosen)
    answer = {
        "case": case.name, "scenario": case.kind, "measured": str(measured_path), "cause": decision["cause"],
        "effects": decision["cause"].split("+") if decision["cause"] not in ("none", "unexplained") else [],
        "selection_steps": selection_steps(fits, scores, chosen),
        "confidence": decision["confidence"], "statement": decision["reason"], "model": chosen,
        "parameters": _parameters(fits[chosen], nominal=False) if chosen != "nominal" else {},
        "nominal_parameters": _parameters(fits[chosen], nominal=True),
        "rmse_before": rmse_before, "rmse_after": rmse_after, "gain_percent": gain,
        "rmse_case_as_given": None, "candidates": _candidate_rows(fits, scores, decision),
        "none_of_these": _none_of_these_entry(fits["nominal"], alternatives),
        "not_applicable": not_applicable,
        "diverged": {k: f"prediction not finite from t = {t:g} s" for k, t in diverged.items()},
        "nominal": {"bic": fits["nominal"].bic, "train_rms_sigma": scores["nominal"]["train_rms_sigma"],
                    "holdout_rms_sigma": scores["nominal"]["holdout_rms_sigma"], "fit_seconds": fits["nominal"].seconds},
        "channels": {"used": problem.channels, "unknown": measured.unknown,
                     "not_predicted": [c for c in measured.channels if c not in problem.channels]},
        "noise": {c: {"sigma": measured.noise[c], "source": measured.noise_source[c]} for c in measured.channels},
        "split_time_s": problem.split_time, "samples": int(len(problem.time)),
        "residuals_before": {c: describe(c, r) for c, r in before.items()},
        "residuals_after": {c: describe(c, r) for c, r in after.items()},
        "residual_figures": {k: {c: {f: r[f] for f in ("rms", "mean", "white_p", "trend_p", "dominant_hz",
                                                        "dominant_share", "window_rms")} for c, r in a.items()}
                             for k, a in (("before", before), ("after", after))},
        "hint": _hint(problem, before, predictions["nominal"]),
        "decisive_delta_bic": case.diagnosis.decisive_delta_bic, "adequate_rms": case.diagnosis.adequate_rms,
    }
    case_as_given = prediction(problem, None, _unfitted(problem), problem.time)
    answer["rmse_case_as_given"] = {c: v["rmse"] for c, v in score(problem, {"case": case_as_given})["case"]["holdout"].items()}
    answer["extended_case"] = None
    extended = extended_case(case_path, problem, fits[chosen], effects.get(chosen)) if chosen != "nominal" and \
        decision["cause"] == chosen else None
    answer["wall_s"] = time.perf_counter() - wall
    return answer, (problem, predictions, chosen, before, after, extended)


def _predicted_and_scored(problem: Problem, fits: dict, effects: dict, predictions: dict, step_errors: dict,
                          diverged: dict, new: list[str]):
    """Predict the models ``new`` (into ``predictions``), drop every model whose prediction diverges
    (into ``diverged``), add the kept new ones' step errors (into ``step_errors``) and score all;
    returns (fits, predictions, scores)."""
    for k in new:
        predictions[k] = prediction(problem, effects.get(k), fits[k], problem.time)
    fits, predictions, more = _without_diverged(problem, fits, predictions)
    diverged.update(more)
    step_errors.update({k: step_error_sigma(problem, effects.get(k), fits[k], predictions[k]) for k in new if k in fits})
    return fits, predictions, score(problem, predictions, step_errors)


def _fit_form(task) -> FitResult | None:
    """One generic form's fit, in a worker; None when the fit fails numerically (a form driven to a
    load that makes the motion blow up: its Jacobian overflows)."""
    form, nominal = task
    try:
        with np.errstate(all="ignore"):
            return CandidateFit(_PROBLEM, form).fit(nominal)
    except (np.linalg.LinAlgError, FloatingPointError, ValueError, SimulationFailed):
        return None


def _none_of_these_fits(problem: Problem, fits: dict, workers: int = WORKERS, every_form: bool = True) -> dict:
    """The "none of these" alternatives (:mod:`riskassess.diagnosis.discrepancy`: the generic forms that
    apply) fitted from the nominal fit, in the worker processes; id -> fit, without the forms whose
    fit fails numerically or whose prediction diverges (they cannot then stand against a cause); empty for the towing scenario. ``every_form`` False: only the first form (the
    smooth torque in time), for an answer that names no cause (the forms can only take a named cause
    away; the time form's delta BIC is still reported)."""
    global _PROBLEM
    forms = [f for f in generic_forms(problem.time[0], problem.time[-1]) if not f.not_applicable(problem.case,
                                                                                                  problem.channels)]
    forms = forms if every_form else forms[:1]
    if not forms:
        return {}
    _PROBLEM = problem
    tasks = [(f, fits["nominal"]) for f in forms]
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        fitted = [_fit_form(t) for t in tasks]
    else:
        with multiprocessing.get_context("fork").Pool(workers, initializer=single_threaded_blas) as pool:
            fitted = pool.map(_fit_form, tasks, chunksize=1)
    out = {}
    for form, fit in zip(forms, fitted):
        if fit is None:
            continue
        predicted = prediction(problem, form, fit, problem.time)
        if first_unpredicted_time(problem.time, predicted, problem.values) is None:
            out[form.id] = fit
    return out


def _none_of_these_entry(nominal: FitResult, alternatives: dict) -> dict | None:
    """The answer's ``none_of_these``: the best generic form's delta BIC against the nominal model, its
    parameter count, fit time and description, and every form's delta BIC."""
    if not alternatives:
        return None
    models = {f.id: f.model for f in generic_forms(0.0, 1.0)}
    best = min(alternatives, key=lambda k: alternatives[k].bic)
    fit = alternatives[best]
    return {"delta_bic": float(nominal.bic - fit.bic), "parameters": len(fit.names) - fit.nominal_count,
            "fit_seconds": fit.seconds, "best": best, "model": models[best],
            "forms": {k: float(nominal.bic - f.bic) for k, f in alternatives.items()}}


def _unfitted(problem: Problem) -> FitResult:
    n = len(problem.nominal_center)
    return FitResult("nominal", [], [], problem.nominal_center, np.zeros(n), n, 0.0, 0.0, 1, 0.0, 0, "")


def _copy_towing_reference(out: Path, case_path: Path) -> list[str]:
    """Copy a towing (impact) diagnosis case's towing (impact) case into ``out`` at the same relative
    path, so that ``case.toml`` and the extended case there load; the copied names (none for other kinds)."""
    raw = read_toml(case_path)
    kind = scenario_form(raw).get("kind")
    if kind not in ("towing", "impact"):
        return []
    name = raw[kind]            # validated on load: relative, in the case's folder or below
    (out / name).parent.mkdir(parents=True, exist_ok=True)
    results.atomic_write_bytes(out / name, (case_path.parent / name).read_bytes())
    return [name]


def _diagnose_impact_case(case, case_path: Path, measured, measured_path, out_dir, workers, progress, candidates,
                          overwrite) -> dict:
    """:func:`diagnose_case` of the impact scenario (:mod:`riskassess.diagnosis.impact_fit`): the answer into
    ``diagnosis.json``, the window values into ``diagnosis.npz``, the case, its impact case and, when a
    cause is named, the extended case (its ``[[effects]]`` entry) into the output folder."""
    folder = claim(out_dir or default_out(case.name, "-diagnosis"), case.name, "diagnose", overwrite, stage="diagnose")
    with folder.recording():
        results.atomic_write_bytes(folder.path / "case.toml", case_path.read_bytes())
        folder.add_files("case.toml", *_copy_towing_reference(folder.path, case_path))
        answer, arrays = diagnose_impact(case, measured, workers, progress, candidates)
        answer["measured"] = str(measured_path)
        answer["extended_case"] = None
        files = ["diagnosis.json", "diagnosis.npz"]
        if answer["cause"] == answer["model"] and answer["model"] != "nominal":
            target = folder.path / f"{safe_name(case_path.stem)}.extended.toml"
            results.atomic_write_bytes(target, impact_extended_case(case_path, answer).encode())
            answer["extended_case"] = str(target)
            files.append(target.name)
        results.atomic_write_npz(folder.path / "diagnosis.npz", arrays)
        results.atomic_write_json(folder.path / "diagnosis.json", answer)
        folder.add_files(*files)
    folder.finish("complete")
    return answer


def impact_extended_case(case_path: Path, answer: dict) -> str:
    """The impact diagnosis case with the named effect and its fitted parameter in ``[[effects]]``.

    Parameters
    ----------
    case_path : Path
        The diagnosis case file.
    answer : dict
        The impact diagnosis answer (its ``cause`` and ``parameters``, SI).

    Returns
    -------
    str
        TOML text with a comment header.
    """
    raw = read_toml(case_path)
    entry = {"id": answer["cause"], "parameters": {n: p["value"] for n, p in answer["parameters"].items()}}
    raw["effects"] = [e for e in raw.get("effects", []) if e.get("id") != entry["id"]] + [entry]
    header = (f"# Extended by 'riskassess diagnose' from {case_path.name}: impact effect '{entry['id']}' set to its\n"
              f"# fitted value; the impact case is referenced relative to this file (a copy sits beside it).\n")
    return header + toml_text(raw) + "\n"


def _write(folder: OutputFolder, case_path: Path, answer, data: tuple, figures: bool = True) -> None:
    """The diagnosis files into the claimed ``folder``; the extended case only there."""
    problem, predictions, chosen, before, after, extended = data
    out = folder.path
    files = ["diagnosis.json", "diagnosis.npz"]
    if extended is not None:
        target = out / f"{safe_name(case_path.stem)}.extended.toml"
        results.atomic_write_bytes(target, extended.encode())
        files.append(target.name)
        answer["extended_case"] = str(target)
    arrays = {"time": problem.time, "train": problem.train, "channels": np.array(problem.channels)}
    for c in problem.channels:
        arrays[f"measured/{c}"] = problem.values[c]
        arrays[f"nominal/{c}"] = predictions["nominal"][c]
        arrays[f"chosen/{c}"] = predictions[chosen][c]
        arrays[f"residual_before/{c}"] = before[c]["residual"]
        arrays[f"residual_after/{c}"] = after[c]["residual"]
    results.atomic_write_npz(out / "diagnosis.npz", arrays)
    if figures:
        files += write_figures(out, answer, arrays)
    results.atomic_write_json(out / "diagnosis.json", answer)
    folder.add_files(*files)


__all__ = ["diagnose_case", "fit_candidates", "extended_case", "CHANNELS"]
