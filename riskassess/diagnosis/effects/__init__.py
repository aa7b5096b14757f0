"""Catalog of candidate effects: every module of this package defines ``EFFECT``, an instance of
:class:`riskassess.diagnosis.effects.base.Effect`; adding an effect is adding one module."""
from __future__ import annotations

import importlib
import pkgutil

from riskassess.diagnosis.effects.base import Effect, Parameter


def discover_effects(package_path, package_name: str) -> dict:
    """id -> ``EFFECT`` of every module of a plug-in package except ``base``, in module order (this
    catalog's and the impact scenario's, :mod:`riskassess.diagnosis.impact_effects`).

    Parameters
    ----------
    package_path : list of str
        The package's ``__path__``.
    package_name : str
        The package's ``__name__``.
    """
    catalog = {}
    for info in sorted(pkgutil.iter_modules(package_path), key=lambda m: m.name):
        if info.name == "base":
            continue
        effect = importlib.import_module(f"{package_name}.{info.name}").EFFECT
        catalog[effect.id] = effect
    return catalog


#: id -> effect, in module order.
CATALOG: dict[str, Effect] = discover_effects(__path__, __name__)

__all__ = ["CATALOG", "Effect", "Parameter"]
