import numpy as np
import pytest

from multibody.quasi_steady import quasi_steady_time


def test_decaying_oscillation_switches_when_band_is_met():
    # Tension 200 N + 50 exp(-t/tau) cos(w t): the peak-to-peak over a window T starting at
    # t0 is at most about 2*50*exp(-t0/tau) (analytic envelope). With rel_tol = 1 % of 200 N
    # the band is 2 N, so the window must start after t0 = tau*ln(100/2) = 10*3.912 = 39.1 s;
    # the switch time is t0 + T = 49.1 s, give or take one oscillation half-period (pi/w).
    t = np.linspace(0.0, 120.0, 24001)
    tau, w, T = 10.0, 2.0, 10.0
    tension = 200.0 + 50.0 * np.exp(-t / tau) * np.cos(w * t)
    rel_speed = 0.3 * np.exp(-t / tau)  # m/s, settles at zero -> absolute floor 6 mm/s
    t_switch = quasi_steady_time(t, {"tension": tension, "rel_speed": rel_speed}, T, 0.01,
                                 abs_floor={"rel_speed": 0.006})
    assert t_switch is not None
    # rel_speed band: 0.3 exp(-t0/tau)(1-exp(-T/tau)) <= 0.006 -> t0 >= 10 ln(31.6) = 34.5 s,
    # so the tension governs.
    assert abs(t_switch - (T + tau * np.log(50.0))) <= np.pi / w + 1e-9


def test_never_settles_returns_none_and_nan_is_not_steady():
    t = np.linspace(0.0, 50.0, 5001)
    assert quasi_steady_time(t, {"x": 10.0 + np.sin(t)}, 5.0, 0.01) is None
    x = np.full_like(t, 5.0)
    x[-1] = np.nan
    # constant up to the end: steady from t = T on
    assert quasi_steady_time(t, {"x": x}, 5.0, 0.01) == pytest.approx(5.0)


def test_bad_input_is_refused():
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match="window"):
        quasi_steady_time(t, {"x": t}, 0.0, 0.01)
    with pytest.raises(ValueError, match="shape"):
        quasi_steady_time(t, {"x": t[:-1]}, 0.5, 0.01)
    with pytest.raises(ValueError, match="increasing"):
        quasi_steady_time(t[::-1], {"x": t}, 0.5, 0.01)
