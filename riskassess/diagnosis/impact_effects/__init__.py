"""Catalog of the impact scenario's candidate effects: every module of this package defines
``EFFECT``, an instance of :class:`riskassess.diagnosis.impact_effects.base.ImpactEffect`; adding an
effect is adding one module. A separate catalog from :mod:`riskassess.diagnosis.effects`: these are
deviations of the impact model's own physical parameters, not loads added to the tumbling or
towing models (docs/diagnosis.md, "Impact scenario")."""
from __future__ import annotations

from riskassess.diagnosis.effects import discover_effects
from riskassess.diagnosis.impact_effects.base import ImpactEffect

#: id -> effect, in module order.
IMPACT_CATALOG: dict[str, ImpactEffect] = discover_effects(__path__, __name__)

__all__ = ["IMPACT_CATALOG", "ImpactEffect"]
