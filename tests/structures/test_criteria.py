"""Allowables as ranges: likelihood of failure under a uniform law, margins, exceedance times."""
import numpy as np
import pytest

from structures.criteria import Allowable, combined_likelihood, first_exceedance_time


def test_uniform_range_likelihood():
    # The paper's hinge-panel interface, 200-1000 N m: a 600 N m demand breaks half the
    # plausible structures (uniform law), 4 kN m (the paper's loads) all of them.
    a = Allowable.of([200.0, 1000.0])
    assert a.likelihood_of_failure(100.0) == 0.0
    assert a.likelihood_of_failure(600.0) == pytest.approx(0.5)
    assert a.likelihood_of_failure(4000.0) == 1.0
    assert a.margin_of_safety(100.0, "low") == pytest.approx(1.0)
    assert a.margin_of_safety(500.0, "high") == pytest.approx(1.0)
    assert Allowable.of(300.0).likelihood_of_failure(300.0) == 1.0


def test_independent_criteria_combine():
    assert combined_likelihood([0.5, 0.5]) == pytest.approx(0.75)
    assert combined_likelihood([]) == 0.0


def test_first_exceedance_respects_the_skipped_transient():
    t = np.linspace(0.0, 1.0, 11)
    demand = np.array([9, 0, 0, 1, 5, 6, 0, 0, 0, 7, 0], float)
    assert first_exceedance_time(t, demand, 5.0) == 0.0
    assert first_exceedance_time(t, demand, 5.0, skip_until=0.25) == pytest.approx(0.4)
    assert first_exceedance_time(t, demand, 8.0, skip_until=0.25) is None
