"""Sweep definitions and the envelope statistics, without running simulations."""
import tomllib

import numpy as np
import pytest

from riskassess.sweep.envelope import envelope, no_debris_lower_bound, runs_needed
from riskassess.sweep.spec import (SweepSpecError, case_with, parse_uncertain, parse_vary, run_id, run_specs)
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
