"""Open-loop thrust ramp against the chaser's orbital velocity (Boonrath, Singh & Botta 2024,
equation after eq. 2); ``params = [t_on, t_slope, f_max]`` (s, s, N), no state."""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.control.thrust import THRUST_SIGNATURE

NAME = "ramp"
ALONG_BODY_Z = False
CASE_SECTIONS = ()


@njit(cache=True)
def ramp_thrust(t, t_on, t_slope, f_max):
    """Open-loop thrust magnitude (N): zero until ``t_on``, linear to ``f_max`` over ``t_slope``,
    then constant.

    Parameters
    ----------
    t : float
        Time (s).
    t_on, t_slope : float
        Thrust-on time and ramp duration (s).
    f_max : float
        Final thrust (N).
    """
    if t <= t_on:
        return 0.0
    if t < t_on + t_slope:
        return f_max * (t - t_on) / t_slope
    return f_max


@njit(THRUST_SIGNATURE, cache=True)
def command(t, z, z_rate, range_rate, params, state, step, advance):
    """:func:`ramp_thrust` behind the common interface (:mod:`multibody.control.thrust`).

    Parameters
    ----------
    t : float
        Time (s).
    params : (3,) float
        t_on (s), t_slope (s), f_max (N).
    z, z_rate, range_rate, state, step, advance
        Not used (open loop, no state).
    """
    return ramp_thrust(t, params[0], params[1], params[2])


def arrays(case, tether, z0, z_rate0) -> tuple[np.ndarray, np.ndarray]:
    """``params`` from the case's ``[thrust]`` table; the state is one unused slot.

    Parameters
    ----------
    case
        The towing case (:mod:`multibody.control.thrust_laws`); read: ``thrust``.
    tether, z0, z_rate0
        Not used.
    """
    th = case.thrust
    return np.array([th.t_on, th.t_slope, th.max_force]), np.zeros(1)
