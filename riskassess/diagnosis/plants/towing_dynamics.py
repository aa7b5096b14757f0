"""The towing scenario's fast model: the lower-order towing model's compiled twin with effect loads.

The nominal model is :mod:`multibody.towing` (chaser, connection point P, main tether and
sub-tethers, two-body gravity, thrust law, sliding-mode attitude control; Boonrath, Singh & Botta
2024, Sec. 2.2). It is integrated by the twin's own loop
(:func:`multibody.towing_kernel.verlet_run`: Verlet half kick, Lie-group drift, forces at the
evaluation state with P stepped implicitly, half kick), which before each force evaluation calls an
effect's *towing law* (its load hook); the law's loads go into the packed model's further-forces section
(:func:`multibody.towing_kernel.extra_forces`) and so act in that step, P's share inside its
implicit step. ``tests/diagnosis/test_towing.py`` checks that with no effect it reproduces
:func:`multibody.towing.run_twin` to round-off.

A towing law has the signature ``law(t, q, v, p, work, xe, h, load)``:

* ``t`` (s, the towing case's clock), ``q``, ``v`` (15,) the evaluation state in the kernel layout
  (P's entries are stale: read P from :func:`point_position`);
* ``p`` the effect's law parameters, ``work`` the packed model (geometry, masses, the last
  evaluation's diagnostics: main-tether elongation and rate, thrust);
* ``xe`` the law's own states, advanced in place by the law over ``h`` (s; 0: do not advance): a view
  of the effect's block (index 0 its first state) of the model's effect states, allocated when the
  model is built: each effect declares how many it needs and their values at t = 0
  (``Effect.towing_extra_states``, ``Effect.initial_towing_states``), and a pair's second effect's
  block follows the first's (:mod:`riskassess.diagnosis.composite`);
* ``load`` (15,) the generalized forces it ADDS, kernel layout: force on P (N, inertial), chaser
  and debris force (N, inertial) and torque (N m, body frame).

Loads are evaluated once per step and held over it (as the thrust law and P's update are).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.connection_point import V_N, X_N
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.towing_kernel import (CHASER, DEBRIS, LOAD_LAW_SIGNATURE, ST_TENSION, W_ATTACH_CHASER, W_DIAG,
                                     W_INERTIA, W_MASSES, W_N_ATTACH, W_POINT, W_REFERENCE, W_TETHER, no_load)

#: numba signature of a towing law (see the module doc): the towing kernel's load hook
#: (:data:`multibody.towing_kernel.LOAD_LAW_SIGNATURE`); laws are compiled eagerly with it so that one
#: compiled integrator takes any of them as a first-class function.
TOWING_LAW_SIGNATURE = LOAD_LAW_SIGNATURE
#: The nominal towing model: no effect.
no_towing_load = no_load


@njit(cache=True, inline="always")
def point_position(work):
    """P's position displacement (m) and velocity (m/s), inertial, at the last completed step.

    Parameters
    ----------
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).

    Returns
    -------
    x_point, v_point : (3,) float
        P's displacement from its reference position (m, ECI) and its velocity (m/s, ECI); views
        into ``work``.
    """
    start = int(work[W_POINT])
    return work[start + X_N:start + X_N + 3], work[start + V_N:start + V_N + 3]


@njit(cache=True, inline="always")
def last_diagnostics(work):
    """The last force evaluation's diagnostics (:data:`multibody.towing_kernel.MT_TENSION` ... layout).

    Parameters
    ----------
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).

    Returns
    -------
    diagnostics : (ST_TENSION,) float
        Main-tether tension (N), elongation (m) and rate (m/s), thrust (N), control torque (N m,
        chaser body frame), sliding variables; a view into ``work``.
    """
    start = int(work[W_DIAG])
    return work[start:start + ST_TENSION]


@njit(cache=True)
def body_position(work, q, base):
    """Absolute CoM position (m, Earth-centred inertial) of the body at ``base`` (CHASER or DEBRIS).

    Parameters
    ----------
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    q : (15,) float
        Positions, kernel layout (displacements from the reference positions, m, ECI).
    base : int
        ``CHASER`` or ``DEBRIS`` (index of the body's first coordinate).

    Returns
    -------
    r_eci : (3,) float
        CoM position from the Earth's centre, ECI (m).
    """
    row = 1 if base == CHASER else 2
    reference = work[W_REFERENCE + 3 * row:W_REFERENCE + 3 * row + 3]
    return reference + q[base:base + 3]


@njit(cache=True)
def main_tether_direction(work, q):
    """Unit vector from the main tether's chaser end A to P (inertial) and the chaser rotation
    (body -> inertial) at the state ``q``.

    Parameters
    ----------
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    q : (15,) float
        Positions, kernel layout (m, ECI; rotation vectors, rad).

    Returns
    -------
    direction_eci : (3,) float
        Unit vector A -> P, ECI (-).
    chaser_to_eci : (3, 3) float
        Chaser body -> ECI rotation.
    """
    rot_c = rotation_matrix_from_rotation_vector(q[CHASER + 3:CHASER + 6])
    attach = work[W_ATTACH_CHASER:W_TETHER]
    point, _ = point_position(work)
    d = work[W_REFERENCE:W_REFERENCE + 3] + point - body_position(work, q, CHASER) - rot_c @ attach
    return d / np.sqrt(d @ d), rot_c


def diagnostics_size(work) -> int:
    """Columns of the diagnostics rows of a packed model (main tether, thrust, torque, sliding, STs).

    Parameters
    ----------
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).

    Returns
    -------
    n_diag : int
    """
    return ST_TENSION + int(work[W_N_ATTACH])


__all__ = ["DEBRIS", "TOWING_LAW_SIGNATURE", "W_INERTIA", "W_MASSES", "W_TETHER", "main_tether_direction",
           "no_towing_load", "point_position"]
