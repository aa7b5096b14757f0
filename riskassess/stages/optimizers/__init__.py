"""Optimizers of the towing identification, one plug-in file each, found by name.

A plug-in is a module of this package implementing :class:`riskassess.stages.optimizers.base.Optimizer`:

- ``NAME``: the name a case (``identification.searches``) and the CLI (``--optimizers``) use;
- ``search(problem, x0, settings) -> (s, cost)``: minimize the pymoo ``problem``
  (:class:`riskassess.stages.identify.TowingFit`, bounded, 4 variables) from ``x0`` with the case's
  ``identification.optimizers`` ``settings``; returns the best s (4,) and its cost.

Adding an optimizer is adding one file here (and its name to the case schema's ``searches``);
``OPTIMIZERS[name]`` of an unknown name is a ``ValueError`` listing the known ones
(:mod:`multibody.maths.plugins`).
"""
from __future__ import annotations

from multibody.maths.plugins import Family, discover
from riskassess.stages.optimizers.base import Optimizer

#: Optimizer name -> its module (``NAME``, ``search``), in module-name order.
OPTIMIZERS: Family = discover(__name__, __path__, "optimizer", Optimizer, skip=("base",))

__all__ = ["OPTIMIZERS", "Optimizer"]
