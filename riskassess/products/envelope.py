"""The safe impact envelope of a sweep: margins, stresses and breakup against the swept key.

"Safe" at a value of the swept key (the impact velocity by default) means: with confidence
``confidence``, the probability that a capture makes no secondary debris is at least
``reliability``. From n finished runs at that value, k of them with debris, the one-sided
Clopper-Pearson lower bound of P(no debris) is

.. math:: p_{low} = B^{-1}(1 - c;\\; n - k,\\; k + 1)

(the beta quantile; :math:`p_{low} = (1-c)^{1/n}` when k = 0). The safe limit is the largest
value below which every swept value is safe. With one run per value (no uncertain inputs)
no probability can be stated: the answer is then deterministic, and n >= ln(1-c)/ln(R)
runs per value (29 for c = 0.95, R = 0.9) would be needed for the statement.
Between the last safe and the first unsafe value the limit is also estimated by linear
interpolation of the largest utilization (peak demand over decisive allowable) to 1.

Unknown runs are never safe. A run that failed (diverged, or any other error), whose verdict
is indeterminate, or that is still pending counts as a run *with* debris in the bound:
with u unknown runs, a value is safe when its n known runs have no debris and
:math:`B^{-1}(1 - c;\\; n,\\; u + 1) \\ge R`, a bound that holds whatever the unknown runs
would have given; deterministically, a value with any unknown run is not safe. Every value
with a run is a point, so the limit never steps over a value whose runs all failed.
"""
from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
from scipy.stats import beta, spearmanr

from riskassess.products.sweep_records import debris_state_of
from structures.verdict import DEBRIS, NO_DEBRIS

DEFAULT_KEY = "launch.velocity"
#: Run outcomes that say nothing about debris; the envelope counts each as a run with debris.
UNKNOWN = ("failed", "indeterminate", "pending")


def no_debris_lower_bound(n: int, k: int, confidence: float) -> float:
    """One-sided Clopper-Pearson lower bound of P(no debris) from n runs with k debris cases.

    Parameters
    ----------
    n : int
        Runs counted (n >= 0); 0 gives a bound of 0.
    k : int
        Of them, runs with debris (unknown runs included), 0 <= k <= n.
    confidence : float
        One-sided confidence c, in (0, 1).

    Returns
    -------
    float
        :math:`B^{-1}(1 - c;\\; n - k,\\; k + 1)` (module doc); 0 when every run has debris.
    """
    if n == 0:
        return 0.0
    if k == n:
        return 0.0
    return float(beta.ppf(1.0 - confidence, n - k, k + 1))


def clopper_pearson(k: int, n: int, confidence: float) -> tuple[float, float]:
    """Two-sided Clopper-Pearson interval of a binomial probability from k events in n trials
    (exact: it covers the true probability with at least ``confidence`` for every n).

    Parameters
    ----------
    k, n : int
        Events and trials, 0 <= k <= n, n >= 1.
    confidence : float
        Two-sided confidence, in (0, 1).

    Returns
    -------
    (float, float)
        Lower and upper end of the interval.
    """
    alpha = 1.0 - confidence
    low = 0.0 if k == 0 else float(beta.ppf(alpha / 2.0, k, n - k + 1))
    high = 1.0 if k == n else float(beta.ppf(1.0 - alpha / 2.0, k + 1, n - k))
    return low, high


def debris_probability(rows: list[dict], confidence: float = 0.95) -> dict:
    """P(secondary debris) of a Monte Carlo from its runs' records, with its interval.

    The estimate is k / (k + m) over the runs with a verdict (k with debris, m without). Runs that
    say nothing (failed, indeterminate, pending: u of them) are never counted as safe: the
    interval is Clopper-Pearson's, its lower end with every unknown run taken as debris-free and its
    upper end with every unknown run taken as debris, so it holds whatever the unknown runs would
    have shown. None where no run has a verdict.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store (:meth:`riskassess.sweep.store.ResultStore.rows`).
    confidence : float
        Two-sided confidence of the interval, in (0, 1).

    Returns
    -------
    dict
        ``estimate`` (None without a verdict), ``interval`` [low, high] (None without runs),
        ``confidence``, ``runs``, ``debris_runs``, ``no_debris_runs``, ``unknown_runs``.
    """
    status = [run_status(r) for r in rows]
    k, m = status.count("debris"), status.count("no_debris")
    unknown = sum(status.count(s) for s in UNKNOWN)
    n = k + m + unknown
    if n == 0:
        return {"estimate": None, "interval": None, "confidence": confidence, "runs": 0, "debris_runs": 0,
                "no_debris_runs": 0, "unknown_runs": 0}
    low = clopper_pearson(k, n, confidence)[0]
    high = clopper_pearson(k + unknown, n, confidence)[1]
    return {"estimate": k / (k + m) if k + m else None, "interval": [low, high], "confidence": confidence,
            "runs": n, "debris_runs": k, "no_debris_runs": m, "unknown_runs": unknown}


