"""Contact shapes of the debris bodies, one plug-in file each, found by name.

A shape is a module of this package that defines

- ``NAME``: the ``kind`` a case's ``shapes`` table gives;
- ``KEYS``: its keys (:class:`multibody.shape_base.Key`: name, kind of value, meaning with unit,
  default), in file order; the case schema (:mod:`riskassess.cases.impact`) is built from them;
- ``mesh_target_frame(**keys) -> trimesh.Trimesh``: the closed triangle mesh of the shape in the
  target frame (m), taking the keys as keywords.

Adding a shape is adding one file here.
"""
from __future__ import annotations

import importlib
import pkgutil


def discover() -> dict:
    """Shape name -> its module, for every module of this package, in module-name order."""
    shapes = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        shapes[module.NAME] = module
    return shapes


#: Shape name -> its module.
SHAPES = discover()


def shape_plugin(kind: str):
    """The module of the contact shape named ``kind``; ValueError listing the known ones otherwise.

    Parameters
    ----------
    kind : str
        A shape's ``NAME`` (a case's ``shapes`` table ``kind``).

    Returns
    -------
    module
        Its plug-in module (``NAME``, ``KEYS``, ``mesh_target_frame``; meshes in the target frame, m).
    """
    if kind not in SHAPES:
        raise ValueError(f"unknown shape kind {kind!r}; the known kinds are {', '.join(SHAPES)}")
    return SHAPES[kind]
