"""Catalog of candidate effects: every module of this package defines ``EFFECT``, an instance of
:class:`riskassess.diagnosis.effects.base.Effect`; adding an effect is adding one module."""
from __future__ import annotations

import importlib
import pkgutil

from riskassess.diagnosis.effects.base import Effect, Parameter


def _discover() -> dict[str, Effect]:
    catalog = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name == "base":
            continue
        effect = importlib.import_module(f"{__name__}.{info.name}").EFFECT
        catalog[effect.id] = effect
    return catalog


#: id -> effect, in module order.
CATALOG: dict[str, Effect] = _discover()

__all__ = ["CATALOG", "Effect", "Parameter"]
