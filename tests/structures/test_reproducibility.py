"""Reproducible or chaotic peaks (structures/reproducibility.py) and the twin check of a verdict
(structures.verdict.apply_twin, case key structures.twin): a peak its twin run does not reproduce never
reads as safe."""
from pathlib import Path

import numpy as np
import pytest

from riskassess.cases.impact import CaseError, load_case
from riskassess.stages.run import run_case
from structures.criteria import Allowable
from structures.reproducibility import parting_time, twin_label
from structures.verdict import apply_twin
from structures.weak_location import WeakLocation, assess

CASES = Path(__file__).resolve().parents[2] / "cases"
T = np.arange(0.0, 2.0, 1e-3)


def _moment_history(late_peak):
    """A joint moment about h1 (N m): a 100 N m bump at 0.5 s shared by both runs, then a late strike at
    1.5 s of ``late_peak``."""
    moment = np.zeros((T.size, 3))
    moment[:, 0] = 100.0 * np.exp(-((T - 0.5) / 0.05) ** 2) + late_peak * np.exp(-((T - 1.5) / 0.02) ** 2)
    return moment


def test_runs_part_when_their_peaks_so_far_spread_beyond_the_tolerance():
    a, b = _moment_history(300.0)[:, 0], _moment_history(250.0)[:, 0]
    # identical through the first bump; the late strikes (300 / 250 N m at 1.5 s) part the running maxima
    # on their rise, once they pass the bump's 100 N m and differ by 5 % of the median, before 1.5 s
    parting = parting_time(T, [a, b])
    assert 1.4 < parting < 1.5
    assert parting_time(T, [a, a]) == np.inf
    # a phase drift of a ringing load (50 N m at 50 Hz after the shared bump) leaves the peaks alone: no parting
    bump = _moment_history(0.0)[:, 0]
    ringing = [bump + 50.0 * (T > 1.0) * np.sin(2 * np.pi * 50 * T + phase) for phase in (0.0, 0.3)]
    assert parting_time(T, ringing) == np.inf


def test_a_late_peak_is_chaotic_an_early_one_deterministic():
    late = twin_label(T, _moment_history(300.0)[:, 0], _moment_history(250.0)[:, 0], skip_until=0.25)
    assert late["window"] == "chaotic" and not late["reproduced"] and late["twin_peak"] == pytest.approx(250.0, rel=1e-3)
    early = twin_label(T, _moment_history(50.0)[:, 0], _moment_history(40.0)[:, 0], skip_until=0.25)
    # the peak (100 N m at 0.5 s) comes before the late strikes (50 / 40 N m) could part the running maxima
    assert early["window"] == "deterministic" and early["reproduced"] and early["parting_time_s"] is None


def _verdict(run_moment, twin_moment, allowable=1000.0):
    location = WeakLocation(name="root", joint=0, section_to_joint=np.eye(3), offset_joint=np.zeros(3),
                            allowable_moment=Allowable.of(allowable))
    row = assess(location, T, np.zeros_like(run_moment), run_moment, skip_until=0.25)
    row.update(state="holds", indeterminate_reason=None, released_at_s=None)
    verdict = {"locations": [row], "debris_state": "no_debris", "secondary_debris": False}
    series = {"time": T, "joint_force_joint": np.zeros((T.size, 1, 3)), "joint_moment_joint": run_moment[:, None]}
    twin = None if twin_moment is None else dict(series, joint_moment_joint=twin_moment[:, None])
    return apply_twin(verdict, [location], series, twin, 0.25, "low", "" if twin is not None else "no twin")


def test_a_location_holding_on_a_chaotic_peak_is_indeterminate():
    verdict = _verdict(_moment_history(300.0), _moment_history(250.0))
    row = verdict["locations"][0]
    assert row["state"] == "indeterminate" and row["peak_window"] == "chaotic"
    assert "one draw of a chaotic capture" in row["indeterminate_reason"]
    assert verdict["debris_state"] == "indeterminate" and verdict["secondary_debris"] is None


def test_a_reproduced_peak_holds_and_says_so():
    verdict = _verdict(_moment_history(300.0), _moment_history(300.0))
    row = verdict["locations"][0]
    assert row["state"] == "holds" and row["peak_window"] == "deterministic"
    assert "reproduced by a twin run 1e-07 apart in launch speed" in row["condition"]
    assert verdict["debris_state"] == "no_debris"


def test_a_twin_that_exceeds_or_did_not_run_leaves_nothing_safe():
    # the twin's late strike (1200 N m) exceeds the 1000 N m allowable the run (300 N m) holds
    exceeded = _verdict(_moment_history(300.0), _moment_history(1200.0))["locations"][0]
    assert exceeded["state"] == "indeterminate" and "its twin run exceeds its moment allowable" in exceeded[
        "indeterminate_reason"]
    missing = _verdict(_moment_history(300.0), None)
    assert missing["locations"][0]["state"] == "indeterminate" and missing["debris_state"] == "indeterminate"
    assert missing["twin"]["ran"] is False


