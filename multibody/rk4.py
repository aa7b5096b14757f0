"""The classical fixed-step Runge-Kutta scheme (RK4), compiled, for any compiled state derivative.

One implementation for the small models whose right-hand side runs inside numba, where SciPy's
integrators cannot: the diagnosis' fast model (:mod:`riskassess.diagnosis.dynamics`, with the
effects' load laws) and the torque-free propagation inside the perception fit
(:mod:`perception.euler_poinsot`). Imports nothing of ours, so every package may use it.

The derivative is a numba function passed as an argument, ``rate(t, x, *args) -> dx`` (``args`` a
tuple, which may hold first-class functions such as an effect's law). Both functions here are
inlined into their caller at numba's IR level (``inline="always"``): the derivative is then a direct
call of a global function in the caller, which stays cacheable. (A dispatcher handed over as a
run-time value is a "dynamic global": numba refused to cache the caller, and every process
recompiled it.)
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def rk4_step(rate, t, x, h, args):
    """One classical RK4 step of dx/dt = rate(t, x, *args).

    Parameters
    ----------
    rate : numba function
        ``rate(t, x, *args)``: the time derivative of ``x`` (same shape, units of ``x`` per second).
    t : float
        Time at the step's start (s).
    x : (n,) float
        State at ``t``.
    h : float
        Step (s).
    args : tuple
        Further arguments of ``rate`` (constants over the step).

    Returns
    -------
    x : (n,) float
        State at ``t + h`` (a new array).
    """
    k1 = rate(t, x, *args)
    k2 = rate(t + 0.5 * h, x + 0.5 * h * k1, *args)
    k3 = rate(t + 0.5 * h, x + 0.5 * h * k2, *args)
    k4 = rate(t + h, x + h * k3, *args)
    return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


@njit(cache=True, inline="always")
def rk4_at_times(rate, args, x0, t0, times, max_step, quaternion_at):
    """States at ``times`` from ``x0`` at ``t0``, by RK4 steps no longer than ``max_step`` (equal steps
    between consecutive output times), a unit quaternion in the state renormalised after every step.

    Parameters
    ----------
    rate : numba function
        ``rate(t, x, *args)``, see :func:`rk4_step`.
    args : tuple
        Further arguments of ``rate``.
    x0 : (n,) float
        State at ``t0`` (not changed).
    t0 : float
        Time of ``x0`` (s).
    times : (k,) float
        Output times (s), non-decreasing, none before ``t0``; an output at ``t0`` is ``x0``.
    max_step : float
        Longest step (s); a span within 1e-9 steps of a whole number of them takes that number.
    quaternion_at : int
        Index of the first of four entries holding a unit quaternion, renormalised after every step
        (the RK4 step does not keep its norm); negative: none.

    Returns
    -------
    states : (k, n) float
        The state at each of ``times``.
    """
    out = np.empty((times.shape[0], x0.shape[0]))
    x = x0.copy()
    t = t0
    for i in range(times.shape[0]):
        span = times[i] - t
        steps = int(np.ceil(span / max_step - 1e-9)) if span > 0 else 0
        for _ in range(steps):
            h = span / steps
            x = rk4_step(rate, t, x, h, args)
            if quaternion_at >= 0:
                q = x[quaternion_at:quaternion_at + 4]
                q /= np.sqrt(q @ q)
            t += h
        t = times[i]
        out[i] = x
    return out