#: What a single run's ``p_secondary_debris`` says it needs: one run is one draw, not a probability.
MONTE_CARLO_NEEDED = "--monte-carlo N"


def single_run_probability(verdict: dict) -> dict:
    """``p_secondary_debris`` of a single run (``assess --json`` without ``--monte-carlo``): no number.

    One deterministic run answers "debris / no debris / indeterminate" for one draw of the inputs; any
    number put here (0, 1, a location's likelihood) could be read as P(secondary debris), so the
    estimate and its interval are None, the Monte Carlo counts are 0, and ``needs`` says how to get one.
    The run's answer and what it rests on go to ``deterministic`` and ``condition``.

    Parameters
    ----------
    verdict : dict
        The run's structural verdict (``structures.json``): ``debris_state`` and per location
        ``state`` and ``condition``.

    Returns
    -------
    dict
        The keys of :func:`debris_probability` (``estimate``, ``interval``, ``confidence`` None;
        ``runs``, ``debris_runs``, ``no_debris_runs``, ``unknown_runs`` 0: no Monte Carlo run), plus
        ``needs`` (:data:`MONTE_CARLO_NEEDED`), ``deterministic`` (the run's ``debris_state``) and
        ``condition`` (:func:`deterministic_condition`).
    """
    return {"estimate": None, "interval": None, "confidence": None, "runs": 0, "debris_runs": 0,
            "no_debris_runs": 0, "unknown_runs": 0, "needs": MONTE_CARLO_NEEDED,
            "deterministic": verdict.get("debris_state"), "condition": deterministic_condition(verdict)}


def deterministic_condition(verdict: dict) -> str:
    """The single run's result and the condition it rests on: the answer, then the condition sentence of
    each location that decides it (the failing ones for debris, the indeterminate ones for no verdict, all
    for no debris), then that a probability needs a Monte Carlo.

    Parameters
    ----------
    verdict : dict
        The structural verdict (``structures.json``).

    Returns
    -------
    str
    """
    state = verdict.get("debris_state") or ("debris" if verdict.get("secondary_debris") else "no_debris")
    deciding = {"debris": "fails", "indeterminate": "indeterminate"}.get(state)
    locations = verdict.get("locations") or []
    conditions = [loc["condition"] for loc in locations
                  if loc.get("condition") and (deciding is None or loc.get("state") == deciding)]
    answer = {"debris": "secondary debris", "no_debris": "no secondary debris",
              "indeterminate": "indeterminate (no verdict; never read as no debris)"}[state]
    if state == "debris" and verdict.get("released_pieces") and not conditions:
        conditions = [f"{len(verdict['released_pieces'])} piece(s) released."]
    return (f"One deterministic run: {answer}. " + " ".join(conditions)
            + f" P(secondary debris) is not given by one run: it needs assess {MONTE_CARLO_NEEDED}.").replace("  ", " ")


def utilization_sensitivity(rows: list[dict]) -> dict:
    """Sensitivity of each weak location's utilization (peak over decisive allowable) to each
    varied or uncertain input: Spearman's rank correlation over the finished runs with a finite
    utilization (monotone effects count, whatever their shape; -1 to 1, None with fewer than 3
    runs or a constant input). Returns {location: {input key: rho}}.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store (:meth:`riskassess.sweep.store.ResultStore.rows`); their
        ``overrides`` (case key -> value, SI) are the inputs, ``result["locations"]`` the
        utilizations (-).
    """
    done = [r for r in rows if r["state"] == "done" and r["result"] and r["result"].get("locations")]
    keys = list(rows[0]["overrides"]) if rows else []
    locations = sorted({name for r in done for name in r["result"]["locations"]})
    out = {}
    for name in locations:
        out[name] = {}
        for key in keys:
            pairs = [(r["overrides"][key], r["result"]["locations"].get(name, {}).get("utilization")) for r in done]
            pairs = [(x, u) for x, u in pairs if u is not None and math.isfinite(u)]
            x, u = (np.array(v, float) for v in zip(*pairs)) if pairs else (np.array([]), np.array([]))
            if len(x) < 3 or np.ptp(x) == 0.0 or np.ptp(u) == 0.0:
                out[name][key] = None
                continue
            out[name][key] = float(spearmanr(x, u).statistic)
    return out


