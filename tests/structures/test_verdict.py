"""The condition sentence of a location's verdict (structures/verdict.py): the deterministic result
and the condition it rests on, in one sentence (issue 23: "FAIL" beside "likelihood >= 3 %")."""
from structures.verdict import condition_sentence


def _result(peak, allowable, state, released_at=None, unit="N m", policy_value=None):
    low, high = allowable
    likelihood = min(max((peak - low) / (high - low), 0.0), 1.0) if high > low else float(peak >= low)
    return {"name": "solar_array_hinge", "state": state, "released_at_s": released_at, "indeterminate_reason": None,
            "criteria": {"hinge_moment": {"peak": peak, "peak_time_s": 0.41, "unit": unit, "allowable": [low, high],
                                          "likelihood": likelihood, "margin_of_safety": (policy_value or low) / peak - 1,
                                          "decisive_allowable": policy_value or low}}}


def test_a_released_range_location_states_its_threshold_probability_and_policy():
    # the case: released at 223 N m against 200-1000 N m judged at the low end;
    # P(allowable < 223) = (223 - 200) / 800 = 2.9 % -> "3 %", a lower bound since the joint let go
    text = condition_sentence(_result(223.0, (200.0, 1000.0), "fails", released_at=0.41), "low")
    assert text == ("solar_array_hinge breaks if its hinge moment allowable is below 223 N m (this run's peak, at 0.41 s, "
                    "up to its release): P >= 3% for an allowable uniform over 200-1000 N m; this run judges at "
                    "the low end (200 N m): fails.")


def test_a_holding_single_value_location_states_its_margin():
    text = condition_sentence(_result(30e6, (50e6, 50e6), "holds", unit="Pa"), "low")
    # margin = 50 / 30 - 1 = +0.67
    assert text == ("solar_array_hinge holds: its hinge moment reached 30 MPa (this run's peak, at 0.41 s) against an "
                    "allowable of 50 MPa (margin +0.67).")


def test_an_indeterminate_location_states_no_condition():
    result = _result(10.0, (200.0, 1000.0), "indeterminate")
    result["indeterminate_reason"] = "no net contact on the debris after skip_initial"
    assert "indeterminate (no net contact" in condition_sentence(result, "low")


def test_a_range_stress_location_reads_in_mpa_with_an_equal_sign():
    # P(allowable < 165 MPa) for 950-3500 MPa is 0: the peak is below the range
    text = condition_sentence(_result(164.8e6, (950e6, 3500e6), "holds", unit="Pa"), "low")
    assert "below 164.8 MPa" in text and "P = 0% for an allowable uniform over 950-3500 MPa" in text
    assert text.endswith("this run judges at the low end (950 MPa): holds.")


def test_a_hold_unchecked_for_chaos_says_so():
    # structures_verdict marks every location "unchecked" until a twin run (structures.twin) labels its peaks
    result = _result(30e6, (50e6, 50e6), "holds", unit="Pa")
    result["peak_window"] = "unchecked"
    assert condition_sentence(result, "low").endswith(
        "(margin +0.67). Unchecked for chaos: a late peak of one run is one draw (structures.twin checks it; "
        "assess --monte-carlo gives P).")
    result["state"] = "fails"
    assert "Unchecked" not in condition_sentence(result, "low")


def test_each_indeterminate_reason_comes_with_its_rule():
    """Each producer of a reason returns its rule with it (the reasons keep their numbers; the rule is what a
    sweep counts), on hand-made series and checks; a location with several reasons lists each rule once, in the
    order of structures.indeterminacy.RULES."""
    import numpy as np
    import pytest

    from structures.indeterminacy import RULES, Indeterminacy, mark, rules_of
    from structures.thread_gaps import pass_through_reason
    from structures.verdict import MIN_JUDGED_SAMPLES, apply_twin, evidence_gaps, location_state

    time = np.arange(0.0, 1.0, 1e-3)
    touching = np.zeros((time.size, 1, 3))
    touching[:, 0, 1] = 100.0
    early = touching.copy()
    early[time >= 0.25] = 0.0
    short = time[:250 + MIN_JUDGED_SAMPLES - 1]
    sparse = np.arange(0.0, 1.0, 0.0101)
    assert [g.rule for g in evidence_gaps(time, early, 0.25)] == ["no_capture_load"]
    assert [g.rule for g in evidence_gaps(short, touching[:short.size], 0.25)] == ["too_few_judged_samples"]
    assert [g.rule for g in evidence_gaps(sparse, touching[:sparse.size], 0.25)] == ["coarse_sampling"]
    both = evidence_gaps(sparse[:30], touching[:30], 0.25)        # 5 judged samples, 10.1 ms apart
    row = {}
    mark(row, *location_state({"fails": False, "released_at_s": None, "judged": True}, both))
    assert row["indeterminate_rules"] == ["too_few_judged_samples", "coarse_sampling"]
    assert row["indeterminate_reason"] == "; ".join(g.reason for g in both)
    mark(row, *location_state({"fails": False, "released_at_s": None, "judged": False}, []))
    assert row["indeterminate_rules"] == ["non_finite_loads"] and row["state"] == "indeterminate"
    mark(row, *location_state({"fails": True, "released_at_s": None, "judged": True}, both))
    assert row == {"state": "fails", "indeterminate_reason": None, "indeterminate_rules": []}
    check = {"bodies": ["solar_array"], "most_threads": 17, "snapshots": 50, "first_s": 1.74, "last_s": 7.5,
             "force_bound_N": 80.0, "moment_bound_Nm": 355.0, "could_exceed": ["moment"], "worst_ratio": 1.2}
    assert pass_through_reason(check).rule == "thread_pass_through"
    row = {"name": "a", "state": "holds", "indeterminate_reason": None, "criteria": {"moment": {"peak": 100.0}}}
    verdict = apply_twin({"debris_state": "no_debris", "secondary_debris": False, "locations": [row]}, [None],
                         {}, None, 0.25, "low", note="no time left")
    assert verdict["debris_state"] == "indeterminate"
    assert row["indeterminate_rules"] == ["twin_not_run"] and "no time left" in row["indeterminate_reason"]
    # one rule per reason, each once, in RULES' order; a rule no sweep count knows is refused
    assert rules_of([Indeterminacy("chaotic_peak", "b"), Indeterminacy("twin_exceeds", "a"),
                     Indeterminacy("chaotic_peak", "c")]) == ["twin_exceeds", "chaotic_peak"]
    assert rules_of([]) == [] and len(set(RULES)) == len(RULES)
    with pytest.raises(ValueError, match="unknown indeterminacy rule"):
        rules_of([Indeterminacy("a_rule_nobody_counts", "x")])


def test_the_threads_contact_with_an_energy_error_never_reads_holds():
    """With contact.thread_segments on, a run whose energy balance drifted past THREAD_CONTACT_DRIFT_LIMIT (1 %) or
    was not recorded cannot say a location holds (rule thread_contact_energy): the 2 m/s envelope run's 2.38 %
    (docs/structures.md) is indeterminate; 0.5 % is judged as recorded."""
    from structures.verdict import THREAD_CONTACT_DRIFT_LIMIT, thread_contact_energy_gap

    assert THREAD_CONTACT_DRIFT_LIMIT == 0.01
    gap = thread_contact_energy_gap(0.0238)
    assert gap.rule == "thread_contact_energy" and "2.38 %" in gap.reason
    assert thread_contact_energy_gap(None).rule == "thread_contact_energy"
    assert thread_contact_energy_gap(float("nan")).rule == "thread_contact_energy"
    assert thread_contact_energy_gap(0.005) is None
