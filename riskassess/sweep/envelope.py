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
"""
from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
from scipy.stats import beta

DEFAULT_KEY = "launch.velocity"


def no_debris_lower_bound(n: int, k: int, confidence: float) -> float:
    """One-sided Clopper-Pearson lower bound of P(no debris) from n runs with k debris cases."""
    if n == 0:
        return 0.0
    if k == n:
        return 0.0
    return float(beta.ppf(1.0 - confidence, n - k, k + 1))


def runs_needed(confidence: float, reliability: float) -> int:
    """Debris-free runs per value needed to state P(no debris) >= reliability at that confidence."""
    return math.ceil(math.log(1.0 - confidence) / math.log(reliability))


def envelope_key(rows: list[dict]) -> str | None:
    varied = list(rows[0]["overrides"]) if rows else []
    return DEFAULT_KEY if DEFAULT_KEY in varied else (varied[0] if varied else None)


def envelope(rows: list[dict], key: str | None = None, confidence: float = 0.95, reliability: float = 0.9) -> dict:
    """Per value of ``key``: runs, debris count, bound, utilizations; and the safe limit."""
    key = key or envelope_key(rows)
    done = [r for r in rows if r["state"] == "done" and r["result"]["secondary_debris"] is not None]
    groups = defaultdict(list)
    for r in done:
        groups[r["overrides"][key]].append(r["result"])
    points = []
    for value in sorted(groups):
        results = groups[value]
        n, k = len(results), sum(r["secondary_debris"] for r in results)
        utilization = [max(loc["utilization"] for loc in r["locations"].values()) for r in results]
        lower = no_debris_lower_bound(n, k, confidence)
        points.append({"value": value, "runs": n, "with_debris": k, "no_debris_lower_bound": lower,
                       "safe": k == 0 and lower >= reliability, "deterministic_safe": k == 0,
                       "max_utilization": max(utilization), "mean_utilization": float(np.mean(utilization)),
                       "max_breakup_likelihood": max(r["breakup_likelihood"] for r in results)})
    return {"key": key, "confidence": confidence, "reliability": reliability, "points": points,
            "runs_needed_per_value": runs_needed(confidence, reliability),
            **_limits(points, "safe"), **{f"deterministic_{k}": v for k, v in _limits(points, "deterministic_safe").items()},
            "failed_runs": sum(r["state"] == "failed" for r in rows),
            "pending_runs": sum(r["state"] == "pending" for r in rows)}


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
    if last_safe and first_unsafe:
        u0, u1 = last_safe["max_utilization"], first_unsafe["max_utilization"]
        v0, v1 = last_safe["value"], first_unsafe["value"]
        estimate = v0 + (1.0 - u0) * (v1 - v0) / (u1 - u0) if u1 > u0 and u0 <= 1.0 <= u1 else None
    return {"safe_limit": last_safe["value"] if last_safe else None,
            "first_unsafe": first_unsafe["value"] if first_unsafe else None,
            "interpolated_limit": estimate}


def is_probabilistic(env: dict) -> bool:
    """Enough runs at every value for the confidence statement."""
    return bool(env["points"]) and min(p["runs"] for p in env["points"]) >= env["runs_needed_per_value"]


def envelope_statement(env: dict) -> str:
    """One sentence for people: the safe limit and how sure it is."""
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
        text += f"; first unsafe value: {first:.4g}"
    if interpolated is not None:
        text += f"; the largest utilization reaches 1 at about {interpolated:.4g} (linear interpolation)"
    if prefix:
        text += (f". Deterministic: {min(p['runs'] for p in env['points'])} run(s) per value; a statement at "
                 f"{env['confidence']:.0%} confidence needs {env['runs_needed_per_value']} debris-free runs per "
                 f"value (--monte-carlo {env['runs_needed_per_value']} with --uncertain inputs)")
    return text + "."
