"""Net bending stiffness: the net's threads resist bending (rotational springs at the nodes along
each thread line, :mod:`multibody.net`), with a rigidity EI other than the case's (the small
Envisat case has none: ``bending = false``, as the seed paper)."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect
from riskassess.diagnosis.impact_effects.thread_stiffness import mesh_thread_stiffness
from riskassess.models.impact import solid_bending_rigidity, thread_area, thread_bending_rigidity

#: Range of EI (-) relative to the solid thread's E pi d^4 / 64: a braided line bends far more easily
#: than a solid rod of its modulus (1/10), a coated or stiffened one less (up to 1000 x).
LOWER_FACTOR, UPPER_FACTOR = 0.1, 1000.0


def solid_thread_rigidity(impact_case) -> float:
    """E pi d^4 / 64 of a solid thread of the case's axial stiffness (N m^2).

    Parameters
    ----------
    impact_case : riskassess.cases.impact.Case
        The validated impact case.

    Returns
    -------
    rigidity : float
    """
    thread = impact_case.net.thread
    modulus = mesh_thread_stiffness(impact_case) * impact_case.net.mesh_size / thread_area(thread)
    return float(solid_bending_rigidity(modulus, thread.diameter))


class NetBending(ImpactEffect):
    id = "net_bending"
    title = "The net's threads have a bending stiffness EI other than the case's (none in the small case)"

    def parameter(self, impact_case) -> Parameter:
        """EI (N m^2), fitted as ln(EI / typical); typical the case's EI, or the solid thread's when off."""
        reference = float(thread_bending_rigidity(impact_case.net.thread)) or solid_thread_rigidity(impact_case)
        return Parameter("bending_rigidity", "N m^2", "thread bending rigidity EI", reference,
                         LOWER_FACTOR * reference, UPPER_FACTOR * reference, log=True)

    def case_value(self, impact_case) -> float:
        """The case's EI (N m^2): 0 when bending is off (outside the fitted range: the nominal model)."""
        return float(thread_bending_rigidity(impact_case.net.thread))

    def overrides(self, impact_case, value: float) -> dict:
        """``net.thread.bending`` on, ``net.thread.bending_rigidity`` = value (N m^2)."""
        return {"net.thread.bending": True, "net.thread.bending_rigidity": float(value)}


EFFECT = NetBending()
