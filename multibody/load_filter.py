"""A causal low-pass filter of the joints' loads, run at every simulation step.

Why: a penalty joint stands in for an ideal constraint. Its reaction is the ideal constraint's load plus the
ringing of its own spring modes (15-1500 Hz on envisat_small, docs/structures.md), which are numerical: they
move with the penalty stiffness and the step, and above the output's Nyquist frequency they alias into the
samples. The ideal joint's load is the penalty load's content below those modes. A low-pass filter run on the
load of every step (before the output's decimation, so nothing aliases), with its cut-off stated, well above
the physical content of the model and well below the penalty modes, gives that load: its peak converges in
penalty stiffness, step and output rate where the raw peak does not (tests/multibody/test_load_filter.py).

The filter is a second-order Butterworth low-pass, discretised by the bilinear transform with the cut-off
pre-warped (its gain at the cut-off is exactly 1/sqrt(2), as the analogue filter's), run as a transposed
direct form II biquad with its state per joint and load axis:

.. math::

    H(s) = \\frac{\\omega_c^2}{s^2 + \\sqrt{2}\\,\\omega_c s + \\omega_c^2},\\qquad
    s \\leftarrow \\frac{\\omega_c}{\\tan(\\omega_c h / 2)}\\,\\frac{1 - z^{-1}}{1 + z^{-1}}

(Oppenheim & Schafer, Discrete-Time Signal Processing, 3rd ed., Sec. 7.2.2, eqs. (7.24)-(7.27) for the
bilinear transform and its pre-warping). Its step response overshoots by exp(-pi) = 4.3 %, its group delay at
low frequency is sqrt(2) / omega_c (45 ms at 5 Hz): a filtered peak comes that much after the raw one.

Layout of a filter bank ((nj, 6, 8) float, one row per joint and load axis, axes force x, y, z and moment
h1, h2, h3 of the joint frame): ``[b0, b1, b2, a1, a2, z1, z2, y]`` (coefficients, the two states, the last
output). A row whose cut-off is 0 is a pass-through (b0 = 1).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Columns of a filter bank row.
B0, B1, B2, A1, A2, Z1, Z2, OUTPUT = range(8)
N_COLUMNS = 8
#: Load axes of a joint: force x, y, z (N) and moment h1, h2, h3 (N m), joint frame.
N_AXES = 6
#: A cut-off must lie below this fraction of the step's Nyquist frequency 1 / (2 h): the bilinear transform
#: squeezes the analogue response into [0, 1 / (2 h)], and at 1/10 of it the warping tan(x) / x is below 3.4 %.
NYQUIST_FRACTION = 0.1


def butterworth2_coefficients(cutoff_hz: float, step: float) -> np.ndarray:
    """The biquad coefficients ``[b0, b1, b2, a1, a2]`` of the second-order Butterworth low-pass at ``cutoff_hz``
    for samples ``step`` apart (bilinear transform, pre-warped at the cut-off; module doc).

    Parameters
    ----------
    cutoff_hz : float
        Cut-off (-3 dB) frequency (Hz); 0 gives a pass-through.
    step : float
        Sample interval (s): the simulation step.

    Returns
    -------
    (5,) float
    """
    if cutoff_hz == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0, 0.0])
    if not 0.0 < cutoff_hz <= NYQUIST_FRACTION * 0.5 / step:
        raise ValueError(f"a load filter's cut-off must be in (0, {NYQUIST_FRACTION * 0.5 / step:g}] Hz "
                         f"(1/10 of the step's Nyquist frequency) for step {step:g} s. Got {cutoff_hz!r} instead.")
    k = math.tan(math.pi * cutoff_hz * step)      # tan(omega_c h / 2): the pre-warped cut-off
    norm = 1.0 / (1.0 + math.sqrt(2.0) * k + k * k)
    b0 = k * k * norm
    return np.array([b0, 2.0 * b0, b0, 2.0 * (k * k - 1.0) * norm, (1.0 - math.sqrt(2.0) * k + k * k) * norm])


def filter_bank(cutoffs_hz, step: float) -> np.ndarray:
    """A zeroed filter bank, one second-order Butterworth per joint on each of its six load axes.

    Parameters
    ----------
    cutoffs_hz : (nj,) float
        Each joint's cut-off (Hz); 0: its loads pass unfiltered.
    step : float
        Simulation step (s).

    Returns
    -------
    (nj, 6, 8) float
        Rows ``[b0, b1, b2, a1, a2, z1, z2, y]`` (module doc).
    """
    cutoffs_hz = np.asarray(cutoffs_hz, float).reshape(-1)
    bank = np.zeros((cutoffs_hz.size, N_AXES, N_COLUMNS))
    for j, cutoff in enumerate(cutoffs_hz):
        bank[j, :, :A2 + 1] = butterworth2_coefficients(float(cutoff), step)
    return bank


@njit(cache=True)
def rest_at(bank, j, axis, value):
    """Set row ``(j, axis)``'s state to the filter at rest under a constant input ``value`` (output ``value``):
    the steady state of the transposed direct form II, ``z2 = (b2 - a2) x``, ``z1 = (b1 - a1) x + z2``.

    Parameters
    ----------
    bank : (nj, 6, 8) float
    j, axis : int
    value : float
        The constant input (N or N m).
    """
    row = bank[j, axis]
    row[Z2] = (row[B2] - row[A2]) * value
    row[Z1] = (row[B1] - row[A1]) * value + row[Z2]
    row[OUTPUT] = value


@njit(cache=True)
def advance(bank, j, axis, value) -> float:
    """One step of row ``(j, axis)`` (transposed direct form II) with input ``value``; returns the output.

    .. math:: y = b_0 x + z_1,\\quad z_1 \\leftarrow b_1 x - a_1 y + z_2,\\quad z_2 \\leftarrow b_2 x - a_2 y
    """
    row = bank[j, axis]
    y = row[B0] * value + row[Z1]
    row[Z1] = row[B1] * value - row[A1] * y + row[Z2]
    row[Z2] = row[B2] * value - row[A2] * y
    row[OUTPUT] = y
    return y


@njit(cache=True)
def filter_signal(coefficients, values):
    """A whole signal through one filter, starting at rest under its first value (tests and offline readings).

    Parameters
    ----------
    coefficients : (5,) float
        :func:`butterworth2_coefficients`.
    values : (k,) float
        Samples one step apart.

    Returns
    -------
    (k,) float
    """
    bank = np.zeros((1, 1, N_COLUMNS))
    bank[0, 0, :5] = coefficients
    out = np.empty_like(values)
    if values.shape[0] == 0:
        return out
    rest_at(bank, 0, 0, values[0])
    for k in range(values.shape[0]):
        out[k] = advance(bank, 0, 0, values[k])
    return out
