"""Residuals of a fit: missing measurements count zero, a diverged model never fits (issue 20)."""
import numpy as np
import pytest

from riskassess.diagnosis.fit import DIVERGED_RESIDUAL_SIGMA, first_unpredicted_time, sample_residuals


def test_missing_measurements_count_zero_and_non_finite_predictions_lose():
    model = np.array([1.0, np.nan, 3.0, np.inf])
    measured = np.array([0.5, 2.0, np.nan, 4.0])
    r = sample_residuals(model, measured, 0.5)
    # (1.0 - 0.5) / 0.5 = 1; NaN model on a measured sample: the penalty; NaN measurement: 0
    assert r.tolist() == [pytest.approx(1.0), DIVERGED_RESIDUAL_SIGMA, 0.0, DIVERGED_RESIDUAL_SIGMA]


def test_first_unpredicted_time_ignores_unmeasured_samples():
    times = np.array([0.0, 0.1, 0.2, 0.3])
    measured = {"a": np.array([1.0, np.nan, 1.0, 1.0])}
    assert first_unpredicted_time(times, {"a": np.array([1.0, np.nan, 1.0, 1.0])}, measured) is None
    assert first_unpredicted_time(times, {"a": np.array([1.0, 1.0, np.nan, np.nan])}, measured) == 0.2
