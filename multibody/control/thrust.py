"""Thrust laws of the towing chaser: the plug-in interface shared by the open-loop ramp and the
main-tether elongation controllers (one module each in :mod:`multibody.control.thrust_laws`).

Every law is a compiled function of the same signature (:data:`THRUST_SIGNATURE`), called once per
integration step (a digital controller with zero-order hold over the step):

``command(t, z, z_rate, params, state, step, advance) -> F_t``

* ``t`` time (s); ``z`` main-tether elongation :math:`l_{MT} - l_{MT,0}` (m) and ``z_rate`` its
  rate (m/s), measured at the chaser;
* ``params`` (k,) float the law's constants, ``state`` (j,) float its internal states (reference
  model, adaptive parameters), updated in place over ``step`` (s) when ``advance``;
* returns the thrust magnitude (N) along the chaser's thrust direction.

The towing kernels take the law as a numba first-class function (:data:`THRUST_LAW`), so adding a
law is adding one module to :mod:`multibody.control.thrust_laws` (its contents are listed there).
"""
from __future__ import annotations

from numba import types

_VECTOR = types.float64[::1]
#: numba signature of a thrust law's ``command`` (see the module doc); every law is compiled eagerly
#: with it so that one compiled towing kernel takes any of them.
THRUST_SIGNATURE = types.float64(types.float64, types.float64, types.float64, _VECTOR, _VECTOR, types.float64,
                                 types.boolean)
#: numba type of a thrust law passed to a compiled kernel (first-class function).
THRUST_LAW = types.FunctionType(THRUST_SIGNATURE)
