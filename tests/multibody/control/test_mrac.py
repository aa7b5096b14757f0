"""The MRAC laws' shared parts (multibody/control/mrac.py): the reference model of eq. (13) against its exact
linear solution, and the actuator's saturation with a thrust floor (``mrac.min_thrust``): what is clipped, when the
adaptation is frozen, and the case check of the floor."""
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from multibody.control.mrac import (A0, B, C_MT, K_D, K_MT, K_P, RATE_LAST, U_MAX, U_MIN, Z_D, Z_LAST, ZM, ZM_RATE,
                                    adapting, advance_reference, reference_acceleration, saturated)
from multibody.control.thrust_laws import LAWS
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase

CASE = Path(__file__).parents[3] / "cases" / "zenit2_towing.toml"


def _case(**mrac):
    """The shipped case (the paper's symmetric saturation, no thrust band) with ``mrac`` keys changed."""
    case = load_model(CASE, TowingCase)
    return case.model_copy(update=dict(mrac=case.mrac.model_copy(update=dict(thrust_band=None) | mrac)))


def _arrays(kind, case, z0=0.0, rate0=0.0):
    mt = case.main_tether
    return LAWS[kind].arrays(case, np.array([mt.stiffness, mt.damping, mt.natural_length]), z0, rate0)


def test_the_reference_model_step_response_is_the_exact_linear_one():
    """Eq. (13) taut and unsaturated is linear: z_m'' = -b (k + K_P) z_m - b (c + K_D) z_m' + b K_P z_cmd. Started
    taut at 10 mm and advanced by advance_reference (forward Euler, the controller's digital step) at h = 0.1 ms
    for 10 s, it follows the matrix-exponential solution of that system within 2e-6 m (forward Euler's global
    error, of order h/2 omega_m |z_d - z_0| = 2.5e-6; measured 8.4e-7) and ends at z_d = 0.04 m (settle_at_desired:
    the command z_d (k + K_P)/K_P; the shipped reference has omega_m = 1.68 rad/s, damping ratio 0.95, so 10 s leave
    ~e^-16 of the step). The PD force stays inside the saturation throughout (checked), so the linear solution applies."""
    case = _case()
    params, state = _arrays("mrac2", case, z0=0.01)
    b, k, c, kp, kd, zc = (params[i] for i in (B, K_MT, C_MT, K_P, K_D, Z_D))
    a = np.array([[0.0, 1.0], [-b * (k + kp), -b * (c + kd)]])
    forcing = np.linalg.solve(a, [0.0, -b * kp * zc])          # the equilibrium x* with a x* + [0, b K_P z_cmd] = 0
    h, n = 1e-4, 100_000
    worst = 0.0
    for i in range(1, n + 1):
        pd = kp * (zc - state[ZM]) - kd * state[ZM_RATE]
        assert params[U_MIN] < pd < params[U_MAX]
        advance_reference(params, state, reference_acceleration(params, state[ZM], state[ZM_RATE]), h)
        if i % 1000 == 0:
            exact = forcing + expm(a * i * h) @ (np.array([0.01, 0.0]) - forcing)
            worst = max(worst, abs(state[ZM] - exact[0]))
    assert worst < 2e-6
    assert forcing[0] == pytest.approx(case.mrac.desired_elongation, rel=1e-12)
    assert state[ZM] == pytest.approx(case.mrac.desired_elongation, abs=1e-6)


def test_the_thrust_floor_clips_the_command_and_freezes_the_adaptation():
    """With mrac.min_thrust = 0 the actuator range is [0, u_max]: sat(u) clips to it, H(.) is 1 only strictly
    inside it (eqs. 15, 20), and the reference model's PD force is clipped the same way, so a reference released
    far above its command follows the free tether exactly, z_m'' = -b (k z_m + c z_m') (no negative PD force).
    MRAC-2 at an elongation far above its command returns exactly 0 N (not -u_max, the paper's symmetric
    saturation) and leaves its adaptive parameters unchanged; without the floor it returns -u_max."""
    floor = _case(min_thrust=0.0)
    params, state = _arrays("mrac2", floor, z0=0.5)
    assert params[U_MIN] == 0.0 and params[U_MAX] == floor.thrust.max_force
    assert saturated(-50.0, params) == 0.0 and saturated(250.0, params) == params[U_MAX]
    assert saturated(120.0, params) == 120.0
    assert not adapting(0.0, params) and adapting(1e-9, params) and not adapting(params[U_MAX], params)
    b, k, c = params[B], params[K_MT], params[C_MT]
    assert reference_acceleration(params, 0.3, 0.01) == -b * (k * 0.3 + c * 0.01)
    adaptive = state[A0:].copy()
    thrust = LAWS["mrac2"].command(30.0, 0.5, 0.0, 0.0, params, state, 2e-3, True)
    assert thrust == 0.0 and np.array_equal(state[A0:], adaptive)
    paper, paper_state = _arrays("mrac2", _case(), z0=0.5)
    assert paper[U_MIN] == -paper[U_MAX]
    assert LAWS["mrac2"].command(30.0, 0.5, 0.0, 0.0, paper, paper_state, 2e-3, True) == -paper[U_MAX]


