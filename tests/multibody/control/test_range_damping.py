"""The range-rate damping both MRAC laws may add to their command (``mrac.range_damping``, multibody/control/mrac.py):
the range rate is the relative velocity projected on the line of centres, and the law's command changes by exactly
-c_R dr/dt (off by default: the paper's laws unchanged)."""
from pathlib import Path

import numpy as np
import pytest

from multibody.control.mrac import C_RANGE
from multibody.control.thrust import range_rate
from multibody.control.thrust_laws import LAWS
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase

CASE = Path(__file__).parents[3] / "cases" / "zenit2_towing.toml"


def _arrays(kind, case, z0=0.04):
    mt = case.main_tether
    return LAWS[kind].arrays(case, np.array([mt.stiffness, mt.damping, mt.natural_length]), z0, 0.0)


def test_the_range_rate_is_the_relative_velocity_along_the_line_of_centres():
    """d = (0, 0, 20) m: only the z component of the relative velocity changes the distance, so dr/dt = 0.05 m/s
    exactly (20 x 0.05 / 20 in floating point); a purely transverse velocity gives 0 exactly; the projection does
    not depend on the frame (the same vectors turned by 30 deg about x agree to round-off, 1e-15 m/s)."""
    assert range_rate(0.0, 0.0, 20.0, 0.3, -0.2, 0.05) == 0.05
    assert range_rate(0.0, 0.0, 20.0, 0.3, -0.2, 0.0) == 0.0
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    turn = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    d, v = turn @ [0.0, 0.0, 20.0], turn @ [0.3, -0.2, 0.05]
    assert range_rate(*d, *v) == pytest.approx(0.05, abs=1e-15)


@pytest.mark.parametrize("kind", ["mrac1", "mrac2"])
def test_the_range_damping_adds_exactly_minus_c_times_the_range_rate(kind):
    """At the desired elongation both laws command about the steady thrust (141 N, inside the +-200 N saturation);
    with c_R = 800 N s/m a range rate of +0.02 m/s (separating) lowers the command by 16 N and -0.02 m/s raises it
    by 16 N, to round-off (1e-9 N); with c_R = 0 (the schema's default, the paper's laws) the range rate changes nothing
    (bit-identical)."""
    case = load_model(CASE, TowingCase)
    damped = case.model_copy(update=dict(mrac=case.mrac.model_copy(update=dict(range_damping=800.0))))
    params, state = _arrays(kind, damped)
    assert params[C_RANGE] == 800.0
    base = LAWS[kind].command(30.0, 0.04, 0.0, 0.0, params, state.copy(), 2e-3, False)
    assert 0.0 < base < case.thrust.max_force - 20.0
    for rate in (0.02, -0.02):
        got = LAWS[kind].command(30.0, 0.04, 0.0, rate, params, state.copy(), 2e-3, False)
        assert got - base == pytest.approx(-800.0 * rate, abs=1e-9)
    paper = case.model_copy(update=dict(mrac=case.mrac.model_copy(update=dict(range_damping=0.0))))
    params0, state0 = _arrays(kind, paper)
    assert params0[C_RANGE] == 0.0
    assert (LAWS[kind].command(30.0, 0.04, 0.0, 0.3, params0, state0.copy(), 2e-3, False)
            == LAWS[kind].command(30.0, 0.04, 0.0, 0.0, params0, state0.copy(), 2e-3, False))


def test_a_negative_range_damping_is_refused():
    """A negative c_R would pump the chaser-debris motion: the schema refuses it, naming the key."""
    data = load_model(CASE, TowingCase).model_dump()
    data["mrac"]["range_damping"] = -1.0
    with pytest.raises(ValueError, match="range_damping"):
        TowingCase.model_validate(data)
