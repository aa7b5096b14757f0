"""The load a joint carries when the structure behind it has a first mode: the recorded reaction of a
stiff joint passed through that mode.

The run's joints are stiff penalty springs (modes at 0.5 / step rad/s, ~800 Hz at 1e-4 s): their
reaction is the rigid-body (quasi-static) load plus ringing of a numerical mode. A real appendage root
carries the load its structural modes let through. For one mode of circular frequency omega and damping
ratio zeta, with the child body on the joint's spring and the rigid reaction ``R`` as the load that
spring would carry if it were rigid, the spring's load ``L`` obeys

    L'' + 2 zeta omega L' + omega^2 L = omega^2 R

(a base-driven single-degree-of-freedom oscillator: unit static gain, dynamic amplification up to 2
for a suddenly applied load and 1 / (2 zeta) at resonance, and an impulse J gives a peak J omega).
The response is computed exactly for a reaction linear between samples (first-order hold), so the
output rate only matters through how well the samples describe ``R``. Content of ``R`` far above omega
(the penalty ringing, single-sample contact spikes) is attenuated as (omega / 2 pi f)^2; loads slower
than the mode pass with their dynamic amplification. docs/structures.md ("Are the judged peaks
converged?") states when this reading is conservative.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.signal import cont2discrete, lfilter, lfilter_zi, ss2tf

#: Fewest output samples per period of the highest structural mode a location is read through: the
#: samples must describe the load near the mode (as ``multibody.hinge.STRUCTURAL_STEPS_PER_PERIOD``
#: asks of the step for a mode in the dynamics).
SAMPLES_PER_MODE_PERIOD = 20
#: Relative spread of sample intervals accepted as uniform sampling (the recorder samples at a fixed
#: output rate; the last interval may be shorter by rounding).
UNIFORM_SAMPLING_TOLERANCE = 1e-6


@lru_cache(maxsize=1024)          # a range's grid is filtered for every component and location alike
def modal_filter_coefficients(frequency_hz: float, damping_ratio: float, interval_s: float):
    """Discrete transfer function (b, a) of the mode ``omega^2 / (s^2 + 2 zeta omega s + omega^2)``
    for samples ``interval_s`` apart, exact for a load linear between samples (first-order hold).

    Parameters
    ----------
    frequency_hz : float
        The structure's mode (Hz), > 0.
    damping_ratio : float
        Its damping, fraction of critical (-), in [0, 1).
    interval_s : float
        Sample interval (s), > 0.

    Returns
    -------
    b, a : (3,) float
        Numerator and denominator of the discrete filter, for :func:`scipy.signal.lfilter`.
    """
    if not (frequency_hz > 0 and 0 <= damping_ratio < 1 and interval_s > 0):
        raise ValueError(f"a mode needs frequency_hz > 0, 0 <= damping_ratio < 1 and a positive interval; got "
                         f"{frequency_hz}, {damping_ratio}, {interval_s}")
    omega = 2.0 * np.pi * frequency_hz
    a_c = np.array([[0.0, 1.0], [-omega ** 2, -2.0 * damping_ratio * omega]])
    b_c = np.array([[0.0], [omega ** 2]])
    c_c = np.array([[1.0, 0.0]])
    a_d, b_d, c_d, d_d, _ = cont2discrete((a_c, b_c, c_c, np.zeros((1, 1))), interval_s, method="foh")
    num, den = ss2tf(a_d, b_d, c_d, d_d)
    return np.ravel(num), np.ravel(den)


def modal_load(time, load, frequency_hz: float, damping_ratio: float) -> np.ndarray:
    """The load a mode at ``frequency_hz`` carries when the rigid structure would carry ``load``.

    The structure starts at rest under the first sample (a load already present at t0 is static).

    Parameters
    ----------
    time : (k,) float
        Sample times (s), uniformly spaced.
    load : (k, ...) float
        Rigid-joint reaction, any unit and any trailing shape (components filtered independently,
        e.g. (k, 3) force in the joint frame).
    frequency_hz : float
        The structure's mode (Hz).
    damping_ratio : float
        Its damping, fraction of critical (-).

    Returns
    -------
    (k, ...) float
        The modal load, same unit and shape.
    """
    time = np.asarray(time, float)
    load = np.asarray(load, float)
    if time.size < 2:
        return load.copy()
    steps = np.diff(time)
    interval = float(np.median(steps))
    if np.any(np.abs(steps[:-1] - interval) > UNIFORM_SAMPLING_TOLERANCE * interval + 1e-12) or steps[-1] > interval * (
            1 + UNIFORM_SAMPLING_TOLERANCE):
        raise ValueError("modal_load needs uniformly spaced samples (a fixed output rate)")
    b, a = modal_filter_coefficients(float(frequency_hz), float(damping_ratio), interval)
    initial = lfilter_zi(b, a).reshape((-1,) + (1,) * (load.ndim - 1)) * load[:1]
    out, _ = lfilter(b, a, load, axis=0, zi=initial)
    return out


#: Largest ratio between neighbouring modes of a range's grid: a mode between two grid points reads an
#: impulse (J omega) at most 5 % above its lower neighbour and never above its upper one, and a slow or
#: suddenly applied load alike at every mode; near a resonance of a periodic load the response between
#: grid points can be higher (not bounded here; the envelope is a grid, stated as such).
MODE_GRID_RATIO = 1.05


def mode_grid(low_hz: float, high_hz: float) -> np.ndarray:
    """Modes (Hz) that stand for every first mode in [low_hz, high_hz]: log-spaced, both ends
    included, neighbours at most :data:`MODE_GRID_RATIO` apart; one mode when low == high.

    Parameters
    ----------
    low_hz, high_hz : float
        The range of the structure's first mode (Hz), 0 < low <= high.

    Returns
    -------
    (n,) float
    """
    if not 0 < low_hz <= high_hz:
        raise ValueError(f"a mode range is 0 < low <= high; got [{low_hz}, {high_hz}]")
    count = 1 + int(np.ceil(np.log(high_hz / low_hz) / np.log(MODE_GRID_RATIO) - 1e-9))
    return np.geomspace(low_hz, high_hz, count) if count > 1 else np.array([float(low_hz)])


def modal_loads(time, load, modes_hz, damping_ratio: float) -> np.ndarray:
    """:func:`modal_load` for each mode of ``modes_hz``: (n_modes, k, ...) in the unit of ``load``.

    Parameters
    ----------
    time : (k,) float
        Sample times (s), uniformly spaced.
    load : (k, ...) float
        Rigid-joint reaction (any unit).
    modes_hz : (n_modes,) float
        Modes (Hz), e.g. :func:`mode_grid`.
    damping_ratio : float
        Damping of every mode, fraction of critical (-).

    Returns
    -------
    (n_modes, k, ...) float
    """
    return np.stack([modal_load(time, load, f, damping_ratio) for f in modes_hz])


class OnlineModalLoad:
    """The same modal loads, one sample at a time (what a run checks to release a joint as it goes).

    Each mode's filter runs in transposed direct form II; the first sample sets the static state, as
    :func:`modal_load` does, so the online and batch results agree to rounding.

    Parameters
    ----------
    modes_hz : (n_modes,) float
        Modes (Hz).
    damping_ratio : float
        Their damping, fraction of critical (-).
    interval_s : float
        The fixed output interval (s) the samples arrive at.
    """

    def __init__(self, modes_hz, damping_ratio: float, interval_s: float):
        coeffs = [modal_filter_coefficients(float(f), float(damping_ratio), float(interval_s)) for f in modes_hz]
        self._b = np.array([np.pad(b, (0, 3 - len(b))) for b, _ in coeffs])      # (n_modes, 3)
        self._a = np.array([a / a[0] for _, a in coeffs])
        self._b = self._b / np.array([a[0] for _, a in coeffs])[:, None]
        self._zi = np.array([lfilter_zi(b, a) for b, a in zip(self._b, self._a)])   # (n_modes, 2)
        self._state = None

    def update(self, load) -> np.ndarray:
        """Feed one sample of the rigid-joint load (any shape, e.g. (3,)); returns each mode's load
        at that sample, (n_modes, ...)."""
        x = np.asarray(load, float)
        extra = (1,) * x.ndim
        b = self._b.reshape(self._b.shape + extra)
        a = self._a.reshape(self._a.shape + extra)
        if self._state is None:
            self._state = self._zi.reshape(self._zi.shape + extra) * x
        y = b[:, 0] * x + self._state[:, 0]
        self._state = np.stack([b[:, 1] * x - a[:, 1] * y + self._state[:, 1], b[:, 2] * x - a[:, 2] * y], axis=1)
        return y
