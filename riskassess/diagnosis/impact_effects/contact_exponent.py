"""Contact exponent: the Hertz / Hunt-Crossley exponent n of the contact law differs from the case's.

The stiffness k_n keeps its value (the case file's meaning: F = k_n delta^n, k_n in N/m^n), so a
larger exponent is a softer contact at the sub-millimetre penetrations of the net's nodes."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect

#: Range of the fit (-): 1 (linear spring) to 2 (beyond the Hertz 1.5 of a sphere; the schema allows 3).
LOWER, UPPER = 1.0, 2.0


class ContactExponent(ImpactEffect):
    id = "contact_exponent"
    title = "Hertz / Hunt-Crossley exponent n of the contact law differs from the case's"

    def parameter(self, impact_case) -> Parameter:
        """n (-), fitted linearly in [1, 2] (widened to hold the case's value)."""
        value = impact_case.contact.exponent
        return Parameter("contact_exponent", "-", "Hertz contact exponent n (k_n kept)", value,
                         min(LOWER, value), max(UPPER, value))

    def case_value(self, impact_case) -> float:
        """The case's ``contact.exponent`` (-)."""
        return float(impact_case.contact.exponent)

    def overrides(self, impact_case, value: float) -> dict:
        """``contact.exponent`` = value (-)."""
        return {"contact.exponent": float(value)}


EFFECT = ContactExponent()
