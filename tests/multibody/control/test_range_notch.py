"""The MRAC laws' range-rate notch (multibody/control/mrac.py, ``mrac.range_notch``): the range damping's range rate
through a notch at the debris spin rate, against its analytic transfer function (a sinusoid at the spin rate removed,
a constant and twice the spin rate passed as |H(e^{j omega h})| says), the laws' thrust changed by exactly the range
term, where the frequency comes from, and the case checks."""
import math

import numpy as np
import pytest

from multibody.control.mrac import C_RANGE, RANGE_NOTCH_SIGMA, RANGE_NOTCH_W, range_rate_seen
from multibody.control.notch import notch_coefficients
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing import case_thrust_law
from tests.multibody.control.notch_cases import CASE, mrac2_case_with, spinless_case_data

SPIN = 29.01                               # deg/s, the Table 3 rate at which the once-per-turn line failed the laws
OMEGA = math.radians(SPIN)                 # rad/s, the notch's centre
H = 0.01                                   # sampling step (s)


def _case(**mrac):
    return mrac2_case_with("range_notch", **mrac)


def _law(case, spin_rate_deg_s=SPIN, z0=0.04):
    mt = case.main_tether
    return case_thrust_law(case, np.array([mt.stiffness, mt.damping, mt.natural_length]), z0, 0.0, spin_rate_deg_s)


def _seen(signal, params, state, step=H):
    """The range rate the range damping acts on, for each sample of ``signal`` (advancing the notch's memory)."""
    return np.array([range_rate_seen(params, state, r, step, True) for r in signal])


def _response(params, w, step=H):
    """H(e^{j w h}) of the range notch's difference equation (notch_coefficients), in complex arithmetic."""
    g, b1, a1, a2 = notch_coefficients(params[RANGE_NOTCH_W], params[RANGE_NOTCH_SIGMA], step)
    zi = np.exp(-1j * w * step)
    return g * (1 + b1 * zi + zi ** 2) / (1 + a1 * zi + a2 * zi ** 2)


def test_the_notch_removes_a_sinusoid_at_the_spin_rate_and_passes_a_constant():
    """r' = 0.01 + 0.1 sin(omega t) m/s (0.1 m/s: the once-per-turn line at 29.01 deg/s, ~0.2 m at 0.506 rad/s,
    docs/towing.md). The zeros of H(z) sit on e^{+-j omega h}: in steady state the sinusoid is gone, the constant
    passes with the zero-frequency gain 1 (exact by the choice of g). The start transient (the notch starts at rest on
    0) decays as e^{-sigma t}, sigma = omega / 2Q = 0.0844 1/s for Q = 3: after 290 s below 0.11 e^{-24.5} ~ 3e-12 m/s
    times the filter's transient gain; bound 1e-9 m/s (round-off of 3e4 samples through poles at 1 - 8e-4)."""
    _, params, state = _law(_case())
    assert params[RANGE_NOTCH_W] == pytest.approx(OMEGA, rel=1e-12)
    assert params[RANGE_NOTCH_SIGMA] == pytest.approx(OMEGA / 6.0, rel=1e-12)
    t = np.arange(1, int(300.0 / H) + 1) * H
    seen = _seen(0.01 + 0.1 * np.sin(OMEGA * t), params, state)
    assert np.abs(seen[t > 290.0] - 0.01).max() < 1e-9
    assert np.abs(seen[:300] - 0.01).max() > 1e-2          # it did see the line at the start (not a dead filter)


