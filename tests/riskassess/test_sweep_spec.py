"""Sweep definitions and the envelope statistics, without running simulations."""
import json
import tomllib

import numpy as np
import pytest

from riskassess.cli import main
from riskassess.products.envelope import envelope, envelope_statement, no_debris_lower_bound, runs_needed
from riskassess.sweep.runner import VALIDATE_ALL_UP_TO, validate_runs, validation_sample
from riskassess.cases.uncertain import parse_uncertain
from riskassess.sweep.spec import SweepSpecError, case_with, parse_vary, run_id, run_specs
from tests.riskassess.conftest import CASES

SMALL = tomllib.loads((CASES / "envisat_small.toml").read_text())


def test_vary_gives_n_values_with_both_ends():
    key, values = parse_vary("launch.velocity=10:30:5")
    assert key == "launch.velocity" and np.array_equal(values, [10, 15, 20, 25, 30])
    for bad in ("launch.velocity=10:30", "launch.velocity=a:b:3", "launch.velocity=1:2:0", "=1:2:3"):
        with pytest.raises(SweepSpecError, match="--vary"):
            parse_vary(bad)


def test_uncertain_distributions_and_their_errors():
    assert parse_uncertain("contact.mu_kinetic=uniform(0.1,0.15)") == ("contact.mu_kinetic", "uniform", (0.1, 0.15))
    with pytest.raises(SweepSpecError, match="uniform takes 2 parameters"):
        parse_uncertain("contact.mu_kinetic=uniform(0.1)")
    with pytest.raises(SweepSpecError, match="DIST one of"):
        parse_uncertain("contact.mu_kinetic=cauchy(0,1)")
    with pytest.raises(SweepSpecError, match="needs --monte-carlo"):
        run_specs([], [parse_uncertain("contact.mu_kinetic=uniform(0.1,0.15)")], 0)


def test_keys_address_items_by_name_and_index():
    case = case_with(SMALL, {"target.joints[solar_array_hinge].torsional_damping": 7.0,
                             "target.angular_velocity[2]": 0.05, "launch.velocity": 12.0})
    assert case["target"]["joints"][0]["torsional_damping"] == 7.0
    assert case["target"]["angular_velocity"] == [0.0, 0.0, 0.05]
    assert case["launch"]["velocity"] == 12.0 and SMALL["launch"]["velocity"] == 20.0  # the base is untouched
    with pytest.raises(KeyError, match="no item named 'nope'"):
        case_with(SMALL, {"target.joints[nope].torsional_damping": 1.0})
    with pytest.raises(KeyError, match="no key 'speed' at 'launch'"):
        case_with(SMALL, {"launch.speed": 1.0})


def test_grid_times_samples_with_common_draws_and_stable_ids():
    specs = run_specs([parse_vary("launch.velocity=10:20:3")], [parse_uncertain("contact.mu_kinetic=uniform(0.1,0.15)")],
                      monte_carlo=4, seed=7)
    assert len(specs) == 12 and len({s.run_id for s in specs}) == 12
    draws = [[s.overrides["contact.mu_kinetic"] for s in specs if s.grid_index == g] for g in range(3)]
    assert draws[0] == draws[1] == draws[2]       # common random numbers along the grid
    again = run_specs([parse_vary("launch.velocity=10:20:3")], [parse_uncertain("contact.mu_kinetic=uniform(0.1,0.15)")],
                      monte_carlo=4, seed=7)
    assert [s.run_id for s in again] == [s.run_id for s in specs]  # a re-run finds its runs
    assert run_id({"a": 0.1 + 0.2}) == run_id({"a": 0.3})          # ids ignore the last bits of a float


def test_uniform_draws_have_the_stated_moments():
    """Mean (a+b)/2 and std (b-a)/sqrt(12) of U(0.1, 0.15), 4000 draws: 4 standard errors."""
    specs = run_specs([], [parse_uncertain("contact.mu_kinetic=uniform(0.1,0.15)")], monte_carlo=4000, seed=3)
    x = np.array([s.overrides["contact.mu_kinetic"] for s in specs])
    std = 0.05 / np.sqrt(12)
    assert x.mean() == pytest.approx(0.125, abs=4 * std / np.sqrt(len(x)))
    assert x.std() == pytest.approx(std, rel=0.05)
    assert x.min() >= 0.1 and x.max() <= 0.15


def test_clopper_pearson_lower_bound():
    # no debris in n runs: the bound solves p^n = 1 - c exactly
    for n in (1, 5, 29, 100):
        assert no_debris_lower_bound(n, 0, 0.95) == pytest.approx(0.05 ** (1 / n), rel=1e-10)
    assert runs_needed(0.95, 0.9) == 29          # 0.9^29 = 0.047 < 0.05 <= 0.9^28 = 0.052
    assert no_debris_lower_bound(10, 10, 0.95) == 0.0
    # one debris run in 20: beta quantile, checked against the binomial tail it inverts
    from scipy.stats import binom
    p = no_debris_lower_bound(20, 1, 0.95)
    assert binom.sf(18, 20, p) == pytest.approx(0.05, rel=1e-8)   # P(>= 19 successes | p) = 1 - c


