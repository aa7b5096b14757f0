"""Why a weak location has no verdict: each producer of a reason returns the rule with it.

A location is "indeterminate" when the evidence cannot support "holds" (docs/structures.md, "Three
answers"). The producers (:func:`structures.verdict.evidence_gaps`, :func:`structures.verdict.location_state`,
:func:`structures.thread_gaps.pass_through_reason`, :func:`structures.verdict.apply_twin`) return
:class:`Indeterminacy` pairs: the rule, a name a sweep counts runs by, and the sentence a reader reads,
with its numbers. The rule travels with the sentence from where it is written to ``structures.json``
(``indeterminate_rules`` beside ``indeterminate_reason``) and the sweep store, so nothing reads the
rule back out of the words.
"""
from __future__ import annotations

from typing import NamedTuple

#: The rules that make a location indeterminate, in the order a location lists them:
#: too few judged samples, samples too far apart, no contact load in the judged window (evidence gaps of
#: the run); loads that are not finite; net threads through the part that could take it past its allowable
#: (structures.thread_gaps); the threads' own contact on with an energy error past its limit (structures.verdict.
#: thread_contact_energy_gap); the twin run exceeding the allowable, the peak one draw of a chaotic capture,
#: the twin not run (structures.twin); the run reaching its end time before the capture was over
#: (structures.capture_window, ``structures.window = "capture"``).
RULES = ("too_few_judged_samples", "coarse_sampling", "no_capture_load", "non_finite_loads", "thread_pass_through",
         "thread_contact_energy", "twin_exceeds", "chaotic_peak", "twin_not_run", "capture_not_over")


class Indeterminacy(NamedTuple):
    """One reason a location has no verdict.

    Attributes
    ----------
    rule : str
        One of :data:`RULES`.
    reason : str
        The sentence, with the run's numbers.
    """

    rule: str
    reason: str


def rules_of(found: list[Indeterminacy]) -> list[str]:
    """The rules of ``found``, each once, in the order of :data:`RULES`.

    Parameters
    ----------
    found : list of Indeterminacy

    Returns
    -------
    list of str

    Raises
    ------
    ValueError
        For a rule not in :data:`RULES` (a producer naming a rule no sweep count knows).
    """
    unknown = sorted({f.rule for f in found} - set(RULES))
    if unknown:
        raise ValueError(f"unknown indeterminacy rule(s) {unknown}; the rules are: {', '.join(RULES)}")
    return [rule for rule in RULES if any(f.rule == rule for f in found)]


def mark(row: dict, state: str, found: list[Indeterminacy], suffix: str = "") -> None:
    """Write a location's ``state``, ``indeterminate_reason`` (the reasons joined by "; ", then ``suffix``; None
    when ``found`` is empty) and ``indeterminate_rules`` (:func:`rules_of`) into its verdict ``row``.

    Parameters
    ----------
    row : dict
        One location's verdict (changed in place).
    state : {"fails", "holds", "indeterminate"}
    found : list of Indeterminacy
        Why it is indeterminate; empty for "fails" and "holds".
    suffix : str
        Text appended to the joined reasons (e.g. where P(secondary debris) comes from).
    """
    row["state"] = state
    row["indeterminate_reason"] = "; ".join(f.reason for f in found) + suffix if found else None
    row["indeterminate_rules"] = rules_of(found)
