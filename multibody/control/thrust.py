"""Thrust laws of the towing chaser: one small interface for the open-loop ramp and the
main-tether elongation controllers.

Every law is a compiled function of the same signature, called once per integration step
(a digital controller with zero-order hold over the step):

``command(t, z, z_rate, params, state, step, advance) -> F_t``

* ``t`` time (s); ``z`` main-tether elongation :math:`l_{MT} - l_{MT,0}` (m) and ``z_rate`` its
  rate (m/s), measured at the chaser;
* ``params`` (float array) the law's constants, ``state`` (float array) its internal states
  (reference model, adaptive parameters), updated in place over ``step`` (s) when ``advance``;
* returns the thrust magnitude (N) along the chaser's thrust direction.

:data:`KINDS` maps a case's ``thrust.kind`` to the integer the compiled towing kernel
dispatches on (:func:`thrust_command`).
"""
from __future__ import annotations

from numba import njit

from multibody.control.mrac import mrac1_command, mrac2_command

#: Thrust law of a case -> integer code of the compiled dispatch.
KINDS = {"ramp": 0, "mrac1": 1, "mrac2": 2}


@njit(cache=True)
def ramp_thrust(t, t_on, t_slope, f_max):
    """Open-loop thrust magnitude (N), Boonrath, Singh & Botta 2024, equation after eq. (2):
    zero until ``t_on``, linear to ``f_max`` over ``t_slope``, then constant (s, s, N)."""
    if t <= t_on:
        return 0.0
    if t < t_on + t_slope:
        return f_max * (t - t_on) / t_slope
    return f_max


@njit(cache=True)
def ramp_command(t, z, z_rate, params, state, step, advance):
    """:func:`ramp_thrust` behind the common interface; ``params = [t_on, t_slope, f_max]``."""
    return ramp_thrust(t, params[0], params[1], params[2])


@njit(cache=True)
def thrust_command(kind, t, z, z_rate, params, state, step, advance):
    """Dispatch on ``kind`` (:data:`KINDS`) to the thrust law's ``command``."""
    if kind == 1:
        return mrac1_command(t, z, z_rate, params, state, step, advance)
    if kind == 2:
        return mrac2_command(t, z, z_rate, params, state, step, advance)
    return ramp_command(t, z, z_rate, params, state, step, advance)
