"""The MRAC laws' once-per-turn thrust budget (multibody/control/mrac.py, ``mrac.tow_point_offset``): the thrust the
CoM offset's once-per-turn line asks for, m_C omega^2 delta, and the desired elongation governed so that the steady
thrust leaves it inside the actuator's upper bound; the laws' parameters and the bench target follow it."""
import math
from pathlib import Path

import numpy as np
import pytest

from multibody.control.mrac import F_STEADY, K_MT, K_P, Z_D, abstracted_tether
from multibody.control.thrust_budget import governed_elongation, once_per_turn_thrust
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing import case_thrust_law
from riskassess.products.towing_figures import reference_elongation

CASE = Path(__file__).parents[3] / "cases" / "zenit2_towing.toml"
DELTA = 0.217      # m: Zenit-2 CoM from the middle of its cylinder (Table 1's sub-tether points z = -5.717, +5.283 m)


def _case(spin_rate_deg_s, **mrac):
    case = load_model(CASE, TowingCase)
    return case.model_copy(update=dict(
        thrust=case.thrust.model_copy(update=dict(kind="mrac2")),
        debris=case.debris.model_copy(update=dict(spin_rate_deg_s=spin_rate_deg_s)),
        mrac=case.mrac.model_copy(update=dict(tow_point_offset=DELTA) | mrac)))


def _k_abstracted(case):
    mt = case.main_tether
    return abstracted_tether(case, [mt.stiffness, mt.damping])[0]


def test_the_once_per_turn_thrust_is_m_c_omega_squared_delta():
    """1600 kg x (29.01 deg/s = 0.50632 rad/s)^2 x 0.217 m = 89.01 N (docs/towing.md: 89 N at 29.01 deg/s, 44 N at
    20.44, 12 N at 10.71); exact arithmetic at 29.01 deg/s (1e-12), the rounded 12.13 N at 10.71 (1e-3)."""
    for rate, expected in ((29.01, 1600.0 * math.radians(29.01) ** 2 * DELTA), (10.71, 12.13)):
        assert once_per_turn_thrust(_case(rate)) == pytest.approx(expected, rel=1e-12 if rate == 29.01 else 1e-3)
    assert once_per_turn_thrust(_case(29.01, tow_point_offset=None)) == 0.0


def test_the_budget_lowers_the_elongation_only_where_the_steady_thrust_leaves_no_room():
    """The steady thrust k z_d = 1.1778 x 3000 N/m x 0.04 m = 141.3 N leaves 58.7 N below 200 N: at 20.44 deg/s the line
    asks 44.4 N (room: z_d kept, 0.04 m exactly), at 29.01 deg/s 89.0 N, so z_d = (200 - 89.0) / 3533.3 = 0.03141 m;
    the laws' steady thrust is then 200 N - 89.0 N exactly (round-off)."""
    for rate in (10.71, 20.44):
        case = _case(rate)
        assert governed_elongation(case, _k_abstracted(case)) == 0.04
    case = _case(29.01)
    k = _k_abstracted(case)
    z = governed_elongation(case, k)
    assert z == pytest.approx((200.0 - once_per_turn_thrust(case)) / k, rel=1e-14)
    assert z == pytest.approx(0.03141, abs=1e-5)
    mt = case.main_tether
    _, params, _ = case_thrust_law(case, np.array([mt.stiffness, mt.damping, mt.natural_length]), 0.03, 0.0, 29.01)
    assert params[F_STEADY] + once_per_turn_thrust(case) == pytest.approx(200.0, rel=1e-14)
    assert params[Z_D] == pytest.approx(z * (params[K_MT] + params[K_P]) / params[K_P], rel=1e-14)  # settle command
    assert reference_elongation(case) == pytest.approx(z, rel=1e-12)        # the reference settles there (bench target)


def test_without_the_key_the_laws_are_unchanged():
    """No mrac.tow_point_offset: the desired elongation at every rate, the laws' parameters identical bit for bit."""
    case = _case(29.01, tow_point_offset=None)
    assert governed_elongation(case, _k_abstracted(case)) == 0.04
    mt = case.main_tether
    tether = np.array([mt.stiffness, mt.damping, mt.natural_length])
    _, off, _ = case_thrust_law(case, tether, 0.03, 0.0, 20.44)
    _, on, _ = case_thrust_law(_case(29.01), tether, 0.03, 0.0, 20.44)       # the budget holds at 20.44 deg/s
    assert np.array_equal(off, on)


def test_a_budget_with_no_room_is_refused_naming_the_key():
    """delta = 1 m at 29.01 deg/s asks 410 N of a 200 N chaser: no elongation leaves room."""
    case = _case(29.01, tow_point_offset=1.0)
    with pytest.raises(ValueError, match="mrac.tow_point_offset"):
        governed_elongation(case, _k_abstracted(case))