def probability_statement(p: dict, inputs: list[str]) -> str:
    """One sentence: P(secondary debris), its interval, over what.

    Parameters
    ----------
    p : dict
        The result of :func:`debris_probability`.
    inputs : list of str
        The uncertain inputs as ``--uncertain`` gives them, e.g. ``"contact.mu_kinetic=uniform(0.1,0.2)"``.
    """
    if p["estimate"] is None and p["interval"] is None:
        return "No Monte Carlo run has finished: no probability of secondary debris."
    low, high = p["interval"]
    estimate = "unknown (no run has a verdict)" if p["estimate"] is None else f"{p['estimate']:.0%}"
    text = (f"P(secondary debris) = {estimate}, {p['confidence']:.0%} interval {low:.0%}-{high:.0%}, from "
            f"{p['runs']} runs ({p['debris_runs']} with debris, {p['no_debris_runs']} without")
    if p["unknown_runs"]:
        text += f", {p['unknown_runs']} unknown: the interval holds whatever they would show"
    return text + ")" + (f" over {'; '.join(inputs)}." if inputs else ".")


def runs_needed(confidence: float, reliability: float) -> int:
    """Debris-free runs per value needed to state P(no debris) >= reliability at that confidence.

    Parameters
    ----------
    confidence : float
        Confidence c, in (0, 1).
    reliability : float
        Required P(no debris) R, in (0, 1).

    Returns
    -------
    int
        :math:`\\lceil \\ln(1 - c) / \\ln R \\rceil`.
    """
    return math.ceil(math.log(1.0 - confidence) / math.log(reliability))


def envelope_key(rows: list[dict]) -> str | None:
    """The key the envelope is drawn against: ``launch.velocity`` when the sweep varies it, else its first key.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store; the keys of the first row's ``overrides`` are the swept keys.

    Returns
    -------
    str or None
        A dotted case key; None without rows.
    """
    varied = list(rows[0]["overrides"]) if rows else []
    return DEFAULT_KEY if DEFAULT_KEY in varied else (varied[0] if varied else None)


def run_status(row: dict) -> str:
    """``debris``, ``no_debris``, ``indeterminate``, ``failed``, ``pending``, or ``unassessed``
    (done, in a case without weak locations: no verdict to count). A "no debris" record whose
    evidence is not finite is ``indeterminate`` (:func:`~riskassess.products.sweep_records.debris_state_of`).

    Parameters
    ----------
    row : dict
        One run row of the sweep store (``state``, ``result``, ``debris_state``).
    """
    if row["state"] != "done":
        return row["state"]
    record = dict(row["result"] or {})
    if row.get("debris_state"):
        record["debris_state"] = row["debris_state"]
    return debris_state_of(record) or "unassessed"


def unknown_counts(rows: list[dict]) -> dict[str, int]:
    """Runs the envelope cannot count as safe or unsafe: failed, indeterminate, pending.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store.

    Returns
    -------
    dict of str to int
        ``failed``, ``indeterminate``, ``pending`` -> number of runs.
    """
    status = [run_status(r) for r in rows]
    return {what: status.count(what) for what in UNKNOWN}


def _finite_max(values) -> float | None:
    finite = [v for v in values if v is not None and math.isfinite(v)]
    return max(finite) if finite else None


def _point(value: float, rows: list[dict], confidence: float, reliability: float) -> dict:
    """One envelope point from the runs at ``value``; unknown runs count as runs with debris."""
    status = [run_status(r) for r in rows]
    known = [r["result"] for r, s in zip(rows, status) if s in (DEBRIS, NO_DEBRIS)]
    n, k = len(known), status.count(DEBRIS)
    unknown = {what: status.count(what) for what in UNKNOWN}
    u = sum(unknown.values())
    utilization = [_finite_max(loc["utilization"] for loc in r["locations"].values()) for r in known]
    finite_u = [x for x in utilization if x is not None]
    lower = no_debris_lower_bound(n + u, k + u, confidence)
    return {"value": value, "runs": n, "with_debris": k, **{f"{what}_runs": c for what, c in unknown.items()},
            "unknown_runs": u, "total_runs": n + u, "no_debris_lower_bound": lower,
            "safe": n > 0 and k == 0 and lower >= reliability, "deterministic_safe": n > 0 and k == 0 and u == 0,
            "max_utilization": max(finite_u) if finite_u else None,
            "mean_utilization": float(np.mean(finite_u)) if finite_u else None,
            "max_breakup_likelihood": _finite_max(r["breakup_likelihood"] for r in known)}


