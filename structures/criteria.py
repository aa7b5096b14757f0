"""Failure criteria against allowables that are a single value or an uncertain range.

An allowable given as a range ``[low, high]`` (the seed paper quotes 200-1000 N m for the
solar-array hinge-panel interface and (50, 100) MPa ultimate shear for the antenna
materials) is treated as a random variable, uniform over the range: with nothing known
but the bounds, the uniform law is the maximum-entropy choice. The likelihood of breaking
under a peak demand D is then P(allowable < D) = clip((D - low) / (high - low), 0, 1).
Independent criteria at one location combine as 1 - prod(1 - P_i).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Allowable:
    """An allowable load or stress (SI); ``low == high`` for a single value."""

    low: float
    high: float

    @classmethod
    def of(cls, value) -> "Allowable":
        """From a number or a ``[low, high]`` pair.

        Parameters
        ----------
        value : float or sequence of 2 float
            A single allowable, or its ``[low, high]`` range, in the criterion's SI unit (Pa for
            stresses, N m for moments, N for forces).

        Returns
        -------
        Allowable
        """
        if np.ndim(value) == 0:
            return cls(float(value), float(value))
        low, high = (float(v) for v in value)
        return cls(low, high)

    @property
    def nominal(self) -> float:
        """Mid-range value (the single value when not a range)."""
        return 0.5 * (self.low + self.high)

    def threshold(self, policy: str) -> float:
        """The value at which a run releases the joint: ``"low"``, ``"nominal"`` or ``"high"``.

        Parameters
        ----------
        policy : {"low", "nominal", "high"}
            Which end (or the middle) of a range allowable decides.

        Returns
        -------
        float
            The allowable at that end, in the criterion's SI unit.
        """
        return {"low": self.low, "nominal": self.nominal, "high": self.high}[policy]

    def likelihood_of_failure(self, demand: float) -> float:
        """P(allowable < demand) for an allowable uniform over [low, high]; a step for a single value.

        Parameters
        ----------
        demand : float
            Peak demand, in the allowable's SI unit (Pa, N m or N).

        Returns
        -------
        float
            Probability in [0, 1] (-).
        """
        if self.high <= self.low:
            return float(demand >= self.low)
        return float(np.clip((demand - self.low) / (self.high - self.low), 0.0, 1.0))

    def margin_of_safety(self, demand: float, policy: str = "low") -> float:
        """allowable / demand - 1 at the policy's value (negative: fails); inf for zero demand.

        Parameters
        ----------
        demand : float
            Peak demand, in the allowable's SI unit (Pa, N m or N).
        policy : {"low", "nominal", "high"}
            Which value of a range allowable is used (:meth:`threshold`).

        Returns
        -------
        float
            Margin of safety (-).
        """
        return self.threshold(policy) / demand - 1.0 if demand > 0.0 else float("inf")


def combined_likelihood(likelihoods) -> float:
    """Failure likelihood of a location that fails when any of its independent criteria fails.

    Parameters
    ----------
    likelihoods : iterable of float
        Failure probability of each criterion, in [0, 1] (-).

    Returns
    -------
    float
        1 - prod(1 - P_i) (-).
    """
    return float(1.0 - np.prod([1.0 - p for p in likelihoods]))


def first_exceedance_time(time, demand, threshold, skip_until=0.0):
    """First time (s) at or after ``skip_until`` where ``demand`` reaches ``threshold``; None if never.

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    demand : (k,) float
        Demand at each sample, in the criterion's SI unit (Pa, N m or N).
    threshold : float
        Allowable the demand is compared with, same unit as ``demand``.
    skip_until : float
        Samples before this time are ignored (s).

    Returns
    -------
    float or None
        Time of the first sample with ``demand >= threshold`` (s).
    """
    time = np.asarray(time)
    hit = (np.asarray(demand) >= threshold) & (time >= skip_until)
    return float(time[np.argmax(hit)]) if hit.any() else None
