"""What a run's record in the store says about secondary debris: debris, no debris or indeterminate.

A record says "no debris" only when its verdict says so and every number the verdict rests on
is finite: a run whose loads came out NaN or infinite (a diverged integration that no health
check caught, or a store written before the checks existed) is ``indeterminate``, never safe.
"""
from __future__ import annotations

import math

from structures.verdict import DEBRIS, DEBRIS_STATES, INDETERMINATE, NO_DEBRIS

#: Record fields whose values (numbers, or dicts / lists of numbers) the verdict rests on.
#: Margins of safety are left out: +inf is a legitimate margin of an unloaded criterion.
EVIDENCE_KEYS = ("peak_contact_force_N", "peak_contact_moment_Nm", "joint_peak_moment_after_transient_Nm",
                 "energy_balance_relative_drift", "breakup_likelihood")
LOCATION_EVIDENCE_KEYS = ("utilization", "likelihood", "peaks")


def _all_finite(value) -> bool:
    """True when every number in ``value`` (nested dicts and lists) is finite; None is no number."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return True
    if isinstance(value, (int, float)):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(_all_finite(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return all(_all_finite(v) for v in value)
    return True


def evidence_is_finite(record: dict) -> bool:
    """Every load, utilization and likelihood of the record is a finite number.

    Parameters
    ----------
    record : dict
        A run's record (:func:`riskassess.sweep.runner.run_record`): the fields of
        :data:`EVIDENCE_KEYS` and per location those of :data:`LOCATION_EVIDENCE_KEYS`.
    """
    locations = record.get("locations") or {}
    return (all(_all_finite(record.get(key)) for key in EVIDENCE_KEYS)
            and all(_all_finite(loc.get(key)) for loc in locations.values() for key in LOCATION_EVIDENCE_KEYS))


def debris_state_of(record: dict) -> str | None:
    """``debris``, ``no_debris`` or ``indeterminate`` for a done run's record; None without a
    structural verdict (a case with no weak locations).

    The record's own ``debris_state`` wins when it has one; otherwise ``secondary_debris``
    (True / False / None) gives it. "No debris" on non-finite evidence is ``indeterminate``.

    Parameters
    ----------
    record : dict
        A done run's record (:func:`riskassess.sweep.runner.run_record`).
    """
    state = record.get("debris_state")
    if state not in DEBRIS_STATES:
        debris = record.get("secondary_debris")
        if debris is None:
            return INDETERMINATE if record.get("locations") else None
        state = DEBRIS if debris else NO_DEBRIS
    if state == NO_DEBRIS and not evidence_is_finite(record):
        return INDETERMINATE
    return state


def indeterminate_reasons_of(record: dict) -> list[dict]:
    """Why a done run's record is indeterminate: one entry per (location, rule), ``location``, ``rule``
    (:data:`structures.indeterminacy.RULES`) and the verdict's ``reason``; empty when it is not
    indeterminate. A run made indeterminate by non-finite evidence alone (:func:`debris_state_of`) gets
    ``location`` None and rule ``non_finite_evidence``.

    Parameters
    ----------
    record : dict
        A run's record (:func:`riskassess.sweep.runner.run_record`), with per location ``indeterminate_reason`` and
        ``indeterminate_rules`` (records stored before them give ``rule`` "not_recorded").

    Returns
    -------
    list of dict
    """
    if debris_state_of(record) != INDETERMINATE:
        return []
    reasons = []
    for name, loc in (record.get("locations") or {}).items():
        if "indeterminate_rules" not in loc:
            continue
        reasons += [{"location": name, "rule": rule, "reason": loc["indeterminate_reason"]}
                    for rule in loc["indeterminate_rules"]]
    if reasons:
        return reasons
    if any("indeterminate_rules" not in loc for loc in (record.get("locations") or {}).values()):
        return [{"location": None, "rule": "not_recorded", "reason": "stored before the store kept reasons"}]
    return [{"location": None, "rule": "non_finite_evidence",
             "reason": "a location's peak, utilization or likelihood is not finite"}]


def indeterminate_rule_counts(rows: list[dict]) -> dict:
    """How many indeterminate runs each (location, rule) made so (a run with several counts under each).

    Parameters
    ----------
    rows : list of dict
        Run rows of the sweep store (:meth:`riskassess.sweep.store.ResultStore.rows`); done runs' ``result``
        records (:func:`riskassess.sweep.runner.run_record`).

    Returns
    -------
    dict
        ``(location, rule) -> runs``, most runs first; ``location`` None for a run-wide rule.
    """
    counts: dict = {}
    for row in rows:
        if row.get("state") != "done" or not row.get("result"):
            continue
        for key in {(r["location"], r["rule"]) for r in indeterminate_reasons_of(row["result"])}:
            counts[key] = counts.get(key, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], str(kv[0]))))
