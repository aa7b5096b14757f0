"""A causal low-pass filter of the joints' loads, run at every simulation step.

Why: a penalty joint stands in for an ideal constraint. Its reaction is the ideal constraint's load plus the
ringing of its own spring modes (15-1500 Hz on envisat_small, docs/structures.md), which are numerical: they
move with the penalty stiffness and the step, and above the output's Nyquist frequency they alias into the
samples. The ideal joint's load is the penalty load's content below those modes. A low-pass filter run on the
load of every step (before the output's decimation, so nothing aliases), with its cut-off stated, well above
the physical content of the model and well below the penalty modes, gives that load: its peak converges in
penalty stiffness, step and output rate where the raw peak does not (tests/multibody/test_load_filter.py).

The filter is a Butterworth low-pass of even order n (2 or 4), |H(j omega)|^2 = 1 / (1 + (omega / omega_c)^(2 n)),
as a cascade of n / 2 second-order sections, each discretised by the bilinear transform with the cut-off
pre-warped (the gain at the cut-off is exactly 1/sqrt(2), as the analogue filter's), run as a transposed direct
form II biquad with its state per joint and load axis:

.. math::

    H(s) = \\prod_{k=1}^{n/2} \\frac{\\omega_c^2}{s^2 + \\omega_c s / Q_k + \\omega_c^2},\\quad
    Q_k = \\frac{-1}{2\\cos\\left(\\pi \\frac{2k + n - 1}{2n}\\right)},\\qquad
    s \\leftarrow \\frac{\\omega_c}{\\tan(\\omega_c h / 2)}\\,\\frac{1 - z^{-1}}{1 + z^{-1}}

(Butterworth poles on the circle of radius omega_c; Oppenheim & Schafer, Discrete-Time Signal Processing, 3rd ed.,
Sec. 7.2.2, eqs. (7.24)-(7.27), for the bilinear transform and its pre-warping). Second order (Q = 1/sqrt(2)): step
overshoot exp(-pi) = 4.3 %, low-frequency group delay sqrt(2) / omega_c (75 ms at 3 Hz); fourth order: overshoot
10.8 %, group delay 2.61 / omega_c (139 ms at 3 Hz); a filtered peak comes that much after the raw one. The fourth
order takes a mode 4x above the cut-off down by 4^4 = 256, the second by 16: a penalty mode whose ringing is 20x
the load below it (the ASAR mount's, docs/structures.md) needs the fourth.

Layout of a filter bank ((nj, 6, S, 8) float, one row per joint, load axis (force x, y, z and moment h1, h2, h3 of
the joint frame) and section): ``[b0, b1, b2, a1, a2, z1, z2, y]`` (coefficients, the two states, the section's last
output); the last section's output is the filtered load. A joint whose cut-off is 0 passes through (b0 = 1).
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
#: The orders a filter can have (even: a cascade of second-order sections).
ORDERS = (2, 4)


def section_quality_factors(order: int) -> np.ndarray:
    """The quality factors Q_k of the Butterworth's second-order sections (module doc): 1/sqrt(2) for order 2;
    1.3066 and 0.5412 for order 4.

    Parameters
    ----------
    order : int
        2 or 4.
    """
    if order not in ORDERS:
        raise ValueError(f"a load filter's order is one of {ORDERS}. Got {order!r} instead.")
    k = np.arange(1, order // 2 + 1)
    return -1.0 / (2.0 * np.cos(np.pi * (2 * k + order - 1) / (2 * order)))


def butterworth_sections(cutoff_hz: float, step: float, order: int = 2) -> np.ndarray:
    """The biquad coefficients ``[b0, b1, b2, a1, a2]`` of each second-order section of the Butterworth low-pass of
    ``order`` at ``cutoff_hz`` for samples ``step`` apart (bilinear transform, pre-warped at the cut-off; module doc).

    Parameters
    ----------
    cutoff_hz : float
        Cut-off (-3 dB) frequency (Hz); 0 gives pass-through sections.
    step : float
        Sample interval (s): the simulation step.
    order : int
        2 or 4.

    Returns
    -------
    (order / 2, 5) float
    """
    quality = section_quality_factors(order)
    if cutoff_hz == 0.0:
        return np.tile([1.0, 0.0, 0.0, 0.0, 0.0], (quality.size, 1))
    if not 0.0 < cutoff_hz <= NYQUIST_FRACTION * 0.5 / step:
        raise ValueError(f"a load filter's cut-off must be in (0, {NYQUIST_FRACTION * 0.5 / step:g}] Hz "
                         f"(1/10 of the step's Nyquist frequency) for step {step:g} s. Got {cutoff_hz!r} instead.")
    k = math.tan(math.pi * cutoff_hz * step)      # tan(omega_c h / 2): the pre-warped cut-off
    out = np.empty((quality.size, 5))
    for s, q in enumerate(quality):
        norm = 1.0 / (1.0 + k / q + k * k)
        b0 = k * k * norm
        out[s] = [b0, 2.0 * b0, b0, 2.0 * (k * k - 1.0) * norm, (1.0 - k / q + k * k) * norm]
    return out


def filter_bank(cutoffs_hz, step: float, orders) -> np.ndarray:
    """A zeroed filter bank, one Butterworth per joint on each of its six load axes.

    Parameters
    ----------
    cutoffs_hz : (nj,) float
        Each joint's cut-off (Hz); 0: its loads pass unfiltered.
    step : float
        Simulation step (s).
    orders : (nj,) int
        Each joint's order, 2 or 4 (a joint of lower order than the highest gets pass-through sections after its own).

    Returns
    -------
    (nj, 6, S, 8) float
        Rows ``[b0, b1, b2, a1, a2, z1, z2, y]`` (module doc); S half the highest order.
    """
    cutoffs_hz = np.asarray(cutoffs_hz, float).reshape(-1)
    orders = np.broadcast_to(np.asarray(orders, int), cutoffs_hz.shape)
    bank = np.zeros((cutoffs_hz.size, N_AXES, int(orders.max(initial=2)) // 2, N_COLUMNS))
    bank[:, :, :, B0] = 1.0
    for j, (cutoff, order) in enumerate(zip(cutoffs_hz, orders)):
        bank[j, :, :order // 2, :A2 + 1] = butterworth_sections(float(cutoff), step, int(order))
    return bank


@njit(cache=True)
def rest_at(bank, j, axis, value):
    """Set joint ``j``'s filter on ``axis`` at rest under a constant input ``value`` (output ``value``): each section
    (unit gain at 0 Hz) in the steady state of the transposed direct form II, ``z2 = (b2 - a2) x``,
    ``z1 = (b1 - a1) x + z2``.

    Parameters
    ----------
    bank : (nj, 6, S, 8) float
    j, axis : int
    value : float
        The constant input (N or N m).
    """
    for s in range(bank.shape[2]):
        row = bank[j, axis, s]
        row[Z2] = (row[B2] - row[A2]) * value
        row[Z1] = (row[B1] - row[A1]) * value + row[Z2]
        row[OUTPUT] = value


@njit(cache=True)
def advance(bank, j, axis, value) -> float:
    """One step of joint ``j``'s filter on ``axis`` with input ``value``: each section in turn (transposed direct
    form II), the next taking the last one's output; returns the filtered value.

    .. math:: y = b_0 x + z_1,\\quad z_1 \\leftarrow b_1 x - a_1 y + z_2,\\quad z_2 \\leftarrow b_2 x - a_2 y
    """
    y = value
    for s in range(bank.shape[2]):
        row = bank[j, axis, s]
        x = y
        y = row[B0] * x + row[Z1]
        row[Z1] = row[B1] * x - row[A1] * y + row[Z2]
        row[Z2] = row[B2] * x - row[A2] * y
        row[OUTPUT] = y
    return y


@njit(cache=True)
def filter_signal(sections, values):
    """A whole signal through one filter, starting at rest under its first value (tests and offline readings).

    Parameters
    ----------
    sections : (S, 5) float
        :func:`butterworth_sections`.
    values : (k,) float
        Samples one step apart.

    Returns
    -------
    (k,) float
    """
    bank = np.zeros((1, 1, sections.shape[0], N_COLUMNS))
    bank[0, 0, :, :5] = sections
    out = np.empty_like(values)
    if values.shape[0] == 0:
        return out
    rest_at(bank, 0, 0, values[0])
    for k in range(values.shape[0]):
        out[k] = advance(bank, 0, 0, values[k])
    return out
