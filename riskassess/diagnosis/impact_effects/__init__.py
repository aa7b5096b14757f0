"""Catalog of the impact scenario's candidate effects: every module of this package defines
``EFFECT``, an instance of :class:`riskassess.diagnosis.impact_effects.base.ImpactEffect`; adding an
effect is adding one module. A separate catalog from :mod:`riskassess.diagnosis.effects`: these are
deviations of the impact model's own physical parameters, not loads added to the tumbling or
towing models (docs/diagnosis.md, "Impact scenario")."""
from __future__ import annotations

import importlib
import pkgutil

from riskassess.diagnosis.impact_effects.base import ImpactEffect


def _discover() -> dict[str, ImpactEffect]:
    catalog = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name == "base":
            continue
        effect = importlib.import_module(f"{__name__}.{info.name}").EFFECT
        catalog[effect.id] = effect
    return catalog


#: id -> effect, in module order.
IMPACT_CATALOG: dict[str, ImpactEffect] = _discover()

__all__ = ["IMPACT_CATALOG", "ImpactEffect"]
