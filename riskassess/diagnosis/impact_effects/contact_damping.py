"""Contact damping: the Hunt-Crossley damping factor alpha of the contact differs from the case's."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect, relative_bounds

#: Range of the fit (-): alpha within a factor 20 either way (restitution from ~1 to near 0 at the
#: impact speeds of the net, 1-20 m/s).
FACTOR = 20.0
#: alpha that sizes the range when the case has none (s/m): the seed paper's 0.05 s/m.
REFERENCE_ALPHA = 0.05


class ContactDamping(ImpactEffect):
    id = "contact_damping"
    title = "Hunt-Crossley contact damping factor alpha differs from the case's"

    def parameter(self, impact_case) -> Parameter:
        """alpha (s/m; d_n = 1.5 alpha k_n), fitted as ln(alpha / typical)."""
        value = impact_case.contact.hunt_crossley_alpha or REFERENCE_ALPHA
        low, high = relative_bounds(value, FACTOR)
        return Parameter("hunt_crossley_alpha", "s/m", "Hunt-Crossley damping factor alpha", value, low, high,
                         log=True)

    def case_value(self, impact_case) -> float:
        """The case's ``contact.hunt_crossley_alpha`` (s/m)."""
        return float(impact_case.contact.hunt_crossley_alpha)

    def overrides(self, impact_case, value: float) -> dict:
        """``contact.hunt_crossley_alpha`` = value (s/m)."""
        return {"contact.hunt_crossley_alpha": float(value)}


EFFECT = ContactDamping()
