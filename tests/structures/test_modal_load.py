"""The load a structural mode carries (structures/modal_load.py) against the single-degree-of-freedom
oscillator's closed forms (Clough & Penzien, Dynamics of Structures, Ch. 4-6): step, impulse,
harmonic response and the static limit."""
import numpy as np
import pytest

from structures.modal_load import modal_load


def test_suddenly_applied_load_is_amplified_by_the_step_response():
    # step of R0 on a mode f, zeta: peak R0 (1 + exp(-zeta pi / sqrt(1 - zeta^2))), 2 R0 undamped
    t = np.arange(0.0, 2.0, 1e-3)
    step = np.where(t >= 0.1, 3.0, 0.0)
    for zeta in (0.0, 0.02, 0.05):
        expected = 3.0 * (1.0 + np.exp(-zeta * np.pi / np.sqrt(1.0 - zeta ** 2)))
        # 0.2 %: the step is read as a ramp over one sample (first-order hold), 1/50 of the period
        assert modal_load(t, step, 20.0, zeta).max() == pytest.approx(expected, rel=2e-3)


def test_short_pulse_gives_impulse_times_omega():
    # an impulse J much shorter than the period: undamped peak J omega, whatever the pulse shape
    t = np.arange(0.0, 1.0, 1e-4)
    pulse = np.where((t >= 0.1) & (t < 0.1005), 2.0 / 5e-4, 0.0)          # J = 2 N s over 0.5 ms
    for f in (2.0, 5.0):
        # 0.5 %: the pulse lasts 0.25 % of a period (its finite width lowers the peak by ~(pi f tau)^2 / 6)
        assert modal_load(t, pulse, f, 0.0).max() == pytest.approx(2.0 * 2 * np.pi * f, rel=5e-3)


def test_slow_and_fast_harmonics():
    # harmonic R = sin(2 pi fr t): steady amplitude 1 / sqrt((1 - r^2)^2 + (2 zeta r)^2), r = fr / f
    t = np.arange(0.0, 20.0, 1e-4)
    f, zeta = 5.0, 0.05
    for fr in (0.5, 5.0, 100.0):
        r = fr / f
        late = t > 15.0
        amplitude = np.abs(modal_load(t, np.sin(2 * np.pi * fr * t), f, zeta)[late]).max()
        # 1 %: transients have decayed by exp(-zeta omega 15 s) = 1e-10; 100 samples a period of the
        # 100 Hz input: the linear interpolation loses (pi / 100)^2 / 3 = 0.03 %, the sampled maximum
        # misses the crest by at most 1 - cos(pi / 100) = 0.05 %
        assert amplitude == pytest.approx(1 / np.sqrt((1 - r * r) ** 2 + (2 * zeta * r) ** 2), rel=1e-2)


def test_static_load_passes_unchanged_and_components_are_independent():
    t = np.arange(0.0, 1.0, 1e-3)
    load = np.column_stack([np.full_like(t, 5.0), np.zeros_like(t), np.full_like(t, -2.0)])
    out = modal_load(t, load, 10.0, 0.02)
    # a load present from the first sample is static: the mode starts deflected under it
    assert np.abs(out - load).max() < 1e-9


def test_non_uniform_samples_are_refused():
    with pytest.raises(ValueError, match="uniformly spaced"):
        modal_load(np.array([0.0, 1e-3, 3e-3, 4e-3]), np.zeros(4), 10.0, 0.02)
