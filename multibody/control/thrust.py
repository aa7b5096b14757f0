"""Thrust laws of the towing chaser: the plug-in interface shared by the open-loop ramp and the
main-tether elongation controllers (one module each in :mod:`multibody.control.thrust_laws`).

Every law is a compiled function of the same signature (:data:`THRUST_SIGNATURE`), called once per
integration step (a digital controller with zero-order hold over the step):

``command(t, z, z_rate, range_rate, params, state, step, advance) -> F_t``

* ``t`` time (s); ``z`` main-tether elongation :math:`l_{MT} - l_{MT,0}` (m) and ``z_rate`` its
  rate (m/s), measured at the chaser; ``range_rate`` the rate of the chaser-debris CoM distance (m/s,
  > 0 separating; :func:`range_rate`), what the chaser's relative navigation measures;
* ``params`` (k,) float the law's constants, ``state`` (j,) float its internal states (reference
  model, adaptive parameters), updated in place over ``step`` (s) when ``advance``;
* returns the thrust magnitude (N) along the chaser's thrust direction.

The towing kernels take the law as a numba first-class function (:data:`THRUST_LAW`), so adding a
law is adding one module to :mod:`multibody.control.thrust_laws` implementing :class:`ThrustLaw`.
"""
from __future__ import annotations

import math
from typing import Protocol

import numpy as np
from numba import njit, types

_VECTOR = types.float64[::1]
#: numba signature of a thrust law's ``command`` (see the module doc); every law is compiled eagerly
#: with it so that one compiled towing kernel takes any of them.
THRUST_SIGNATURE = types.float64(types.float64, types.float64, types.float64, types.float64, _VECTOR, _VECTOR,
                                 types.float64, types.boolean)
#: numba type of a thrust law passed to a compiled kernel (first-class function).
THRUST_LAW = types.FunctionType(THRUST_SIGNATURE)


@njit(cache=True)
def range_rate(dx, dy, dz, dvx, dvy, dvz):
    """Rate of the chaser-debris CoM distance (m/s, > 0 while they separate): the relative velocity
    projected on the line of centres.

    Parameters
    ----------
    dx, dy, dz : float
        Debris CoM minus chaser CoM (m), any frame.
    dvx, dvy, dvz : float
        Debris CoM velocity minus chaser CoM velocity (m/s), the same frame.
    """
    return (dx * dvx + dy * dvy + dz * dvz) / math.sqrt(dx * dx + dy * dy + dz * dz)


class ThrustLaw(Protocol):
    """The interface of a thrust law: a module of :mod:`multibody.control.thrust_laws` (one file each)
    defines

    Attributes
    ----------
    NAME : str                   The ``thrust.kind`` a towing case gives.
    ALONG_BODY_Z : bool          True: the thrust acts along the chaser's body z; False: against its
                                 velocity (inertial).
    CASE_SECTIONS : tuple of str The case tables it reads besides ``[thrust]`` (the schema requires them).
    command                      The compiled law (see the module doc), ``@njit(THRUST_SIGNATURE, cache=True)``.
    """

    NAME: str
    ALONG_BODY_Z: bool
    CASE_SECTIONS: tuple[str, ...]
    command: object

    def arrays(self, case, tether, z0, z_rate0) -> tuple[np.ndarray, np.ndarray]:
        """The law's constants and initial states from a towing case.

        Parameters
        ----------
        case : riskassess.cases.towing.TowingCase
            Read: ``thrust``, the law's ``CASE_SECTIONS`` and ``chaser.mass``.
        tether : (3,) or (6,) float
            Main tether first: k_MT (N/m), c_MT (N s/m), ...
        z0 : float
            Main-tether elongation at the start (m).
        z_rate0 : float
            Its rate (m/s).

        Returns
        -------
        params : (k,) float
            Constants of ``command``.
        state : (j,) float
            Its states at the start.
        """
