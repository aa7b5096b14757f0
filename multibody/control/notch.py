"""Second-order digital notch filters of the MRAC laws (:mod:`multibody.control.mrac`) and where their centres sit.

* the filter (:func:`notch_coefficients`, :func:`notch_output`, :func:`shift_notch`): zeros on the unit circle at
  the notch frequency, poles inside it at the same angle, unit gain at zero frequency; its memory is four slots of
  the law's state (x_{k-1}, x_{k-2}, y_{k-1}, y_{k-2}).
* the centres: the breathing notch at twice the spin rate (:func:`notch_frequency`, ``mrac.breathing_notch``) and
  the range-rate notch at the spin rate (:func:`range_notch_frequency`, ``mrac.range_notch``); the MRAC module doc
  says why each is there and what it measured.

The law-side wrappers that bind the filter to the law's parameter and state layout
(:func:`multibody.control.mrac.breathing_notch`, :func:`~multibody.control.mrac.store_notch`,
:func:`~multibody.control.mrac.range_rate_seen`) stay with that layout in :mod:`multibody.control.mrac`.
"""
from __future__ import annotations

import math

from numba import njit


def notch_frequency(case) -> float:
    """Centre of the breathing notch (rad/s): ``mrac.notch_frequency`` if given, else twice the tow's spin rate
    (``debris.spin_rate_deg_s``, which the model builders set to the rate the run is made at); 0 with
    ``mrac.breathing_notch`` off (the laws see the measured elongation).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        Read: ``mrac.breathing_notch``, ``mrac.notch_frequency``, ``debris.spin_rate_deg_s``.

    Raises
    ------
    ValueError
        The notch is on, no frequency is stated and the debris does not spin.
    """
    m = case.mrac
    if not m.breathing_notch:
        return 0.0
    if m.notch_frequency is not None:
        return float(m.notch_frequency)
    if case.debris.spin_rate_deg_s <= 0.0:
        raise ValueError("mrac.breathing_notch: the debris does not spin (debris.spin_rate_deg_s = 0), so there is no "
                         "breathing at twice the spin rate; give mrac.notch_frequency (rad/s) or set "
                         "mrac.breathing_notch = false")
    return 2.0 * math.radians(case.debris.spin_rate_deg_s)


def range_notch_frequency(case) -> float:
    """Centre of the range-rate notch (rad/s): the tow's spin rate (``debris.spin_rate_deg_s``, which the model builders
    set to the rate the run is made at: the GNC's estimate from perception), the once-per-turn line the stage's CoM
    offset drives; 0 with ``mrac.range_notch`` off (the range damping sees the measured range rate).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        Read: ``mrac.range_notch``, ``debris.spin_rate_deg_s``.

    Raises
    ------
    ValueError
        The notch is on and the debris does not spin.
    """
    if not case.mrac.range_notch:
        return 0.0
    if case.debris.spin_rate_deg_s <= 0.0:
        raise ValueError("mrac.range_notch: the debris does not spin (debris.spin_rate_deg_s = 0), so there is no "
                         "once-per-turn line to leave out; set mrac.range_notch = false")
    return math.radians(case.debris.spin_rate_deg_s)


@njit(cache=True)
def notch_coefficients(omega, sigma, step):
    """Second-order digital notch at ``omega`` (rad/s) for the sampling step ``step`` (s), by pole-zero placement:
    zeros on the unit circle at :math:`e^{\\pm j\\omega h}` (a sampled sinusoid of that frequency is removed
    exactly in steady state), poles at :math:`r e^{\\pm j\\omega h}` with :math:`r = e^{-\\sigma h}` (the -3 dB
    width is about :math:`2\\sigma`, and the filter forgets its past with :math:`e^{-\\sigma t}`), gain g that
    makes the zero-frequency gain exactly 1:

    .. math:: H(z) = g \\frac{1 - 2\\cos\\theta\\,z^{-1} + z^{-2}}{1 - 2r\\cos\\theta\\,z^{-1} + r^2 z^{-2}},
              \\quad g = \\frac{(1 - r)^2 + 4r\\sin^2(\\theta/2)}{4\\sin^2(\\theta/2)},\\quad \\theta = \\omega h

    (both sums written without the cancellation of 1 - cos theta at small theta h).

    Parameters
    ----------
    omega : float
        Notch frequency (rad/s), 0 < omega h < pi.
    sigma : float
        Pole decay rate (1/s): omega / (2 Q).
    step : float
        Sampling step h (s).

    Returns
    -------
    g, b1, a1, a2 : float
        y_k = g (x_k + b1 x_{k-1} + x_{k-2}) - a1 y_{k-1} - a2 y_{k-2}.
    """
    theta = omega * step
    r = math.exp(-sigma * step)
    half = math.sin(0.5 * theta) ** 2
    g = ((1.0 - r) ** 2 + 4.0 * r * half) / (4.0 * half)
    return g, -2.0 * math.cos(theta), -2.0 * r * math.cos(theta), r * r


@njit(cache=True)
def notch_output(omega, sigma, state, first, x, step):
    """One sample of the notch at ``omega`` (rad/s) with pole decay rate ``sigma`` (1/s) (:func:`notch_coefficients`)
    for the input ``x``: its last two inputs and outputs are ``state[first:first + 4]`` (x_{k-1}, x_{k-2}, y_{k-1},
    y_{k-2}); :func:`shift_notch` writes this sample's.

    Parameters
    ----------
    omega, sigma : float
        Notch frequency (rad/s) and pole decay rate (1/s).
    state : (j,) float
        The law's state (the notch's memory read).
    first : int
        Index of x_{k-1} in ``state``.
    x : float
        This sample's input (any unit; the output has the same).
    step : float
        Sampling step (s).
    """
    g, b1, a1, a2 = notch_coefficients(omega, sigma, step)
    return g * (x + b1 * state[first] + state[first + 1]) - a1 * state[first + 2] - a2 * state[first + 3]


@njit(cache=True)
def shift_notch(state, first, x, y):
    """Shift a notch's memory ``state[first:first + 4]`` by one sample: input ``x`` and output ``y`` become the last.

    Parameters
    ----------
    state : (j,) float
        The law's state, written in place.
    first : int
        Index of x_{k-1} in ``state``.
    x, y : float
        This sample's input and output.
    """
    state[first + 1], state[first] = state[first], x
    state[first + 3], state[first + 2] = state[first + 2], y
