"""The MRAC laws' breathing notch (multibody/control/mrac.py, ``mrac.breathing_notch``): against its analytic
transfer function (a sinusoid at the notch frequency removed, a constant passed, another frequency scaled by
|H(e^{j omega h})|), what the laws then see, where its frequency comes from, and the case checks."""
import math

import numpy as np
import pytest

from multibody.control.mrac import NOTCH_SIGMA, NOTCH_W, law_measurement
from multibody.control.notch import notch_coefficients
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing import case_thrust_law
from tests.multibody.control.notch_cases import CASE, mrac2_case_with, spinless_case_data

OMEGA = 2.0 * math.radians(20.44)          # twice the Table 3 spin rate (rad/s), the breathing of the full net
H = 0.01                                   # sampling step (s)


def _case(**mrac):
    return mrac2_case_with("breathing_notch", **mrac)


def _law(case, spin_rate_deg_s=20.44, z0=0.04):
    mt = case.main_tether
    return case_thrust_law(case, np.array([mt.stiffness, mt.damping, mt.natural_length]), z0, 0.0, spin_rate_deg_s)


def _filtered(signal, params, state, step=H):
    """The notched elongation and the laws' rate for each sample of ``signal`` (advancing the law's memories)."""
    out = np.array([law_measurement(params, state, z, 0.0, step, True) for z in signal])
    return out[:, 0], out[:, 1]


def test_the_notch_removes_a_sinusoid_at_its_frequency_and_passes_a_constant():
    """z = 0.04 + 0.03 sin(omega t) (the full net's breathing at 20.44 deg/s: 31 mm about 40 mm, docs/towing.md).
    The zeros of H(z) sit exactly on e^{+-j omega h}, so in steady state the sinusoid is gone and the constant passes
    with the zero-frequency gain 1 (exact by the choice of g). What is left is the start transient, which decays as
    e^{-sigma t} (sigma = omega / 2Q = 0.089 1/s for Q = 4): after 300 s it is below 0.03 e^{-26.8} ~ 7e-14 m times
    the filter's transient gain; bound 1e-9 m (round-off of ~3e4 samples through poles at 1 - 9e-4 from z = 1). The
    laws' rate (the difference quotient of the notched elongation) is then 0 within 1e-7 m/s (1e-9 m / h)."""
    case = _case()
    _, params, state = _law(case)
    assert params[NOTCH_W] == pytest.approx(OMEGA, rel=1e-12)
    assert params[NOTCH_SIGMA] == pytest.approx(OMEGA / 8.0, rel=1e-12)
    t = np.arange(1, int(300.0 / H) + 1) * H
    seen, rate = _filtered(0.04 + 0.03 * np.sin(OMEGA * t), params, state)
    assert np.abs(seen[t > 290.0] - 0.04).max() < 1e-9
    assert np.abs(rate[t > 290.0]).max() < 1e-7
    assert np.abs(seen[:100] - 0.04).max() > 1e-3          # it did see the swing at the start (not a dead filter)


def test_a_constant_elongation_passes_unchanged_from_the_first_sample():
    """Started at rest on z0 (initial_state), the notch's output for a constant input z0 is z0 at every sample:
    y = g (1 + b1 + 1) z0 - (a1 + a2) z0 = z0 with g (2 + b1) = 1 + a1 + a2 (the normalisation); round-off only."""
    _, params, state = _law(_case(), z0=0.037)
    seen, rate = _filtered(np.full(1000, 0.037), params, state)
    assert np.abs(seen - 0.037).max() < 1e-14
    assert np.abs(rate).max() < 1e-11


def test_another_frequency_is_scaled_by_the_analytic_response():
    """A sinusoid at omega / 3 (inside the tow's control band) comes out, in steady state, with the amplitude
    |H(e^{j w h})| and phase arg H(e^{j w h}) of the transfer function of notch_coefficients (evaluated here in
    complex arithmetic), within 1e-9 of the 0.01 m amplitude. As the design check, that response is the continuous
    notch's (s^2 + w0^2)/(s^2 + (w0/Q) s + w0^2) at w0/3 to 1e-2 (Q = 4: 0.9956 and 5.36 deg of lag, analytic; the
    digital one at h = 0.01 s: 0.9939 and 5.26 deg, since pole-zero mapping does not preserve the width exactly)."""
    _, params, state = _law(_case())
    w = OMEGA / 3.0
    g, b1, a1, a2 = notch_coefficients(params[NOTCH_W], params[NOTCH_SIGMA], H)
    zi = np.exp(-1j * w * H)
    response = g * (1 + b1 * zi + zi ** 2) / (1 + a1 * zi + a2 * zi ** 2)
    t = np.arange(1, int(400.0 / H) + 1) * H
    seen, _ = _filtered(0.01 * np.sin(w * t), params, state)
    late = t > 380.0
    expected = 0.01 * np.abs(response) * np.sin(w * t[late] + np.angle(response))
    assert np.abs(seen[late] - expected).max() < 1e-9
    continuous = (OMEGA ** 2 - w ** 2) / (OMEGA ** 2 - w ** 2 + 1j * OMEGA * w / 4.0)
    assert abs(response) == pytest.approx(abs(continuous), abs=1e-2)
    assert np.angle(response) == pytest.approx(np.angle(continuous), abs=1e-2)


def test_the_notch_follows_the_tow_spin_or_a_stated_frequency_and_is_off_by_default():
    """The notch sits at twice the rate the tow is made at (not the case's debris.spin_rate_deg_s when another rate
    is run), at mrac.notch_frequency when given, and is off (NOTCH_W = 0: the laws see the measured elongation) in
    the shipped case unless switched on."""
    _, params, _ = _law(_case(), spin_rate_deg_s=10.71)
    assert params[NOTCH_W] == pytest.approx(2.0 * math.radians(10.71), rel=1e-12)
    _, params, _ = _law(_case(notch_frequency=0.5), spin_rate_deg_s=10.71)
    assert params[NOTCH_W] == 0.5
    shipped = load_model(CASE, TowingCase).mrac
    assert not shipped.breathing_notch and shipped.slack_hold_periods == 0.0    # defaults chosen by the replicas (docs)
    _, params, state = _law(_case(breathing_notch=False))
    assert params[NOTCH_W] == 0.0
    seen, _ = law_measurement(params, state, 0.123, 0.0, H, True)
    assert seen == 0.123


@pytest.mark.parametrize("change, words", [
    (dict(rate_filter_time=0.0), "mrac.rate_filter_time"),
    (dict(notch_frequency=2000.0), "Nyquist"),
])
def test_bad_notch_settings_are_refused_naming_the_key(change, words):
    data = load_model(CASE, TowingCase).model_dump()
    data["mrac"].update(dict(breathing_notch=True) | change)
    with pytest.raises(ValueError, match=words):
        TowingCase.model_validate(data)


def test_a_notch_without_spin_or_frequency_is_refused_naming_the_key():
    data = spinless_case_data("breathing_notch")
    with pytest.raises(ValueError, match="mrac.notch_frequency"):
        TowingCase.model_validate(data)