def _row(v, debris, utilization, sample=0):
    return {"state": "done", "overrides": {"launch.velocity": v}, "grid_index": int(v), "sample": sample,
            "result": {"secondary_debris": debris, "breakup_likelihood": 0.0,
                       "locations": {"hinge": {"utilization": utilization}}}}


def test_envelope_limit_and_interpolation():
    rows = [_row(10, False, 0.5), _row(15, False, 0.9), _row(20, True, 1.3), _row(25, False, 0.95)]
    env = envelope(rows)
    assert env["key"] == "launch.velocity"
    # deterministic: safe up to 15 (25 is debris-free but above an unsafe value, so not in the envelope)
    assert env["deterministic_safe_limit"] == 15 and env["deterministic_first_unsafe"] == 20
    assert env["deterministic_interpolated_limit"] == pytest.approx(15 + (1 - 0.9) / (1.3 - 0.9) * 5)
    assert env["safe_limit"] is None              # one run per value cannot give 90 % at 95 % confidence
    many = [_row(10, False, 0.5, m) for m in range(30)] + [_row(15, m == 0, 1.01, m) for m in range(30)]
    env = envelope(many)
    assert env["safe_limit"] == 10 and env["first_unsafe"] == 15


# --- issue 20: failed and indeterminate runs are unknown, never safe (item 2, sweep part) ---

def _known(v, debris, utilization=0.5, sample=0):
    row = _row(v, debris, utilization, sample)
    row["debris_state"] = "debris" if debris else "no_debris"
    return row


def _unknown(v, how, sample=0):
    """A run at ``v`` that says nothing about debris: 'diverged', 'failed', 'pending' or 'indeterminate'."""
    if how == "indeterminate":
        return {**_known(v, False, sample=sample), "debris_state": "indeterminate",
                "result": {"secondary_debris": None, "debris_state": "indeterminate", "breakup_likelihood": None,
                           "locations": {"hinge": {"utilization": float("nan")}}}}
    state = "pending" if how == "pending" else "failed"
    return {"state": state, "overrides": {"launch.velocity": v}, "grid_index": int(v), "sample": sample,
            "result": None, "debris_state": None, "error_kind": {"diverged": "diverged", "failed": "simulation"}.get(how),
            "error": "SimulationFailed: simulation failed at t = 0.1 s" if how == "diverged" else None}


def test_nan_grid_gives_no_safe_limit():
    """Issue 20 item 2: a NaN grid gave a safe limit of "nan". Records of a diverged run that no
    health check stopped (every load NaN, verdict "no debris") are indeterminate."""
    nan = float("nan")
    rows = [{"state": "done", "overrides": {"launch.velocity": v}, "grid_index": k, "sample": 0,
             "result": {"secondary_debris": False, "peak_contact_force_N": nan, "breakup_likelihood": nan,
                        "locations": {"hinge": {"utilization": nan, "likelihood": nan}}}}
            for k, v in enumerate((10.0, 15.0, 20.0))]
    env = envelope(rows)
    assert env["safe_limit"] is None and env["deterministic_safe_limit"] is None
    assert env["indeterminate_runs"] == 3 and [p["indeterminate_runs"] for p in env["points"]] == [1, 1, 1]
    json.dumps(env, allow_nan=False)                       # no NaN anywhere in envelope.json
    text = envelope_statement(env)
    assert "No launch.velocity of the sweep is safe" in text and "nan" not in text.lower()
    assert "3 indeterminate" in text


def test_a_value_whose_runs_failed_stops_the_safe_limit():
    """10 and 20 are debris-free, 15 diverged: the limit is 10, never 20 (the failed value is a point)."""
    rows = [_known(10.0, False, 0.4), _unknown(15.0, "diverged"), _known(20.0, False, 0.6)]
    env = envelope(rows)
    assert [p["value"] for p in env["points"]] == [10.0, 15.0, 20.0]
    assert env["deterministic_safe_limit"] == 10.0 and env["deterministic_first_unsafe"] == 15.0
    assert env["deterministic_interpolated_limit"] is None   # no utilization known at 15
    assert (env["failed_runs"], env["diverged_runs"]) == (1, 1)
    text = envelope_statement(env)
    assert "first value not shown safe: 15 (1 of its 1 runs unknown)" in text
    assert "1 failed (1 diverged), 0 indeterminate, 0 pending" in text