def test_a_thrust_floor_outside_the_actuator_range_is_refused():
    """mrac.min_thrust must lie in [-max_force, max_force): the case check names the key and the range."""
    data = load_model(CASE, TowingCase).model_dump()
    data["mrac"]["thrust_band"] = None
    for bad in (200.0, -250.0):
        data["mrac"]["min_thrust"] = bad
        with pytest.raises(ValueError, match=r"mrac.min_thrust must lie in \[-thrust.max_force"):
            TowingCase.model_validate(data)
    data["mrac"]["min_thrust"] = -200.0
    assert TowingCase.model_validate(data).mrac.min_thrust == -200.0


def test_a_thrust_band_confines_the_command_and_is_checked():
    """mrac.min_thrust and mrac.max_thrust confine sat(u) to a band around the steady thrust (here 110-170 N about
    the free-debris balance (1 + m_C/m_D) k_MT z_d = 141.4 N): MRAC-1 and MRAC-2 commands from far below and far
    above their target land exactly on the band's edges; a ceiling above thrust.max_force or not above the floor is
    refused, naming the key."""
    band = _case(min_thrust=110.0, max_thrust=170.0)
    for kind in ("mrac1", "mrac2"):
        params, state = _arrays(kind, band, z0=0.5)
        assert (params[U_MIN], params[U_MAX]) == (110.0, 170.0)
        assert LAWS[kind].command(30.0, 0.5, 0.0, 0.0, params, state, 2e-3, True) == 110.0
        params, state = _arrays(kind, band, z0=-0.5)
        assert LAWS[kind].command(30.0, -0.5, 0.0, 0.0, params, state, 2e-3, True) == 170.0
    data = load_model(CASE, TowingCase).model_dump()
    data["mrac"]["thrust_band"] = None
    for low, high in ((None, 250.0), (110.0, 110.0), (None, -200.0)):
        data["mrac"]["min_thrust"], data["mrac"]["max_thrust"] = low, high
        with pytest.raises(ValueError, match=r"mrac.max_thrust must lie in \(mrac.min_thrust, thrust.max_force\]"):
            TowingCase.model_validate(data)


def test_a_thrust_band_of_ten_percent_is_about_the_steady_thrust():
    """mrac.thrust_band = 0.1 on the shipped case: sat(u) to [0.9, 1.1] x (1 + m_C/m_D) k_MT z_d
    = [0.9, 1.1] x (1 + 1600/9000) 3000 N/m 0.04 m = [127.2, 155.47] N (hand arithmetic), for both laws; with
    min_thrust or max_thrust as well the case is refused. The shipped case has no band (the paper's saturation)."""
    assert load_model(CASE, TowingCase).mrac.thrust_band is None
    case = _case(thrust_band=0.1)
    steady = (1.0 + 1600.0 / 9000.0) * 3000.0 * 0.04
    for kind in ("mrac1", "mrac2"):
        params, _ = _arrays(kind, case)
        assert params[U_MIN] == pytest.approx(0.9 * steady, rel=1e-12)
        assert params[U_MAX] == pytest.approx(1.1 * steady, rel=1e-12)
    data = case.model_dump()
    data["mrac"]["thrust_band"], data["mrac"]["min_thrust"] = 0.1, 100.0
    with pytest.raises(ValueError, match="mrac.thrust_band sets the actuator range itself"):
        TowingCase.model_validate(data)


