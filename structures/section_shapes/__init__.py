"""Cross-section shapes, one plug-in file each, found by name.

A shape is a module of this package that defines

- ``NAME``: the ``kind`` a case's ``section`` table gives;
- ``DIMENSIONS``: its dimensions (m) with their meaning, in the order ``properties`` takes them (the
  case schema is built from it: every dimension > 0 and <= 20 m);
- ``properties(**dimensions) -> SectionProperties`` (:mod:`structures.section_base`), raising
  ``ValueError`` for impossible dimensions.

Adding a shape is adding one file here.
"""
from __future__ import annotations

import importlib
import pkgutil

#: Shape name -> its module.
SHAPES = {}
for _info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
    _module = importlib.import_module(f"{__name__}.{_info.name}")
    SHAPES[_module.NAME] = _module