def test_a_chaotic_or_exceeded_twin_gives_its_rule_to_the_sweep_store():
    """The rules chaotic_peak and twin_exceeds come from apply_twin itself (structures.indeterminacy) and travel
    through the sweep's record (riskassess.sweep.runner.run_record) to its counts per (location, rule)."""
    from riskassess.products.sweep_records import indeterminate_rule_counts
    from riskassess.sweep.runner import run_record

    chaotic = _verdict(_moment_history(300.0), _moment_history(250.0))       # twin peaks -17 %: not reproduced
    exceeded = _verdict(_moment_history(300.0), _moment_history(1200.0))     # twin 1200 N m > 1000 N m allowable
    assert chaotic["locations"][0]["indeterminate_rules"] == ["chaotic_peak"]
    assert exceeded["locations"][0]["indeterminate_rules"] == ["twin_exceeds"]
    # one location with a force and a moment criterion: the twin exceeds the force allowable (the run's 300 N
    # holds 1000 N, the twin's 1200 N does not) while its moment peak is a chaotic draw: both rules, once each
    location = WeakLocation(name="root", joint=0, section_to_joint=np.eye(3), offset_joint=np.zeros(3),
                            allowable_moment=Allowable.of(1000.0), allowable_force=Allowable.of(1000.0))
    force, twin_force = _moment_history(300.0), _moment_history(1200.0)
    moment, twin_moment = _moment_history(300.0), _moment_history(250.0)
    row = assess(location, T, force, moment, skip_until=0.25)
    row.update(state="holds", indeterminate_reason=None, released_at_s=None)
    series = {"time": T, "joint_force_joint": force[:, None], "joint_moment_joint": moment[:, None]}
    twin = {"time": T, "joint_force_joint": twin_force[:, None], "joint_moment_joint": twin_moment[:, None]}
    both = apply_twin({"locations": [row], "debris_state": "no_debris", "secondary_debris": False}, [location],
                      series, twin, 0.25, "low")
    assert both["locations"][0]["indeterminate_rules"] == ["twin_exceeds", "chaotic_peak"]
    assert both["debris_state"] == "indeterminate"
    summary = {"peak_contact_force_N": {"value": 1.0}, "peak_contact_moment_about_debris_com_Nm": {"value": 1.0},
               "joints": {}, "checks": {"energy_balance_relative_drift": 0.0}, "wall_time_s": 1.0,
               "steps_per_second": 1.0}
    records = [run_record(summary, verdict | {"released_pieces": []}, {}) for verdict in (chaotic, exceeded, both)]
    assert records[2]["locations"]["root"]["indeterminate_rules"] == ["twin_exceeds", "chaotic_peak"]
    assert indeterminate_rule_counts([{"state": "done", "result": r} for r in records]) == {
        ("root", "chaotic_peak"): 2, ("root", "twin_exceeds"): 2}


def _short_case(tmp_path, extra=""):
    text = (CASES / "envisat_small.toml").read_text().replace("end_time = 7.5", "end_time = 0.6")
    text = text.replace('release = "low"', 'release = "never"\ntwin = true' + extra)
    # an array 100x stronger, so that the short run holds everywhere and the twin runs
    text = text.replace("allowable_moment = [200.0, 1000.0]", "allowable_moment = [20000.0, 100000.0]")
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_an_assessed_run_labels_every_judged_peak_against_its_twin(tmp_path):
    # envisat_small for 0.6 s: the first impact, judged from 0.25 s; the twin runs 1e-7 faster
    verdict = run_case(_short_case(tmp_path), tmp_path / "run").structures
    assert verdict["twin"]["ran"] is True, verdict["twin"]
    for row in verdict["locations"]:
        labels = [c["twin"] for c in row["criteria"].values() if c["peak"] is not None]
        assert labels and all(label["window"] in ("deterministic", "chaotic") for label in labels)
        # never safe on an unreproduced peak
        if row["state"] == "holds":
            assert all(label["reproduced"] for label in labels)
    assert verdict["debris_state"] != "no_debris" or all(r["peak_window"] == "deterministic" for r in verdict["locations"])


def test_a_twin_check_of_a_sequential_run_is_refused(tmp_path):
    path = _short_case(tmp_path)
    path.write_text(path.read_text().replace('integrator = "VelocityVerlet"',
                                             'integrator = "VelocityVerlet"\ncoupling = "sequential"'))
    with pytest.raises(CaseError, match="structures.twin checks the peaks of a coupled run"):
        load_case(path)
