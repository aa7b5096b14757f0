"""Catalog of the impact scenario's candidate effects: every module of this package defines
``EFFECT``, an instance of :class:`riskassess.diagnosis.impact_effects.base.ImpactEffect`; adding an
effect is adding one module. A separate catalog from :mod:`riskassess.diagnosis.effects`: these are
deviations of the impact model's own physical parameters, not loads added to the tumbling or
towing models (docs/diagnosis.md, "Impact scenario"). ``IMPACT_CATALOG[id]`` of an unknown id is a
``ValueError`` listing the known ones (:mod:`multibody.maths.plugins`)."""
from __future__ import annotations

from multibody.maths.plugins import Family, discover
from riskassess.diagnosis.impact_effects.base import ImpactEffect

#: id -> effect, in module order.
IMPACT_CATALOG: Family = discover(__name__, __path__, "impact effect", ImpactEffect, key="id", plugin="EFFECT",
                                  skip=("base",))

__all__ = ["IMPACT_CATALOG", "ImpactEffect"]
