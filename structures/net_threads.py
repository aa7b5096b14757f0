"""Integrity of the net itself: the peak tension of every thread against its breaking load.

The tension history comes from the net snapshots with the simulation's own law
(:func:`multibody.net.thread_tension_strain`, the tension-only Kelvin-Voigt thread of
Cuadrat-Grzybowski & Gill 2024 eq. (1)); snapshots are taken at the case's net output rate, so the
peak is the largest *sampled* tension, a lower bound of the true peak between snapshots.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class NetIntegrity:
    """Peak thread tensions of a run and the threads over the breaking load.

    Attributes
    ----------
    peak_tension : (m,) float
        Largest sampled tension of each thread (N).
    peak_time : (m,) float
        Time of that sample (s).
    breaking_load : float or None
        Breaking load of one thread (N); None when the case gives none (not assessed).
    over : (p,) int
        Indices of the threads whose peak tension reaches the breaking load, highest first;
        empty when not assessed.
    """

    peak_tension: np.ndarray
    peak_time: np.ndarray
    breaking_load: float | None
    over: np.ndarray

    @property
    def assessed(self) -> bool:
        return self.breaking_load is not None

    @property
    def margin_of_safety(self) -> float | None:
        """breaking load / highest peak tension - 1 (-); None when not assessed or no thread pulled."""
        peak = float(self.peak_tension.max(initial=0.0))
        if self.breaking_load is None or peak <= 0.0:
            return None
        return self.breaking_load / peak - 1.0


def net_integrity(tension, time, breaking_load: float | None) -> NetIntegrity:
    """Peak tension per thread and the threads at or over ``breaking_load``.

    Parameters
    ----------
    tension : (k, m) float
        Tension of every thread at every snapshot (N).
    time : (k,) float
        Snapshot times (s).
    breaking_load : float or None
        Breaking load of one thread (N), or None.
    """
    tension = np.asarray(tension, float)
    time = np.asarray(time, float)
    if tension.ndim != 2 or tension.shape[0] != time.shape[0]:
        raise ValueError(f"tension must be (k, m) with k = len(time) = {time.shape[0]}; got {tension.shape}")
    at = tension.argmax(axis=0)
    peak = tension[at, np.arange(tension.shape[1])]
    if breaking_load is None:
        over = np.zeros(0, np.int64)
    else:
        over = np.flatnonzero(peak >= breaking_load)
        over = over[np.argsort(-peak[over], kind="stable")]
    return NetIntegrity(peak, time[at], breaking_load, over)
