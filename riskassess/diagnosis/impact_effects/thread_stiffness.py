"""Thread stiffness: the axial stiffness of the net's threads differs from the case's."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect, relative_bounds
from riskassess.models.impact import thread_area, thread_bending_rigidity

#: Range of the fit (-): a factor 5 either way. Stiffer than 5x, the net's highest thread mode
#: (2.4e3 rad/s for envisat_small) times the case's 1e-4 s step nears the Verlet limit.
FACTOR = 5.0


def mesh_thread_stiffness(impact_case) -> float:
    """Axial stiffness of one mesh-length thread EA / l0 (N/m) of the case.

    Parameters
    ----------
    impact_case : riskassess.cases.impact.Case
        The validated impact case (``stiffness`` or ``modulus``).

    Returns
    -------
    stiffness : float
    """
    thread = impact_case.net.thread
    if thread.stiffness is not None:
        return float(thread.stiffness)
    return float(thread.modulus * thread_area(thread) / impact_case.net.mesh_size)


class ThreadStiffness(ImpactEffect):
    id = "thread_stiffness"
    title = "Axial stiffness of the net's threads differs from the case's"

    def parameter(self, impact_case) -> Parameter:
        """EA / l0 of one mesh-length thread (N/m), fitted as ln(value / case value)."""
        value = mesh_thread_stiffness(impact_case)
        low, high = relative_bounds(value, FACTOR)
        return Parameter("thread_stiffness", "N/m", "axial stiffness EA / l0 of one mesh-length thread", value,
                         low, high, log=True)

    def case_value(self, impact_case) -> float:
        """EA / l0 of the case (N/m)."""
        return mesh_thread_stiffness(impact_case)

    def overrides(self, impact_case, value: float) -> dict:
        """The case's own key (``stiffness`` or ``modulus``) scaled; a bending rigidity the case derives
        from the modulus is kept at its value (this effect changes the axial stiffness only)."""
        thread = impact_case.net.thread
        if thread.stiffness is not None:
            return {"net.thread.stiffness": float(value)}
        out = {"net.thread.modulus": float(value * impact_case.net.mesh_size / thread_area(thread))}
        if thread.bending and thread.bending_rigidity is None:
            out["net.thread.bending_rigidity"] = float(thread_bending_rigidity(thread))
        return out


EFFECT = ThreadStiffness()
