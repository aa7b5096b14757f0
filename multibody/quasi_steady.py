"""Quasi-steady-state detection for the switch from the full-net tow to the lower-order model.

Boonrath et al. propose handing a full-net tow over to the tethered lower-order model once
the netted debris moves as one body with the chaser.  The criterion used here: every
monitored signal (e.g. tether tension [N], net-debris relative speed [m/s]) varies by at most
``rel_tol`` of its window mean magnitude (plus ``abs_floor`` in the signal's units, so a signal
that settles at zero is not held to a relative band around zero) over a trailing window of
duration ``window`` [s].  The switch time is the end of the first such window.
"""
from __future__ import annotations

import numpy as np


def quasi_steady_time(t: np.ndarray, signals: dict[str, np.ndarray], window: float,
                      rel_tol: float, abs_floor: dict[str, float] | None = None) -> float | None:
    """First time at which all signals have been quasi-steady over the trailing window.

    Parameters
    ----------
    t : (n,) array, s
        Strictly increasing sample times.
    signals : dict of name -> (n,) array
        Monitored signals sampled at ``t`` (any units; each is judged on its own).
    window : float, s
        Trailing window length T over which the variation is measured (> 0).
    rel_tol : float
        Allowed peak-to-peak variation as a fraction of the window's mean |signal| (>= 0).
    abs_floor : dict of name -> float, optional
        Absolute allowance added to the band, in the signal's units (default 0).

    Returns
    -------
    float or None
        The switch time [s] (end of the first window meeting the criterion), or None if the
        signals never settle (the caller must then stay on the full-net model).
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0.0):
        raise ValueError("quasi_steady_time: t must be a strictly increasing 1-D array")
    if window <= 0.0 or rel_tol < 0.0:
        raise ValueError(f"quasi_steady_time: window must be > 0 and rel_tol >= 0 "
                         f"(got window={window}, rel_tol={rel_tol})")
    floors = abs_floor or {}
    arrays = {k: np.asarray(v, dtype=float) for k, v in signals.items()}
    for name, x in arrays.items():
        if x.shape != t.shape:
            raise ValueError(f"quasi_steady_time: signal {name!r} has shape {x.shape}, "
                             f"expected {t.shape}")
    for i_end in range(t.size):
        i_start = int(np.searchsorted(t, t[i_end] - window, side="left"))
        if t[i_end] - t[0] < window:
            continue
        if all(window_is_steady(x[i_start:i_end + 1], rel_tol, floors.get(name, 0.0))
               for name, x in arrays.items()):
            return float(t[i_end])
    return None


def window_is_steady(x: np.ndarray, rel_tol: float, floor: float) -> bool:
    """Peak-to-peak variation within rel_tol of the mean magnitude (plus an absolute floor).

    Parameters
    ----------
    x : (k,) float
        One signal's samples over the window (any unit).
    rel_tol : float
        Allowed peak-to-peak variation as a fraction of the window's mean |x| (-).
    floor : float
        Absolute allowance, in x's unit.

    Returns
    -------
    bool
        False for a window with a non-finite sample.
    """
    if not np.all(np.isfinite(x)):
        return False  # a diverged signal is never steady
    return float(np.ptp(x)) <= rel_tol * float(np.mean(np.abs(x))) + floor