def test_the_slack_hold_commands_the_steady_thrust_below_its_elongation():
    """mrac.slack_elongation = 4 mm: below it both laws command exactly the steady thrust
    (1 + m_C/m_D) k_MT z_d = 141.33 N (hand arithmetic) and leave their adaptive parameters unchanged; above it the
    command is the law's own (MRAC-2 at z = 0.03 m, z' = 0 with its ideal gains: K_P (z_cmd - z) = 1000 (0.1813 - 0.03)
    = 151.3 N); without the setting (the shipped case) the law acts at any elongation."""
    steady = (1.0 + 1600.0 / 9000.0) * 3000.0 * 0.04
    held = _case(slack_elongation=0.004)
    for kind in ("mrac1", "mrac2"):
        params, state = _arrays(kind, held, z0=0.001)
        adaptive = state[A0:].copy()
        assert LAWS[kind].command(30.0, 0.001, 0.0, 0.0, params, state, 2e-3, True) == pytest.approx(steady, rel=1e-12)
        assert np.array_equal(state[A0:], adaptive)
    params, state = _arrays("mrac2", held, z0=0.03)
    command_z = 0.04 * (1.0 + 1600.0 / 9000.0) * 3000.0 / 1000.0 + 0.04
    assert LAWS["mrac2"].command(30.0, 0.03, 0.0, 0.0, params, state, 2e-3, False) == pytest.approx(
        1000.0 * (command_z - 0.03), rel=1e-9)
    params, state = _arrays("mrac2", _case(), z0=0.001)
    assert LAWS["mrac2"].command(30.0, 0.001, 0.0, 0.0, params, state, 2e-3, False) == pytest.approx(
        1000.0 * (command_z - 0.001), rel=1e-9)


def test_the_slack_hold_lasts_its_breathing_periods_after_the_last_slack_sample():
    """mrac.slack_hold_periods = 1 at 20.44 deg/s: the hold lasts one breathing period, half a spin period,
    180 / 20.44 = 8.806 s (hand arithmetic), after the last sample below slack_elongation. A slack sample at t = 30 s,
    then taut samples (z = 0.03 m): the command is the steady thrust 141.33 N until 38.806 s and the law's own after
    (MRAC-2 with its ideal gains at z' = 0: K_P (z_cmd - z) = 151.3 N, as above), the adaptive parameters unchanged
    while held. Without slack_elongation, or on a debris that does not spin, the setting is refused naming the key."""
    steady = (1.0 + 1600.0 / 9000.0) * 3000.0 * 0.04
    command_z = 0.04 * (1.0 + 1600.0 / 9000.0) * 3000.0 / 1000.0 + 0.04
    case = _case(slack_elongation=0.001, slack_hold_periods=1.0)
    case = case.model_copy(update=dict(debris=case.debris.model_copy(update=dict(spin_rate_deg_s=20.44))))
    params, state = _arrays("mrac2", case, z0=0.03)
    law = LAWS["mrac2"].command
    assert law(30.0, 0.0005, 0.0, 0.0, params, state, 2e-3, True) == pytest.approx(steady, rel=1e-12)
    adaptive = state[A0:].copy()
    hold = 180.0 / 20.44
    assert law(30.0 + hold - 1e-3, 0.03, 0.0, 0.0, params, state.copy(), 2e-3, False) == pytest.approx(steady, rel=1e-12)
    law(30.0 + hold - 1e-3, 0.03, 0.0, 0.0, params, state, 2e-3, True)
    assert np.array_equal(state[A0:], adaptive)
    state[Z_LAST], state[RATE_LAST] = 0.03, 0.0      # the rate estimate at rest on z = 0.03 m
    assert law(30.0 + hold + 1e-3, 0.03, 0.0, 0.0, params, state, 2e-3, False) == pytest.approx(
        1000.0 * (command_z - 0.03), rel=1e-9)
    data = case.model_dump()
    data["mrac"]["slack_elongation"] = None
    with pytest.raises(ValueError, match="mrac.slack_hold_periods needs mrac.slack_elongation"):
        TowingCase.model_validate(data)
    data = case.model_dump()
    data["debris"]["spin_rate_deg_s"] = 0.0
    if data.get("full_net") is not None:
        data["full_net"]["switch_to_lower_order"] = False
    with pytest.raises(ValueError, match="mrac.slack_hold_periods"):
        TowingCase.model_validate(data)
