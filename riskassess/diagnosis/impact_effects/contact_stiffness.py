"""Contact stiffness: the Hertz stiffness k_n of the net-debris contact differs from the case's."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect, relative_bounds

#: Range of the fit (-): k_n known to within a factor 30 either way (the seed paper's value is a
#: Hertz estimate for aluminium against a 1 mm thread node; a real thread's compliance is lower).
FACTOR = 30.0


class ContactStiffness(ImpactEffect):
    id = "contact_stiffness"
    title = "Hertz contact stiffness k_n of the net-debris contact differs from the case's"

    def parameter(self, impact_case) -> Parameter:
        """k_n (N/m^n, n the case's exponent), fitted as ln(k_n / case value)."""
        value = impact_case.contact.stiffness
        low, high = relative_bounds(value, FACTOR)
        return Parameter("contact_stiffness", f"N/m^{impact_case.contact.exponent:g}",
                         "Hertz contact stiffness k_n", value, low, high, log=True)

    def case_value(self, impact_case) -> float:
        """The case's ``contact.stiffness`` (N/m^n)."""
        return float(impact_case.contact.stiffness)

    def overrides(self, impact_case, value: float) -> dict:
        """``contact.stiffness`` = value (N/m^n)."""
        return {"contact.stiffness": float(value)}


EFFECT = ContactStiffness()
