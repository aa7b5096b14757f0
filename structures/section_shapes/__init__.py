"""Cross-section shapes, one plug-in file each, found by name.

A shape is a module of this package implementing :class:`structures.section_base.SectionShape`:

- ``NAME``: the ``kind`` a case's ``section`` table gives;
- ``DIMENSIONS``: its dimensions (m) with their meaning, in the order ``properties`` takes them (the
  case schema is built from it: every dimension > 0 and <= 20 m);
- ``properties(**dimensions) -> SectionProperties`` (:mod:`structures.section_base`), raising
  ``ValueError`` for impossible dimensions.

Adding a shape is adding one file here; ``SHAPES[kind]`` of an unknown kind is a ``ValueError``
listing the known ones (:mod:`multibody.maths.plugins`).
"""
from __future__ import annotations

from multibody.maths.plugins import Family, discover
from structures.section_base import SectionShape

#: Shape name -> its module, in module-name order.
SHAPES: Family = discover(__name__, __path__, "section shape", SectionShape)

__all__ = ["SHAPES"]
