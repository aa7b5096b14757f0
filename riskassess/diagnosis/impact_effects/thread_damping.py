"""Thread damping: the axial damping of the net's threads differs from the case's."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect, relative_bounds

#: Range of the fit (-): a factor 20 either way (the seed paper's 1.58 N s/m is one value for one
#: thread; 32 N s/m on a 42 g node is a 1.3e-4 s decay time, near the 1e-4 s step of the small case).
FACTOR = 20.0
#: Damping that sizes the range when the case has none (N s/m): the seed paper's.
REFERENCE_DAMPING = 1.58


class ThreadDamping(ImpactEffect):
    id = "thread_damping"
    title = "Axial damping of the net's threads differs from the case's"

    def parameter(self, impact_case) -> Parameter:
        """c (N s/m), fitted as ln(c / typical)."""
        value = impact_case.net.thread.damping or REFERENCE_DAMPING
        low, high = relative_bounds(value, FACTOR)
        return Parameter("thread_damping", "N s/m", "axial damping of a thread", value, low, high, log=True)

    def case_value(self, impact_case) -> float:
        """The case's ``net.thread.damping`` (N s/m)."""
        return float(impact_case.net.thread.damping)

    def overrides(self, impact_case, value: float) -> dict:
        """``net.thread.damping`` = value (N s/m)."""
        return {"net.thread.damping": float(value)}


EFFECT = ThreadDamping()
