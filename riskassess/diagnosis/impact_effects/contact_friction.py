"""Friction coefficient: the net-debris friction differs from the case's.

One parameter, the kinetic coefficient mu_k; the static coefficient follows at the case's ratio
mu_s / mu_k (one number is what a post-capture record can see of the stick-slip law)."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect

#: Range of mu_k (-): frictionless to 0.6 (rubber-like on metal; Dyneema on aluminium is ~0.1-0.2).
LOWER, UPPER = 0.0, 0.6


def static_ratio(impact_case) -> float:
    """mu_s / mu_k of the case (1 when mu_k is 0).

    Parameters
    ----------
    impact_case : riskassess.cases.impact.Case
        The validated impact case.

    Returns
    -------
    ratio : float
        (-), >= 1 (the schema keeps mu_k <= mu_s).
    """
    contact = impact_case.contact
    return contact.mu_static / contact.mu_kinetic if contact.mu_kinetic > 0 else 1.0


class ContactFriction(ImpactEffect):
    id = "contact_friction"
    title = "Friction coefficient of the net-debris contact differs from the case's (mu_s / mu_k kept)"

    def parameter(self, impact_case) -> Parameter:
        """mu_k (-), fitted linearly."""
        value = impact_case.contact.mu_kinetic
        return Parameter("mu_kinetic", "-", "kinetic friction coefficient (static at the case's ratio)", value,
                         LOWER, max(UPPER, value))

    def case_value(self, impact_case) -> float:
        """The case's ``contact.mu_kinetic`` (-)."""
        return float(impact_case.contact.mu_kinetic)

    def overrides(self, impact_case, value: float) -> dict:
        """``contact.mu_kinetic`` = value, ``contact.mu_static`` = value x the case's ratio (-)."""
        return {"contact.mu_kinetic": float(value), "contact.mu_static": float(value * static_ratio(impact_case))}


EFFECT = ContactFriction()