@pytest.mark.parametrize("how", ["diverged", "failed", "indeterminate", "pending"])
def test_any_unknown_run_removes_the_deterministic_safe_claim(how):
    rows = [_known(10.0, False), _known(10.0, False, sample=1), _unknown(10.0, how, sample=2)]
    point = envelope(rows)["points"][0]
    assert (point["runs"], point["unknown_runs"], point["total_runs"]) == (2, 1, 3)
    assert not point["deterministic_safe"] and not point["safe"]


def test_unknown_runs_count_as_debris_in_the_bound():
    """The rule: safe when the known runs have no debris and the bound holds even if every
    unknown run had made debris. 49 clean + 1 failed: B^-1(0.05; 49, 2) = 0.909 >= 0.9, safe;
    29 clean + 1 failed: 0.851, not safe (29 clean runs alone would be: 0.05^(1/29) = 0.902)."""
    enough = [_known(10.0, False, sample=m) for m in range(49)] + [_unknown(10.0, "diverged", sample=49)]
    point = envelope(enough)["points"][0]
    assert point["no_debris_lower_bound"] == pytest.approx(no_debris_lower_bound(50, 1, 0.95))
    assert point["safe"] and not point["deterministic_safe"]
    few = [_known(10.0, False, sample=m) for m in range(29)] + [_unknown(10.0, "indeterminate", sample=29)]
    assert not envelope(few)["points"][0]["safe"]
    assert envelope(few[:29])["points"][0]["safe"]


# --- issue 20 item 7 (sweep part): options checked before any work ---

