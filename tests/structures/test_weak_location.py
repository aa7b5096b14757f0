"""The load history a reported peak comes with (structures.weak_location.history_around_peak)."""
import numpy as np
import pytest

from structures.weak_location import PEAK_HISTORY_HALF_WIDTH_S, PEAK_HISTORY_SAMPLES, history_around_peak


def test_peak_width_of_a_gaussian_pulse_is_its_full_width_at_half_maximum():
    # a Gaussian exp(-(t/s)^2) is above half its peak over 2 s sqrt(ln 2) (analytic), read to one
    # sample interval at 1 kHz and at 10 kHz
    sigma = 0.01
    for interval in (1e-3, 1e-4):
        t = np.arange(0.0, 1.0, interval)
        demand = 3.0e6 * np.exp(-((t - 0.5) / sigma) ** 2)
        k = int(np.argmax(demand))
        out = history_around_peak(t, demand, k)
        assert out["peak_width_s"] == pytest.approx(2 * sigma * np.sqrt(np.log(2)), abs=interval)
        kept = np.array(out["peak_history"]["time_s"])
        assert t[k] in kept and len(kept) <= PEAK_HISTORY_SAMPLES + 1
        assert kept.min() >= t[k] - PEAK_HISTORY_HALF_WIDTH_S - 1e-12
        assert kept.max() <= t[k] + PEAK_HISTORY_HALF_WIDTH_S + 1e-12
        assert max(out["peak_history"]["demand"]) == demand[k]


def test_a_one_sample_spike_has_the_width_of_one_sample():
    t = np.arange(0.0, 0.2, 1e-3)
    demand = np.zeros_like(t)
    demand[100] = 5.0
    assert history_around_peak(t, demand, 100)["peak_width_s"] == pytest.approx(1e-3)
