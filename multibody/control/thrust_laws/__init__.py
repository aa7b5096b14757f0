"""Thrust laws of the towing chaser, one plug-in module each, found by name.

A law is a module of this package that defines

- ``NAME``: the ``thrust.kind`` a towing case gives;
- ``ALONG_BODY_Z``: True if the thrust acts along the chaser's body z, False if against its
  velocity (inertial);
- ``CASE_SECTIONS``: the case tables it reads besides ``[thrust]`` (the case schema requires them);
- ``command``: the compiled law, :data:`multibody.control.thrust.THRUST_SIGNATURE`, ``cache=True``;
- ``arrays(case, tether, z0, z_rate0) -> (params, state)``: its constants and initial states (flat
  float arrays) from a towing case (``riskassess.cases.towing.TowingCase``: ``thrust``, the
  ``CASE_SECTIONS`` and ``chaser.mass``), the main tether ``tether`` = [k_MT (N/m), c_MT (N s/m), ...]
  and the elongation z0 (m) and its rate z_rate0 (m/s) at the start.

Adding a law is adding one file here.
"""
from __future__ import annotations

import importlib
import pkgutil
from types import ModuleType

#: Law name -> its module, in module order.
LAWS: dict[str, ModuleType] = {}
for _info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
    _module = importlib.import_module(f"{__name__}.{_info.name}")
    LAWS[_module.NAME] = _module


def thrust_law(name: str) -> ModuleType:
    """The law module called ``name``; a ValueError listing the known laws otherwise.

    Parameters
    ----------
    name : str
        A case's ``thrust.kind``.
    """
    if name not in LAWS:
        raise ValueError(f"thrust.kind: unknown thrust law '{name}'; the known laws are: {', '.join(LAWS)}")
    return LAWS[name]


__all__ = ["LAWS", "thrust_law"]
