"""Catalog of candidate effects: every module of this package defines ``EFFECT``, an instance of
:class:`riskassess.diagnosis.effects.base.Effect`; adding an effect is adding one module.
``CATALOG[id]`` of an unknown id is a ``ValueError`` listing the known ones (:mod:`multibody.maths.plugins`)."""
from __future__ import annotations

from multibody.maths.plugins import Family, discover
from riskassess.diagnosis.effects.base import Effect, Parameter

#: id -> effect, in module order.
CATALOG: Family = discover(__name__, __path__, "effect", Effect, key="id", plugin="EFFECT", skip=("base",))

__all__ = ["CATALOG", "Effect", "Parameter"]
