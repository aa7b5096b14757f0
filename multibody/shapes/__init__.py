"""Contact shapes of the debris bodies, one plug-in file each, found by name.

A shape is a module of this package implementing :class:`multibody.shapes.base.ContactShape`:

- ``NAME``: the ``kind`` a case's ``shapes`` table gives;
- ``KEYS``: its keys (:class:`multibody.shapes.base.Key`: name, kind of value, meaning with unit,
  default), in file order; the case schema (:mod:`riskassess.cases.impact`) is built from them;
- ``mesh_target_frame(**keys) -> trimesh.Trimesh``: the closed triangle mesh of the shape in the
  target frame (m), taking the keys as keywords.

Adding a shape is adding one file here; ``SHAPES[kind]`` of an unknown kind is a ``ValueError``
listing the known ones (:mod:`multibody.maths.plugins`).
"""
from __future__ import annotations

from multibody.maths.plugins import Family, discover
from multibody.shapes.base import ContactShape

#: Modules of this folder that are not shapes: the interface itself.
NOT_SHAPES = ("base",)

#: Shape name -> its module, in module-name order.
SHAPES: Family = discover(__name__, __path__, "contact shape", ContactShape, skip=NOT_SHAPES)

__all__ = ["NOT_SHAPES", "SHAPES"]
