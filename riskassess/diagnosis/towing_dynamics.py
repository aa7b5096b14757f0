"""The towing scenario's fast model: the lower-order towing model's compiled twin with effect loads.

The nominal model is :mod:`multibody.towing` (chaser, connection point P, main tether and
sub-tethers, two-body gravity, thrust law, sliding-mode attitude control; Boonrath, Singh & Botta
2024, Sec. 2.2). :func:`integrate` runs exactly the twin's scheme
(:func:`multibody.towing_kernel.twin_run`: Verlet half kick, Lie-group drift, forces at the
evaluation state with P stepped implicitly, half kick) and, before each force evaluation, calls an
effect's *towing law*; the law's loads go into the packed model's further-forces section
(:func:`multibody.towing_kernel.extra_forces`) and so act in that step, P's share inside its
implicit step. ``tests/diagnosis/test_towing.py`` checks that with no effect it reproduces
:func:`multibody.towing.run_twin` to round-off.

A towing law has the signature ``law(t, q, v, p, work, xe, h, load)``:

* ``t`` (s, the towing case's clock), ``q``, ``v`` (15,) the evaluation state in the kernel layout
  (P's entries are stale: read P from :func:`point_position`);
* ``p`` the effect's law parameters, ``work`` the packed model (geometry, masses, the last
  evaluation's diagnostics: main-tether elongation and rate, thrust);
* ``xe`` (``EXTRA_STATES``,) the effects' own states (``XE_MAXWELL``: Maxwell-branch tension (N),
  ``XE_ELONGATION``: the elongation it was last advanced at (m); ``XE_DAMPER``: a nutation damper's
  angular velocity, debris frame (rad/s)), advanced in place by the law over ``h`` (s; 0: do not
  advance);
* ``load`` (15,) the generalized forces it ADDS, kernel layout: force on P (N, inertial), chaser
  and debris force (N, inertial) and torque (N m, body frame).

Loads are evaluated once per step and held over it (as the thrust law and P's update are).
"""
from __future__ import annotations

import numpy as np
from numba import njit, types

from multibody.connection_point import V_N, X_N
from multibody.kernel import rotation_matrix_from_rotation_vector, verlet_evaluation_state
from multibody.towing_kernel import (CHASER, DEBRIS, N_COORDINATES, ST_TENSION, W_ACCEL, W_ATTACH_CHASER, W_INERTIA,
                                     W_DIAG, W_MASSES, W_POINT, W_REFERENCE, W_STEP, W_TETHER, extra_forces, packed_forces, start_forces)
from multibody.towing_kernel import W_N_ATTACH

_VECTOR = types.float64[::1]
#: numba signature of a towing law (see the module doc); laws are compiled eagerly with it so that one
#: compiled integrator takes any of them as a first-class function.
TOWING_LAW_SIGNATURE = types.void(types.float64, _VECTOR, _VECTOR, _VECTOR, _VECTOR, _VECTOR, types.float64, _VECTOR)
_LAW = types.FunctionType(TOWING_LAW_SIGNATURE)
#: Effects' own states: Maxwell-branch tension (N), the main tether's elongation when it was last
#: advanced (m), damper angular velocity (3, debris frame, rad/s).
XE_MAXWELL, XE_ELONGATION, XE_DAMPER, EXTRA_STATES = 0, 1, 2, 5


def initial_extra_states(omega_debris_body) -> np.ndarray:
    """``xe`` at t = 0: no Maxwell tension, elongation not yet seen (NaN), the damper turning with the
    debris (rad/s, debris frame).

    Parameters
    ----------
    omega_debris_body : (3,) float
        Debris inertial angular velocity at t = 0, debris body frame (rad/s).

    Returns
    -------
    xe : (EXTRA_STATES,) float
        Layout ``XE_*``.
    """
    xe = np.zeros(EXTRA_STATES)
    xe[XE_ELONGATION] = np.nan
    xe[XE_DAMPER:XE_DAMPER + 3] = omega_debris_body
    return xe


@njit(TOWING_LAW_SIGNATURE, cache=True)
def no_towing_load(t, q, v, p, work, xe, h, load):
    """The nominal towing model: no effect.

    Parameters
    ----------
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        Evaluation state, kernel layout (:mod:`multibody.towing_kernel`): P, chaser and debris
        displacements from their reference positions (m, ECI; P's are stale, see
        :func:`~riskassess.diagnosis.towing_dynamics.point_position`) and rotation vectors body -> ECI
        (rad); velocities (m/s, ECI) and angular velocities (rad/s, body frames).
    p : (j,) float
        Not used.
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (EXTRA_STATES,) float
        Effects' own states (``XE_*`` of :mod:`riskassess.diagnosis.towing_dynamics`); not used.
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: nothing.
    """
    return


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


