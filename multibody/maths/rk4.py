"""The classical fixed-step Runge-Kutta scheme (RK4), compiled, for any compiled state derivative.

One implementation for the small models whose right-hand side runs inside numba, where SciPy's
integrators cannot: the diagnosis' fast model (:mod:`riskassess.diagnosis.plants.dynamics`, with the
effects' load laws) and the torque-free propagation inside the perception fit
(:mod:`perception.euler_poinsot`). Imports nothing of ours, so every package may use it.

A model asks once, at import, for its integrator: ``rk4_integrator(rate, quaternion_at)`` compiles the
scheme below (:func:`_rk4_step`, :func:`_rk4_at_times`) with the model's derivative ``rate(t, x, *args)``
bound as a global name of the compiled code, so the derivative is a direct call, as in a loop written
for that model. Why not hand the derivative over as an argument: a compiled function passed as a
run-time value is a "dynamic global" (numba will not cache the caller, and every process
recompiled it), and inlining the scheme into the caller at numba's IR level (``inline="always"``, the
way round that) cost the diagnosis' fast model 10-15 % of its time (docs/architecture.md, "Compiled
kernels"). The bound functions are cached like any other kernel, under a name of their own per
derivative.
"""
from __future__ import annotations

import types

import numpy as np
from numba import njit

#: (name of the derivative, quaternion index) -> (derivative, its compiled integrator).
_INTEGRATORS: dict = {}


def _rk4_step(t, x, h, args):
    """One classical RK4 step of dx/dt = RATE(t, x, *args) (template: ``RATE`` is bound by
    :func:`rk4_integrator`).

    Parameters
    ----------
    t : float
        Time at the step's start (s).
    x : (n,) float
        State at ``t``.
    h : float
        Step (s).
    args : tuple
        Further arguments of the derivative (constants over the step).

    Returns
    -------
    x : (n,) float
        State at ``t + h`` (a new array).
    """
    k1 = RATE(t, x, *args)  # noqa: F821 (bound by rk4_integrator)
    k2 = RATE(t + 0.5 * h, x + 0.5 * h * k1, *args)  # noqa: F821
    k3 = RATE(t + 0.5 * h, x + 0.5 * h * k2, *args)  # noqa: F821
    k4 = RATE(t + h, x + h * k3, *args)  # noqa: F821
    return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def _rk4_at_times(args, x0, t0, times, max_step):
    """States at ``times`` from ``x0`` at ``t0`` by steps of ``STEP`` (template: ``STEP`` and
    ``QUATERNION_AT`` are bound by :func:`rk4_integrator`, which documents the arguments)."""
    out = np.empty((times.shape[0], x0.shape[0]))
    x = x0.copy()
    t = t0
    for i in range(times.shape[0]):
        span = times[i] - t
        steps = int(np.ceil(span / max_step - 1e-9)) if span > 0 else 0
        for _ in range(steps):
            h = span / steps
            x = STEP(t, x, h, args)  # noqa: F821 (bound by rk4_integrator)
            if QUATERNION_AT >= 0:  # noqa: F821
                q = x[QUATERNION_AT:QUATERNION_AT + 4]  # noqa: F821
                q /= np.sqrt(q @ q)
            t += h
        t = times[i]
        out[i] = x
    return out


def _bound(template, name: str, cache: bool, **names):
    """``template`` compiled with ``names`` as its globals, cached under ``template.name``."""
    function = types.FunctionType(template.__code__, dict(template.__globals__, **names), template.__name__)
    function.__qualname__ = f"{template.__name__}.{name}"
    return njit(cache=cache)(function)


def rk4_integrator(rate, quaternion_at: int = -1):
    """The compiled RK4 integrator of one model, made once per derivative (at the import of the
    model's module): ``run(args, x0, t0, times, max_step) -> states``.

    ``run`` gives the states at ``times`` from ``x0`` at ``t0``, by RK4 steps no longer than
    ``max_step`` (equal steps between consecutive output times: a span within 1e-9 steps of a whole
    number of them takes that number), a unit quaternion in the state renormalised after every step
    (the RK4 step does not keep its norm). ``args`` is a tuple of the derivative's further arguments
    (constant over the run; it may hold first-class functions, such as an effect's law); ``x0`` (n,)
    float is not changed; ``times`` (k,) float, non-decreasing, none before ``t0`` (an output at ``t0``
    is ``x0``); returns (k, n) float. ``run`` is an ordinary compiled function: call it from compiled
    code or from Python.

    Parameters
    ----------
    rate : numba dispatcher
        ``rate(t, x, *args)``: the time derivative of ``x`` (same shape, units of ``x`` per second),
        an ``@njit`` function defined at a module's top level.
    quaternion_at : int
        Index of the first of four entries of the state holding a unit quaternion; negative: none.

    Returns
    -------
    run : numba dispatcher
        ``run(args, x0, t0, times, max_step) -> (k, n) float``.
    """
    name = f"{rate.py_func.__module__}.{rate.py_func.__qualname__}.q{quaternion_at}".replace("-", "m")
    known = _INTEGRATORS.get(name)
    if known is not None and known[0] is rate:
        return known[1]
    # the cache is keyed by the name; a second derivative under one name (a module imported twice)
    # compiles its own, uncached
    cache = known is None
    step = _bound(_rk4_step, name, cache, RATE=rate)
    run = _bound(_rk4_at_times, name, cache, STEP=step, QUATERNION_AT=quaternion_at)
    _INTEGRATORS[name] = (rate, run)
    return run


__all__ = ["rk4_integrator"]
