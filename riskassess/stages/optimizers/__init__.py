"""Optimizers of the towing identification, one plug-in file each, found by name.

A plug-in is a module of this package that defines

- ``NAME``: the name a case (``identification.searches``) and the CLI (``--optimizers``) use;
- ``search(problem, x0, settings) -> (s, cost)``: minimize the pymoo ``problem``
  (:class:`riskassess.stages.identify.TowingFit`, bounded, 4 variables) from ``x0`` with the case's
  ``identification.optimizers`` ``settings``; returns the best s (4,) and its cost.

Adding an optimizer is adding one file here (and its name to the case schema's ``searches``).
"""
from __future__ import annotations

import importlib
import pkgutil

#: Optimizer name -> its module (``NAME``, ``search``).
OPTIMIZERS = {}
for _info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
    _module = importlib.import_module(f"{__name__}.{_info.name}")
    OPTIMIZERS[_module.NAME] = _module


def optimizer_search(name: str):
    """The ``search`` function of optimizer ``name``; ``ValueError`` listing the known names.

    Parameters
    ----------
    name : str
        An optimizer name (:data:`OPTIMIZERS`).

    Returns
    -------
    callable
        ``search(problem, x0, settings) -> (s, cost)``.
    """
    if name not in OPTIMIZERS:
        raise ValueError(f"unknown optimizer '{name}'; the optimizers are: {', '.join(sorted(OPTIMIZERS))}")
    return OPTIMIZERS[name].search
