"""The load history a reported peak comes with (structures.weak_location.history_around_peak)."""
import numpy as np
import pytest

from structures.weak_location import (PEAK_HISTORY_HALF_WIDTH_S, PEAK_HISTORY_SAMPLES, WeakLocation, history_around_peak,
                                      joint_loads, reading)


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


def test_a_filtered_location_is_judged_on_its_joints_filtered_loads():
    """With load_filter_hz the location reads joint_*_filtered_joint (multibody.load_filter), says so in its reading, and
    refuses a run that recorded no filtered loads (never silently the raw ones)."""
    series = {"joint_force_joint": np.ones((4, 2, 3)), "joint_moment_joint": 2 * np.ones((4, 2, 3)),
              "joint_force_filtered_joint": 3 * np.ones((4, 2, 3)), "joint_moment_filtered_joint": 4 * np.ones((4, 2, 3))}
    raw = WeakLocation(name="root", joint=1, section_to_joint=np.eye(3), offset_joint=np.zeros(3))
    filtered = WeakLocation(name="root", joint=1, section_to_joint=np.eye(3), offset_joint=np.zeros(3), load_filter_hz=3.0)
    assert [float(a[0, 0]) for a in joint_loads(raw, series)] == [1.0, 2.0]
    assert [float(a[0, 0]) for a in joint_loads(filtered, series)] == [3.0, 4.0]
    assert reading(filtered).startswith("through a 4th-order Butterworth low-pass at 3 Hz run every step")
    assert reading(raw) == "as recorded (the stiff joint's reaction)"
    with pytest.raises(KeyError, match="recorded no filtered loads"):
        joint_loads(filtered, {k: v for k, v in series.items() if "filtered" not in k})