@pytest.mark.parametrize("argv, message", [
    (["--workers", "0"], "--workers must be >= 1. Got 0"),
    (["--confidence", "1.5"], "--confidence must be between 0 and 1"),
    (["--reliability", "0"], "--reliability must be between 0 and 1"),
    (["--confidence", "nan"], "--confidence must be between 0 and 1"),
    (["--monte-carlo", "-1"], "--monte-carlo must be >= 0"),
    (["--monte-carlo", "3"], "needs --uncertain"),
    (["--seed", "-1", "--monte-carlo", "2", "--uncertain", "contact.mu_kinetic=uniform(0.1,0.2)"], "--seed must be >= 0"),
    (["--vary", "launch.velocity=10:30:10000000"], "the sweep has 10000000 runs; at most 100000"),
    (["--vary", "launch.velocity=10:30:1000", "--vary", "contact.mu_kinetic=0.1:0.2:1000"], "1000000 runs"),
    (["--vary", "launch.velocity=10:nan:3"], "finite numbers"),
    (["--vary", "launch.velocity=10:30:3", "--vary", "launch.velocity=1:2:2"], "repeated: launch.velocity"),
    (["--monte-carlo", "2", "--uncertain", "contact.mu_kinetic=normal(0.1,-1)"], "needs std >= 0"),
    (["--monte-carlo", "2", "--uncertain", "contact.mu_kinetic=uniform(0.2,0.1)"], "needs low < high"),
    ([], "nothing to sweep"),
])
def test_sweep_options_are_refused_before_any_work(argv, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    validated = []
    # refused before any run is validated: no validation of millions of runs
    monkeypatch.setattr("riskassess.sweep.runner.validate_runs", lambda *a, **k: validated.append(a))
    assert main(["sweep", str(CASES / "envisat_small.toml"), *argv]) == 2
    assert message in capsys.readouterr().err
    assert validated == []
    assert list(tmp_path.iterdir()) == []                    # no store, no folder


def test_large_grid_validates_each_value_once():
    """A 1000 x 30 grid: each of the 1030 values (and the 4 corners) is validated once, not 30 000 cases."""
    specs = run_specs([parse_vary("launch.velocity=10:30:1000"), parse_vary("contact.mu_kinetic=0.1:0.2:30")])
    sample, what = validation_sample(specs)
    values = {(k, s.overrides[k]) for s in sample for k in s.overrides}
    assert len(values) == 1030 and len(sample) <= 1030 + 4
    corners = {(s.overrides["launch.velocity"], s.overrides["contact.mu_kinetic"]) for s in sample}
    assert {(10.0, 0.1), (10.0, 0.2), (30.0, 0.1), (30.0, 0.2)} <= corners
    assert "of 30000 runs validated" in what and "1030 distinct values" in what
    small = specs[:VALIDATE_ALL_UP_TO]
    assert validation_sample(small) == (small, f"all {VALIDATE_ALL_UP_TO} runs validated")


def test_sampled_validation_still_finds_a_bad_value():
    """-1 m/s in a 300-run grid (above the validate-all limit) is caught before any run."""
    text = (CASES / "envisat_small.toml").read_text()
    specs = run_specs([parse_vary("launch.velocity=-1:20:30"), parse_vary("contact.mu_kinetic=0.1:0.2:10")])
    with pytest.raises(SweepSpecError, match=r"of \d+ validated sweep runs give an invalid case \(\d+ of 300 runs"):
        validate_runs(str(CASES / "envisat_small.toml"), text, specs)


def test_clopper_pearson_matches_its_closed_forms():
    """Clopper-Pearson ends: for k = 0 the upper end is 1 - (alpha/2)^(1/n), for k = n the lower end
    is (alpha/2)^(1/n) (the binomial tail equations solved by hand)."""
    from riskassess.products.envelope import clopper_pearson

    low, high = clopper_pearson(0, 20, 0.95)
    assert low == 0.0 and abs(high - (1.0 - 0.025 ** (1 / 20))) < 1e-12
    low, high = clopper_pearson(20, 20, 0.95)
    assert high == 1.0 and abs(low - 0.025 ** (1 / 20)) < 1e-12
    # k = 3 of 20: the textbook interval 3.2 %-37.9 % (e.g. R's binom.test(3, 20))
    low, high = clopper_pearson(3, 20, 0.95)
    assert abs(low - 0.0321) < 5e-4 and abs(high - 0.3789) < 5e-4


def test_debris_probability_never_counts_unknown_runs_as_safe():
    from riskassess.products.envelope import clopper_pearson, debris_probability

    rows = ([{"state": "done", "result": {"debris_state": "debris"}}] * 3
            + [{"state": "done", "result": {"debris_state": "no_debris"}}] * 15
            + [{"state": "failed", "result": None}] * 2)
    p = debris_probability(rows, 0.95)
    assert (p["runs"], p["debris_runs"], p["no_debris_runs"], p["unknown_runs"]) == (20, 3, 15, 2)
    assert p["estimate"] == 3 / 18
    # lower end: the 2 unknown runs debris-free (3 of 20); upper end: both with debris (5 of 20)
    assert p["interval"] == [clopper_pearson(3, 20, 0.95)[0], clopper_pearson(5, 20, 0.95)[1]]


def test_utilization_sensitivity_is_the_rank_correlation_with_each_input():
    """Spearman's rho: 1 for a utilization that grows monotonically (here cubically) with an input,
    -1 for one that falls with it, None for a constant input; failed runs left out."""
    from riskassess.products.envelope import utilization_sensitivity

    rng = np.random.default_rng(0)
    rows = []
    for x, y in zip(rng.uniform(10, 20, 12), rng.uniform(0.1, 0.2, 12)):
        rows.append({"state": "done", "overrides": {"launch.velocity": x, "contact.mu_kinetic": y, "c": 1.0},
                     "result": {"locations": {"hinge": {"utilization": (x / 10) ** 3},
                                              "dish": {"utilization": 1.0 / y}}}})
    rows.append({"state": "failed", "overrides": {"launch.velocity": 99.0, "contact.mu_kinetic": 0.5, "c": 1.0},
                 "result": None})
    s = utilization_sensitivity(rows)
    assert s["hinge"]["launch.velocity"] == pytest.approx(1.0) and s["dish"]["contact.mu_kinetic"] == pytest.approx(-1.0)
    assert abs(s["hinge"]["contact.mu_kinetic"]) < 0.7 and s["hinge"]["c"] is None


def test_single_run_probability_holds_no_number_whatever_the_run_said():
    """A single run's p_secondary_debris (assess --json without --monte-carlo): no estimate, no interval, for each of
    the three answers; an indeterminate run is never worded as no debris, and only the deciding locations' conditions
    are quoted."""
    from riskassess.products.envelope import single_run_probability

    holds = {"name": "a", "state": "holds", "condition": "a holds: margin +0.50."}
    fails = {"name": "b", "state": "fails", "condition": "b breaks if its moment allowable is below 223 N m."}
    unknown = {"name": "c", "state": "indeterminate", "condition": "c: indeterminate (twin unchecked)."}
    cases = {"debris": ([holds, fails], "secondary debris.", [fails], [holds]),
             "no_debris": ([holds], "no secondary debris.", [holds], []),
             "indeterminate": ([holds, unknown], "indeterminate (no verdict; never read as no debris).", [unknown],
                               [holds])}
    for state, (locations, answer, quoted, left_out) in cases.items():
        p = single_run_probability({"debris_state": state, "locations": locations, "released_pieces": []})
        assert p["estimate"] is None and p["interval"] is None and p["confidence"] is None and p["runs"] == 0
        assert p["deterministic"] == state and p["needs"] == "--monte-carlo N"
        assert p["condition"].startswith(f"One deterministic run: {answer} ")
        assert all(loc["condition"] in p["condition"] for loc in quoted)
        assert not any(loc["condition"] in p["condition"] for loc in left_out)
    # a release without a failing row (older folders) still says what made the debris
    p = single_run_probability({"debris_state": "debris", "locations": [holds], "released_pieces": [{}]})
    assert "1 piece(s) released." in p["condition"]