@pytest.mark.parametrize("ratio", [2.0, 1.0 / 3.0])
def test_other_frequencies_pass_as_the_analytic_response_says(ratio):
    """A sinusoid at 2 omega (the net's breathing, which the range damping was sized for) and at omega / 3 (the tow's
    slow bounce band) comes out in steady state with the amplitude |H(e^{j w h})| and the phase arg H(e^{j w h}) of the
    difference equation, within 1e-9 of the 0.1 m/s amplitude (transient e^{-sigma 380 s} ~ 1e-14). Design check: the
    pole-zero placement is the continuous filter k (s^2 + w0^2) / ((s + sigma)^2 + w0^2), k = (sigma^2 + w0^2) / w0^2
    (poles at -sigma +- j w0 mapped by e^{s h}, gain 1 at zero frequency), to 1e-3 at h = 0.01 s (w h = 0.01); for
    Q = 3 its gain is 1.012 at 2 omega (3 k / |sigma^2/w0^2 - 3 + 4 j sigma/w0|, analytic) and 0.989 at omega / 3: the
    range damping keeps its full strength at twice the spin rate and at the slow bounce."""
    _, params, state = _law(_case())
    w = ratio * OMEGA
    response = _response(params, w)
    t = np.arange(1, int(400.0 / H) + 1) * H
    seen = _seen(0.1 * np.sin(w * t), params, state)
    late = t > 380.0
    expected = 0.1 * np.abs(response) * np.sin(w * t[late] + np.angle(response))
    assert np.abs(seen[late] - expected).max() < 1e-9
    sigma, s_ = OMEGA / 6.0, 1j * w
    continuous = (sigma ** 2 + OMEGA ** 2) / OMEGA ** 2 * (s_ ** 2 + OMEGA ** 2) / ((s_ + sigma) ** 2 + OMEGA ** 2)
    assert abs(response) == pytest.approx(abs(continuous), abs=1e-3)
    assert np.angle(response) == pytest.approx(np.angle(continuous), abs=1e-3)
    assert abs(response) == pytest.approx(1.012 if ratio == 2.0 else 0.989, abs=1e-3)


@pytest.mark.parametrize("kind", ["mrac1", "mrac2"])
def test_the_laws_thrust_changes_by_the_range_term_alone(kind):
    """Both laws, the same samples (elongation at z_d, a range rate 0.05 sin(omega t) m/s) with the notch off and on:
    the range term -c_R r' neither adapts nor moves the reference model (the command stays inside +-200 N: 141 +- 50 N),
    so the two thrusts differ by exactly -c_R (r'_seen - r') at every sample (round-off 1e-9 N), and from 290 s on the
    notched law's thrust carries no line at omega (its range term is below c_R x 1e-9 m/s)."""
    t = np.arange(1, int(300.0 / H) + 1) * H
    rate = 0.05 * np.sin(OMEGA * t)
    thrust = {}
    for on in (False, True):
        case = _case(range_notch=on)
        case = case.model_copy(update=dict(thrust=case.thrust.model_copy(update=dict(kind=kind))))
        law, params, state = _law(case)
        notch_state = state.copy()
        seen = _seen(rate, params, notch_state) if on else rate
        thrust[on] = np.array([law.command(ti, 0.04, 0.0, r, params, state, H, True) for ti, r in zip(t, rate)])
    after_on = t >= case.thrust.t_on
    assert np.abs(thrust[True] - thrust[False] + params[C_RANGE] * (seen - rate))[after_on].max() < 1e-9
    assert np.abs(thrust[False]).max() < case.thrust.max_force                     # never saturated
    late = t > 300.0 - 2.0 * 2.0 * math.pi / OMEGA                    # the last two spin periods (after 275 s)
    line = {on: abs(2.0 * np.mean(thrust[on][late] * np.exp(-1j * OMEGA * t[late]))) for on in thrust}
    assert line[False] == pytest.approx(params[C_RANGE] * 0.05, rel=1e-2)   # c_R x 0.05 m/s = 50 N without the notch
    assert line[True] < 1e-3 * line[False]


def test_the_notch_follows_the_tow_spin_and_is_off_unless_asked():
    """The notch sits at the rate the tow is made at (not the case's debris.spin_rate_deg_s when another rate is run);
    off (RANGE_NOTCH_W = 0) the range damping sees the measured range rate itself, bit for bit."""
    _, params, _ = _law(_case(), spin_rate_deg_s=10.71)
    assert params[RANGE_NOTCH_W] == pytest.approx(math.radians(10.71), rel=1e-12)
    _, params, state = _law(_case(range_notch=False))
    assert params[RANGE_NOTCH_W] == 0.0
    assert range_rate_seen(params, state, 0.123, H, True) == 0.123


def test_a_notch_without_range_damping_is_refused_naming_the_key():
    data = load_model(CASE, TowingCase).model_dump()
    data["mrac"].update(range_notch=True, range_damping=0.0)
    with pytest.raises(ValueError, match="mrac.range_damping"):
        TowingCase.model_validate(data)


def test_a_notch_without_spin_is_refused_naming_the_key():
    data = spinless_case_data("range_notch")
    with pytest.raises(ValueError, match="mrac.range_notch"):
        TowingCase.model_validate(data)
