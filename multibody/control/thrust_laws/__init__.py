"""Thrust laws of the towing chaser, one plug-in module each, found by name.

A law is a module of this package implementing :class:`multibody.control.thrust.ThrustLaw`:

- ``NAME``: the ``thrust.kind`` a towing case gives;
- ``ALONG_BODY_Z``: True if the thrust acts along the chaser's body z, False if against its
  velocity (inertial);
- ``CASE_SECTIONS``: the case tables it reads besides ``[thrust]`` (the case schema requires them);
- ``command``: the compiled law, :data:`multibody.control.thrust.THRUST_SIGNATURE`, ``cache=True``;
- ``arrays(case, tether, z0, z_rate0) -> (params, state)``: its constants and initial states (flat
  float arrays) from a towing case (``riskassess.cases.towing.TowingCase``: ``thrust``, the
  ``CASE_SECTIONS`` and ``chaser.mass``), the main tether ``tether`` = [k_MT (N/m), c_MT (N s/m), ...]
  and the elongation z0 (m) and its rate z_rate0 (m/s) at the start.

Adding a law is adding one file here; ``LAWS[name]`` of an unknown name is a ``ValueError`` listing
the known ones (:mod:`multibody.maths.plugins`).
"""
from __future__ import annotations

from multibody.control.thrust import ThrustLaw
from multibody.maths.plugins import Family, discover

#: Law name -> its module, in module-name order.
LAWS: Family = discover(__name__, __path__, "thrust law", ThrustLaw)

__all__ = ["LAWS"]