@njit(types.void(_LAW, types.float64, _VECTOR, _VECTOR, _VECTOR, _VECTOR, _VECTOR, types.float64, _VECTOR), cache=True)
def apply_loads(law, t, q, v, p, work, xe, h, load):
    """Evaluate ``law`` at (``t``, ``q``, ``v``) into ``load`` and make it the packed model's further
    forces for the coming force evaluation (advancing the effect states ``xe`` over ``h``).

    Parameters
    ----------
    law : compiled function
        Towing law (``TOWING_LAW_SIGNATURE``, see the module doc).
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        State, kernel layout (:mod:`multibody.towing_kernel`): displacements from the reference
        positions (m, ECI) and rotation vectors body -> ECI (rad); velocities (m/s, ECI) and angular
        velocities (rad/s, body frames).
    p : (j,) float
        The law's parameters.
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
        Its further-forces section is overwritten with ``load``.
    xe : (EXTRA_STATES,) float
        Effects' own states (``XE_*``), advanced in place by the law.
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Scratch, overwritten with the law's generalized forces (N, ECI; N m, body frames).
    """
    load[:] = 0.0
    law(t, q, v, p, work, xe, h, load)
    extra = extra_forces(work)
    extra[:] = load


@njit(types.void(_LAW, _VECTOR, _VECTOR, _VECTOR, types.float64, types.int64, _VECTOR, _VECTOR, types.int64[::1],
                 types.float64[:, ::1], types.float64[:, ::1], types.float64[:, ::1], types.float64[:, ::1]), cache=True)
def integrate(law, p, q, v, t0, n_steps, work, xe, record, out_q, out_v, out_diag, out_xe):
    """Integrate the packed towing model ``work`` from (``q``, ``v``) at ``t0`` (s) over ``n_steps``
    steps with the effect ``law``; records state, diagnostics and effect states after the steps
    listed in ``record`` (increasing step indices, 0 = the initial state) into the ``out_*`` rows.

    Parameters
    ----------
    law : compiled function
        Towing law (``TOWING_LAW_SIGNATURE``).
    p : (j,) float
        The law's parameters (at least one entry).
    q, v : (15,) float
        State, kernel layout (:mod:`multibody.towing_kernel`): displacements from the reference
        positions (m, ECI) and rotation vectors body -> ECI (rad); velocities (m/s, ECI) and angular
        velocities (rad/s, body frames).
        Advanced in place.
    t0 : float
        Start time (s), the towing case's clock.
    n_steps : int
        Number of steps of ``work``'s step (s).
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (EXTRA_STATES,) float
        Effects' own states, advanced in place.
    record : (r,) int64
        Step indices to record, increasing.
    out_q, out_v : (r, 15) float
        Recorded states (kernel layout, units of ``q``, ``v``), written.
    out_diag : (r, n_diag) float
        Recorded diagnostics (:func:`diagnostics_size` columns; N, m, m/s, N m), written.
    out_xe : (r, EXTRA_STATES) float
        Recorded effect states, written.
    """
    step = work[W_STEP]
    load = np.zeros(N_COORDINATES)
    apply_loads(law, t0, q, v, p, work, xe, 0.0, load)
    start_forces(q, v, t0, work)
    acc = work[int(work[W_ACCEL]):int(work[W_ACCEL]) + N_COORDINATES]     # the stored accelerations (a view)
    k = 0
    for n in range(n_steps + 1):
        t = t0 + n * step
        while k < record.shape[0] and record[k] == n:
            out_q[k], out_v[k], out_xe[k] = q, v, xe
            out_diag[k] = packed_forces(q.copy(), v.copy(), t, work, False)[1]
            k += 1
        if n == n_steps or k == record.shape[0]:
            break
        q_next, v_half = verlet_evaluation_state(q, v, acc, step, 3, 2)
        apply_loads(law, t + step, q_next, v_half, p, work, xe, step, load)
        start_forces(q_next, v_half, t + step, work)
        q[:] = q_next
        v[:] = v_half + (0.5 * step) * acc


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


__all__ = ["DEBRIS", "EXTRA_STATES", "TOWING_LAW_SIGNATURE", "W_INERTIA", "W_MASSES", "W_TETHER", "XE_DAMPER",
           "XE_MAXWELL", "integrate", "main_tether_direction", "no_towing_load", "point_position"]