def envelope(rows: list[dict], key: str | None = None, confidence: float = 0.95, reliability: float = 0.9) -> dict:
    """Per value of ``key``: runs, debris count, unknown runs, bound, utilizations; and the safe limit.

    Every value with a run is a point, including values whose runs all failed or are pending
    (they are never safe, so the limit cannot step over them). Runs of a case without weak
    locations (no verdict) are left out.

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store (:meth:`riskassess.sweep.store.ResultStore.rows`).
    key : str, optional
        The swept case key the envelope is drawn against (in its SI unit); default
        :func:`envelope_key`.
    confidence : float
        One-sided confidence c of the bound, in (0, 1).
    reliability : float
        Required P(no debris) R, in (0, 1).

    Returns
    -------
    dict
        ``key``, ``confidence``, ``reliability``, ``points`` (one dict per value),
        ``runs_needed_per_value``, ``safe_limit``, ``first_unsafe``, ``interpolated_limit`` (in the
        unit of ``key``), the same with prefix ``deterministic_``, and the counts of unknown and
        diverged runs.
    """
    key = key or envelope_key(rows)
    groups = defaultdict(list)
    for r in rows:
        if run_status(r) != "unassessed":
            groups[r["overrides"][key]].append(r)
    points = [_point(value, groups[value], confidence, reliability) for value in sorted(groups)]
    status = [run_status(r) for r in rows]
    return {"key": key, "confidence": confidence, "reliability": reliability, "points": points,
            "runs_needed_per_value": runs_needed(confidence, reliability),
            **_limits(points, "safe"), **{f"deterministic_{k}": v for k, v in _limits(points, "deterministic_safe").items()},
            **{f"{what}_runs": status.count(what) for what in UNKNOWN},
            "diverged_runs": sum(r["state"] == "failed" and r.get("error_kind") == "diverged" for r in rows)}


def _limits(points: list[dict], flag: str) -> dict:
    """Largest value with every smaller value safe, the first unsafe value, and the
    interpolated value where the largest utilization reaches 1."""
    last_safe = first_unsafe = None
    for p in points:
        if not p[flag]:
            first_unsafe = p
            break
        last_safe = p
    estimate = None
    if last_safe and first_unsafe and None not in (last_safe["max_utilization"], first_unsafe["max_utilization"]):
        u0, u1 = last_safe["max_utilization"], first_unsafe["max_utilization"]
        v0, v1 = last_safe["value"], first_unsafe["value"]
        estimate = v0 + (1.0 - u0) * (v1 - v0) / (u1 - u0) if u1 > u0 and u0 <= 1.0 <= u1 else None
    return {"safe_limit": last_safe["value"] if last_safe else None,
            "first_unsafe": first_unsafe["value"] if first_unsafe else None,
            "interpolated_limit": estimate}


def is_probabilistic(env: dict) -> bool:
    """Enough runs at every value for the confidence statement.

    Parameters
    ----------
    env : dict
        The result of :func:`envelope`.
    """
    return bool(env["points"]) and min(p["total_runs"] for p in env["points"]) >= env["runs_needed_per_value"]


def envelope_statement(env: dict) -> str:
    """One sentence for people: the safe limit and how sure it is.

    Parameters
    ----------
    env : dict
        The result of :func:`envelope`.
    """
    key = env["key"]
    if not env["points"]:
        return "No finished run with a structural verdict yet: no envelope."
    if is_probabilistic(env):
        prefix = ""
        limit, first, interpolated = env["safe_limit"], env["first_unsafe"], env["interpolated_limit"]
        what = (f"at {env['confidence']:.0%} confidence that P(no secondary debris) >= {env['reliability']:.0%}")
    else:
        prefix = "deterministic_"
        limit, first, interpolated = (env["deterministic_safe_limit"], env["deterministic_first_unsafe"],
                                      env["deterministic_interpolated_limit"])
        what = "with no secondary debris in any run"
    text = (f"Largest {key} {what}: {limit:.4g}" if limit is not None
            else f"No {key} of the sweep is safe ({what})")
    if first is not None:
        point = next(p for p in env["points"] if p["value"] == first)
        if point["with_debris"] or not point["unknown_runs"]:
            text += f"; first unsafe value: {first:.4g}"
        else:
            text += (f"; first value not shown safe: {first:.4g} ({point['unknown_runs']} of its "
                     f"{point['total_runs']} runs unknown)")
    if interpolated is not None:
        text += f"; the largest utilization reaches 1 at about {interpolated:.4g} (linear interpolation)"
    if prefix:
        text += (f". Deterministic: {min(p['runs'] for p in env['points'])} run(s) per value; a statement at "
                 f"{env['confidence']:.0%} confidence needs {env['runs_needed_per_value']} debris-free runs per "
                 f"value (--monte-carlo {env['runs_needed_per_value']} with --uncertain inputs)")
    if any(env[f"{what}_runs"] for what in UNKNOWN):
        text += (f". Unknown runs, counted as runs with debris (never safe): {env['failed_runs']} failed "
                 f"({env['diverged_runs']} diverged), {env['indeterminate_runs']} indeterminate, "
                 f"{env['pending_runs']} pending")
    return text + "."
