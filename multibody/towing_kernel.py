"""Compiled forces of the lower-order towing model (Boonrath, Singh & Botta 2024, Sec. 2.2) and
its compiled twin integrator.

Bodies: the connection point P (point mass), the chaser C and the debris D (rigid bodies); the
main tether (MT) joins P to the chaser's attachment point A, the sub-tethers (ST) join P to the
debris' attachment points. Every vector is in the Earth-centred inertial frame unless named
``_body``.

Coordinate layout of the kernel and of the twin (``q`` / ``v``, 15 entries; the Exudyn object holds
entries 3-14, P's state lives in the packed model and is advanced implicitly by
:mod:`multibody.connection_point` once per step):

* 0-2  P: displacement from its reference position (m); velocity (m/s), inertial.
* 3-8  chaser: CoM displacement (m), rotation vector body->inertial (rad); CoM velocity (m/s),
  inertial, and angular velocity (rad/s), body frame.
* 9-14 debris: same as the chaser.

The generalized force on a rotational part is the torque in the body frame; the rigid bodies'
gyroscopic terms are Exudyn's own (the twin adds them as Exudyn does).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.experimental import structref

from multibody.control.attitude import desired_attitude, sliding_mode_torque
from multibody.control.thrust import THRUST_LAW, range_rate
from multibody.connection_point import STATE_SIZE, TIME, V_N, X_N, advance_point, initial_point_state
from multibody.kernel import verlet_evaluation_state
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.net import tension_only_kelvin_voigt
from multibody.orbit import add_body_gravity

N_COORDINATES = 15
P, CHASER, DEBRIS = 0, 3, 9
#: Diagnostic outputs of :func:`towing_forces`, then one sub-tether tension per attachment point.
MT_TENSION, MT_ELONGATION, MT_ELONGATION_RATE, THRUST, TORQUE, SLIDING, ST_TENSION = 0, 1, 2, 3, 4, 7, 10
#: Tether parameter indices.
K_MT, C_MT, L_MT, K_ST, C_ST, L_ST = range(6)
#: Attitude-controller parameter indices: on/off, K, G (3), boundary-layer width (3).
ATT_ON, ATT_K, ATT_G, ATT_WIDTH = 0, 1, 2, 5


@njit(cache=True, inline="always")
def _rotate(r, x, y, z):
    """r (x, y, z) for a (3, 3) matrix, as a tuple (no allocation)."""
    return (r[0, 0] * x + r[0, 1] * y + r[0, 2] * z, r[1, 0] * x + r[1, 1] * y + r[1, 2] * z,
            r[2, 0] * x + r[2, 1] * y + r[2, 2] * z)


@njit(cache=True, inline="always")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(cache=True)
def _tether_to_body(x, v, rot, base, com, point_body, k, c, rest, out_force):
    """One tether from P (at ``x``, m) to a point of the body at ``base`` (eqs. 4-5, 13-14): adds its
    pull on P and on the body to ``out_force``; returns tension (N), stretch (m), stretch rate (m/s)
    and the unit vector point->P (inertial)."""
    ax, ay, az = _rotate(rot, point_body[0], point_body[1], point_body[2])
    wx, wy, wz = _cross(v[base + 3], v[base + 4], v[base + 5], point_body[0], point_body[1], point_body[2])
    ux, uy, uz = _rotate(rot, wx, wy, wz)
    dx = x[0] - com[0] - ax
    dy = x[1] - com[1] - ay
    dz = x[2] - com[2] - az
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    dx, dy, dz = dx / length, dy / length, dz / length
    rate = (v[0] - v[base] - ux) * dx + (v[1] - v[base + 1] - uy) * dy + (v[2] - v[base + 2] - uz) * dz
    tension = tension_only_kelvin_voigt(length - rest, rate, k, c)
    fx, fy, fz = tension * dx, tension * dy, tension * dz
    out_force[0] -= fx
    out_force[1] -= fy
    out_force[2] -= fz
    out_force[base] += fx
    out_force[base + 1] += fy
    out_force[base + 2] += fz
    bx = rot[0, 0] * fx + rot[1, 0] * fy + rot[2, 0] * fz  # pull in the body frame
    by = rot[0, 1] * fx + rot[1, 1] * fy + rot[2, 1] * fz
    bz = rot[0, 2] * fx + rot[1, 2] * fy + rot[2, 2] * fz
    mx, my, mz = _cross(point_body[0], point_body[1], point_body[2], bx, by, bz)
    out_force[base + 3] += mx
    out_force[base + 4] += my
    out_force[base + 5] += mz
    return tension, length - rest, rate, dx, dy, dz


class TowingParts(NamedTuple):
    """The lower-order model's constants as :func:`towing_forces` takes them (SI; inertial frame unless
    ``_body``; n sub-tethers)."""

    reference: np.ndarray        # (3, 3) reference positions of P, chaser CoM, debris CoM (m, absolute)
    masses: np.ndarray           # (3,) m_P, m_C, m_D (kg)
    inertia_chaser: np.ndarray   # (3, 3) J_C about the CoM, chaser body frame (kg m^2)
    attach_chaser: np.ndarray    # (3,) MT attachment r_A/C, chaser body frame (m)
    attach_debris: np.ndarray    # (n, 3) ST attachments r_i/D, debris body frame (m)
    tether: np.ndarray           # (6,) k_MT (N/m), c_MT (N s/m), l_MT0 (m), k_ST, c_ST, l_ST0: K_MT ... L_ST
    mu: float                    # gravitational parameter (m^3/s^2)
    attitude: np.ndarray         # (8,) controller on (1/0), K (1/s), G (3,) (rad/s^2), width (3,) (rad/s): ATT_*


class ThrustLaw(NamedTuple):
    """The chaser's thrust law as :func:`towing_forces` takes it."""

    command: object              # compiled command, :data:`multibody.control.thrust.THRUST_LAW` (first-class function)
    along_body_z: bool           # along the chaser's body z (True) or against its inertial velocity
    params: np.ndarray           # (k,) the law's constants
    state: np.ndarray            # (j,) its states, advanced in place


@njit(cache=True)
def towing_forces(q, v, t, parts, thrust, step, advance, out_force, out_diag):
    """Generalized forces (``out_force``, (15,)) of the lower-order model at time ``t`` (s).

    MT and ST tensions (eqs. 4, 5, 13, 14), two-body gravity on P, chaser and debris (eq. 1),
    thrust (``thrust``, a :class:`ThrustLaw`: the case's compiled :mod:`multibody.control.thrust` law),
    sliding-mode torque (eqs. 7-10); the model's constants in ``parts`` (:class:`TowingParts`). The
    thrust law's state advances by ``step`` (s) when ``advance``. ``out_diag`` receives MT tension,
    elongation and rate, thrust magnitude, control torque (3, body), sliding variable (3) and the ST
    tensions.

    Parameters
    ----------
    q, v : (15,) float
        State at ``t``, kernel layout (module doc): P, chaser and debris displacements from the
        reference positions (m, inertial) and rotation vectors body -> inertial (rad); velocities
        (m/s, inertial) and angular velocities (rad/s, body frames).
    t : float
        Time (s).
    parts : TowingParts
        The model's constants.
    thrust : ThrustLaw
        The thrust law, its parameters and state.
    step : float
        The controller's sampling step (s).
    advance : bool
        Advance the thrust law's state.
    out_force : (15,) float
        Generalized forces, kernel layout (N, inertial; N m, body frames), overwritten.
    out_diag : (ST_TENSION + n,) float
        Diagnostics (N, m, m/s, N, N m body, rad/s, N), written.
    """
    reference, masses, inertia_chaser, attach_chaser, attach_debris, tether, mu, attitude = parts
    command, thrust_along_body_z, thrust_params, thrust_state = thrust
    out_force[:] = 0.0
    x = np.empty(3)  # P, absolute (m)
    com_c = np.empty(3)
    com_d = np.empty(3)
    for i in range(3):
        x[i] = reference[0, i] + q[i]
        com_c[i] = reference[1, i] + q[CHASER + i]
        com_d[i] = reference[2, i] + q[DEBRIS + i]
    rot_c = rotation_matrix_from_rotation_vector(q[CHASER + 3:CHASER + 6])
    rot_d = rotation_matrix_from_rotation_vector(q[DEBRIS + 3:DEBRIS + 6])
    tension, z, z_rate, ux, uy, uz = _tether_to_body(x, v, rot_c, CHASER, com_c, attach_chaser,
                                                     tether[K_MT], tether[C_MT], tether[L_MT], out_force)
    out_diag[MT_TENSION], out_diag[MT_ELONGATION], out_diag[MT_ELONGATION_RATE] = tension, z, z_rate
    for i in range(attach_debris.shape[0]):
        out_diag[ST_TENSION + i] = _tether_to_body(x, v, rot_d, DEBRIS, com_d, attach_debris[i],
                                                   tether[K_ST], tether[C_ST], tether[L_ST], out_force)[0]
    add_body_gravity(out_force, 0, x[0], x[1], x[2], masses[0], mu)
    add_body_gravity(out_force, CHASER, com_c[0], com_c[1], com_c[2], masses[1], mu)
    add_body_gravity(out_force, DEBRIS, com_d[0], com_d[1], com_d[2], masses[2], mu)

    r_rate = range_rate(com_d[0] - com_c[0], com_d[1] - com_c[1], com_d[2] - com_c[2], v[DEBRIS] - v[CHASER],
                        v[DEBRIS + 1] - v[CHASER + 1], v[DEBRIS + 2] - v[CHASER + 2])
    magnitude = command(t, z, z_rate, r_rate, thrust_params, thrust_state, step, advance)
    out_diag[THRUST] = magnitude
    if magnitude != 0.0:
        if thrust_along_body_z:
            dx, dy, dz = rot_c[0, 2], rot_c[1, 2], rot_c[2, 2]
        else:
            speed = math.sqrt(v[CHASER] ** 2 + v[CHASER + 1] ** 2 + v[CHASER + 2] ** 2)
            dx, dy, dz = -v[CHASER] / speed, -v[CHASER + 1] / speed, -v[CHASER + 2] / speed
        out_force[CHASER] += magnitude * dx
        out_force[CHASER + 1] += magnitude * dy
        out_force[CHASER + 2] += magnitude * dz
    if attitude[ATT_ON] > 0.0:
        u = np.empty(3)
        u[0], u[1], u[2] = ux, uy, uz
        desired = desired_attitude(u, com_c)
        torque, s = sliding_mode_torque(rot_c, v[CHASER + 3:CHASER + 6], desired, inertia_chaser,
                                        attitude[ATT_K], attitude[ATT_G:ATT_G + 3], attitude[ATT_WIDTH:ATT_WIDTH + 3])
        for i in range(3):
            out_force[CHASER + 3 + i] += torque[i]
            out_diag[TORQUE + i] = torque[i]
            out_diag[SLIDING + i] = s[i]


@njit(cache=True)
def accelerations(v, force, masses, inertia, inverse_inertia):
    """Accelerations of chaser and debris as Exudyn forms them: M^-1 (f - gyroscopic terms),
    rotation-vector Lie-group nodes; zero for P (implicit, see the module doc).

    Parameters
    ----------
    v : (15,) float
        Velocities, kernel layout: CoM velocities (m/s, inertial), angular velocities (rad/s, body frames).
    force : (15,) float
        Generalized forces, kernel layout (N, inertial; N m, body frames).
    masses : (3,) float
        m_P, m_C, m_D (kg).
    inertia, inverse_inertia : (2, 3, 3) float
        Chaser and debris inertia about the CoM (kg m^2) and its inverse, body frames.

    Returns
    -------
    (15,) float
        Accelerations, kernel layout (m/s^2, inertial; rad/s^2, body frames); zero for P.
    """
    a = np.empty(N_COORDINATES)
    a[0:3] = 0.0  # P is advanced implicitly (multibody.connection_point), not by the Verlet kicks
    for b in range(2):
        base = CHASER + 6 * b
        wx, wy, wz = v[base + 3], v[base + 4], v[base + 5]
        for i in range(3):
            a[base + i] = force[base + i] / masses[b + 1]
        jw = _rotate(inertia[b], wx, wy, wz)  # scalar tuples instead of temporaries (runs every step)
        gx, gy, gz = _cross(wx, wy, wz, jw[0], jw[1], jw[2])
        a[base + 3:base + 6] = _rotate(inverse_inertia[b], force[base + 3] - gx, force[base + 4] - gy, force[base + 5] - gz)
    return a


# ---------------------------------------------------------------------------- packed model
# One float array holds the whole model, the thrust law's state and the work buffers, so that a
# step costs one call from Python (numba's dispatch costs ~0.2 us per argument); the TowKernel
# structref pairs it with the thrust law's compiled command.
(W_N_ATTACH, W_ALONG_Z, W_STEP, W_MU, W_THRUST_PARAMS, W_N_THRUST_PARAMS, W_THRUST_STATE, W_N_THRUST_STATE,
 W_ATTACH, W_DIAG, W_FORCE, W_ACCEL, W_POINT, W_EXTRA) = range(14)
W_REFERENCE, W_MASSES, W_INERTIA, W_INVERSE, W_ATTACH_CHASER, W_TETHER, W_ATTITUDE, W_END = (
    16, 25, 28, 46, 64, 67, 73, 81)


def pack(reference, masses, inertia, attach_chaser, attach_debris, tether, mu, attitude, thrust_along_body_z,
         thrust_params, thrust_state, step, point_velocity, start_time) -> np.ndarray:
    """The packed model (see :func:`towing_forces` for the meaning of each part) with P's integrator
    state at ``start_time`` (s), P moving with ``point_velocity`` (m/s, inertial). The last section
    (:data:`W_EXTRA`, zero here) holds further generalized forces (15,) in the kernel layout that
    other stages set between steps (:func:`extra_forces`; the diagnosis' effects): added to the
    bodies' forces, and P's entries act inside its implicit step.

    Parameters
    ----------
    reference : (3, 3) float
        Reference positions of P, chaser CoM, debris CoM (m, absolute, inertial).
    masses : (3,) float
        m_P, m_C, m_D (kg).
    inertia : (2, 3, 3) float
        Chaser and debris inertia about the CoM, body frames (kg m^2).
    attach_chaser : (3,) float
        MT attachment r_A/C, chaser body frame (m).
    attach_debris : (n, 3) float
        ST attachments r_i/D, debris body frame (m).
    tether : (6,) float
        k_MT (N/m), c_MT (N s/m), l_MT0 (m), k_ST, c_ST, l_ST0 (``K_MT`` ... ``L_ST``).
    mu : float
        Gravitational parameter (m^3/s^2).
    attitude : (8,) float
        Controller on (1/0), K (1/s), G (3,) (rad/s^2), width (3,) (rad/s) (``ATT_*``).
    thrust_along_body_z : bool
        Thrust along the chaser's body z (True) or against its inertial velocity.
    thrust_params, thrust_state : (k,) and (j,) float
        The thrust law's constants and initial state (:mod:`multibody.control.thrust`).
    step : float
        Time step (s): the controller's sampling step and P's integration step.
    point_velocity : (3,) float
        P's velocity at ``start_time`` (m/s, inertial).
    start_time : float
        Time of the initial state (s).

    Returns
    -------
    (m,) float
        The packed model (layout: ``W_*`` offsets and the section offsets in its first entries).
    """
    n = len(attach_debris)
    sizes = [3 * n, len(thrust_params), len(thrust_state), ST_TENSION + n, N_COORDINATES, N_COORDINATES, STATE_SIZE,
             N_COORDINATES]
    offsets = W_END + np.concatenate([[0], np.cumsum(sizes)])
    work = np.zeros(offsets[-1])
    work[:14] = [n, float(thrust_along_body_z), step, mu, offsets[1], len(thrust_params), offsets[2],
                 len(thrust_state), offsets[0], offsets[3], offsets[4], offsets[5], offsets[6], offsets[7]]
    work[offsets[6]:offsets[7]] = initial_point_state(point_velocity, start_time)
    inertia = np.asarray(inertia, float)
    work[W_REFERENCE:W_END] = np.concatenate([np.ravel(reference), masses, inertia.ravel(), np.linalg.inv(inertia).ravel(),
                                              attach_chaser, tether, attitude])
    for start, part in zip(offsets[:3], (np.ravel(attach_debris), thrust_params, thrust_state)):
        work[start:start + len(part)] = part
    return work


_VECTOR = types.float64[::1]


@structref.register
class TowKernelType(types.StructRef):
    """numba type of :class:`TowKernel`."""


class TowKernel(structref.StructRefProxy):
    """The lower-order model as the compiled kernels take it (make it with :func:`tow_kernel`).

    Fields
    ------
    work : (m,) float    The packed model of :func:`pack` (geometry, masses, tethers, attitude control,
                         the thrust law's params and state, P's state, work buffers; SI, inertial).
    thrust : first-class function   The thrust law's compiled ``command``
                         (:data:`multibody.control.thrust.THRUST_LAW`).
    """

    @property
    def work(self) -> np.ndarray:
        """The packed model (the kernel's own array, not a copy)."""
        return _work_of(self)


@njit(cache=True)
def _work_of(tow):
    return tow.work


structref.define_proxy(TowKernel, TowKernelType, ["work", "thrust"])
#: numba type of the kernels' model argument.
TOW_KERNEL = TowKernelType([("work", _VECTOR), ("thrust", THRUST_LAW)])


@njit(TOW_KERNEL(_VECTOR, THRUST_LAW), cache=True)
def tow_kernel(work, thrust):
    """The :class:`TowKernel` of the packed model ``work`` (:func:`pack`, shared, not copied) and the
    thrust law ``thrust`` (a compiled ``command`` of :mod:`multibody.control.thrust_laws`).

    Parameters
    ----------
    work : (w,) float
        Packed model (:func:`pack`).
    thrust : first-class function
        The thrust law's compiled command (:data:`multibody.control.thrust.THRUST_LAW`).
    """
    tow = structref.new(TOW_KERNEL)
    tow.work = work
    tow.thrust = thrust
    return tow


@njit(cache=True, inline="always")
def _section(work, index, size_index):
    start = int(work[index])
    return work[start:start + int(work[size_index])]


@njit(cache=True)
def _attachments(q, v, reference, attach_chaser, attach_debris):
    """Main-tether end on the chaser, then the sub-tether ends on the debris: positions relative
    to P's reference position (m) and velocities (m/s), inertial, (1 + n, 3) each."""
    n = attach_debris.shape[0]
    points, velocities = np.empty((n + 1, 3)), np.empty((n + 1, 3))
    for b, base in ((1, CHASER), (2, DEBRIS)):
        rot = rotation_matrix_from_rotation_vector(q[base + 3:base + 6])
        for i in range(1 if b == 1 else n):
            r = attach_chaser if b == 1 else attach_debris[i]
            row = 0 if b == 1 else i + 1
            arm = _rotate(rot, r[0], r[1], r[2])  # scalar tuples: this runs every step, allocations dominated it
            wx, wy, wz = _cross(v[base + 3], v[base + 4], v[base + 5], r[0], r[1], r[2])
            arm_rate = _rotate(rot, wx, wy, wz)
            for a in range(3):
                points[row, a] = reference[b, a] - reference[0, a] + q[base + a] + arm[a]
                velocities[row, a] = v[base + a] + arm_rate[a]
    return points, velocities


@njit(cache=True)
def _advance_connection_point(q, v, t, work, attach):
    """If ``t`` is a new step time: the bodies' velocities at ``t`` predicted from the step's
    evaluation (half-step) velocities ``v`` and the last stored accelerations, v + h/2 a (so the
    implicit P and the tether dampers see chaser, debris and P at the same instant: with the
    half-step velocities the damper force would be O(h) off); then P stepped implicitly to ``t``
    (:func:`multibody.connection_point.advance_point`). Returns the velocities to evaluate the
    forces with, P's entries (also in ``q``, ``v``) from its state at ``t``."""
    n = attach.shape[0]
    reference = work[W_REFERENCE:W_MASSES].reshape((3, 3))
    tether = work[W_TETHER:W_ATTITUDE]
    state = work[int(work[W_POINT]):int(work[W_POINT]) + STATE_SIZE]
    step = work[W_STEP]
    v_eval = v
    if t > state[TIME] + 0.5 * step:
        v_eval, half, acc = np.empty(N_COORDINATES), 0.5 * (t - state[TIME]), int(work[W_ACCEL])
        for i in range(N_COORDINATES):
            v_eval[i] = v[i] + half * work[acc + i]
        points, velocities = _attachments(q, v_eval, reference, work[W_ATTACH_CHASER:W_TETHER], attach)
        stiffness, damping, rest = np.full(n + 1, tether[K_ST]), np.full(n + 1, tether[C_ST]), np.full(n + 1, tether[L_ST])
        stiffness[0], damping[0], rest[0] = tether[K_MT], tether[C_MT], tether[L_MT]
        advance_point(state, t, step, work[W_MASSES], reference[0], work[W_MU], points, velocities,
                      stiffness, damping, rest, extra_forces(work)[0:3])
    q[0:3] = state[X_N:X_N + 3]
    v[0:3] = state[V_N:V_N + 3]
    v_eval[0:3] = state[V_N:V_N + 3]
    return v_eval


@njit(cache=True)
def packed_forces(q, v, t, tow, advance):
    """:func:`towing_forces` of the packed model ``tow`` (:class:`TowKernel`); the force and diagnostics
    land in its ``work``. P's entries of ``q`` and ``v`` are overwritten with its implicit state at ``t``
    (advanced first if ``t`` is a new step time, the forces then taken at the bodies' predicted
    velocities at ``t``, see :func:`_advance_connection_point`).

    Parameters
    ----------
    q, v : (15,) float
        State, kernel layout (module doc); P's entries are overwritten with its implicit state at ``t``.
    t : float
        Time (s).
    tow : TowKernel
        The packed model and its thrust law (:func:`tow_kernel`).
    advance : bool
        Advance the thrust law's state (once per new step time).

    Returns
    -------
    force : (15,) float
        Generalized forces, kernel layout (N, inertial; N m, body frames); a view into ``tow.work``.
    diag : (ST_TENSION + n,) float
        Diagnostics (:func:`towing_forces`); a view into ``tow.work``.
    """
    work, thrust = tow.work, tow.thrust
    n = int(work[W_N_ATTACH])
    attach = work[int(work[W_ATTACH]):int(work[W_ATTACH]) + 3 * n].reshape((n, 3))
    v_eval = _advance_connection_point(q, v, t, work, attach)
    diag = work[int(work[W_DIAG]):int(work[W_DIAG]) + ST_TENSION + n]
    force = work[int(work[W_FORCE]):int(work[W_FORCE]) + N_COORDINATES]
    parts = TowingParts(work[W_REFERENCE:W_MASSES].reshape((3, 3)), work[W_MASSES:W_INERTIA],
                        work[W_INERTIA:W_INERTIA + 9].reshape((3, 3)), work[W_ATTACH_CHASER:W_TETHER], attach,
                        work[W_TETHER:W_ATTITUDE], work[W_MU], work[W_ATTITUDE:W_END])
    law = ThrustLaw(thrust, work[W_ALONG_Z] > 0.0, _section(work, W_THRUST_PARAMS, W_N_THRUST_PARAMS),
                    _section(work, W_THRUST_STATE, W_N_THRUST_STATE))
    towing_forces(q, v_eval, t, parts, law, work[W_STEP], advance, force, diag)
    extra = extra_forces(work)
    for i in range(3, N_COORDINATES):
        force[i] += extra[i]
    return force, diag


@njit(cache=True, inline="always")
def extra_forces(work):
    """The packed model's further generalized forces (15,), kernel layout (a view: set them in place).

    Parameters
    ----------
    work : (m,) float
        The packed model (:func:`pack`).

    Returns
    -------
    (15,) float
        View of its extra forces (N, inertial; N m, body frames), kernel layout.
    """
    start = int(work[W_EXTRA])
    return work[start:start + N_COORDINATES]


@njit(cache=True)
def body_forces(q_bodies, v_bodies, t, tow, advance):
    """The packed model's generalized forces on chaser and debris (12,) for Exudyn's object, which
    holds only their coordinates (entries 3-14 of the kernel layout); P comes from ``tow``; the
    thrust law's state advances when ``advance``.

    Parameters
    ----------
    q_bodies, v_bodies : (12,) float
        Chaser and debris entries (3-14) of the kernel layout's ``q`` and ``v`` (module doc).
    t : float
        Time (s).
    tow : TowKernel
        The packed model and its thrust law.
    advance : bool
        Advance the thrust law (and P, if ``t`` is a new step time).
    """
    q, v = np.zeros(N_COORDINATES), np.zeros(N_COORDINATES)
    q[3:], v[3:] = q_bodies, v_bodies
    force, _ = packed_forces(q, v, t, tow, advance)
    _store_accelerations(v, force, tow.work)  # as the twin does, for the next step's velocity prediction
    return force[3:].copy()


@njit(cache=True)
def sampled_state(q_bodies, v_bodies, t, tow):
    """Full state (15,) each and diagnostics at ``t`` from the bodies' state and P's stored state
    (thrust law not advanced).

    Parameters
    ----------
    q_bodies, v_bodies : (12,) float
        Chaser and debris entries (3-14) of the kernel layout's ``q`` and ``v`` (module doc).
    t : float
        Time (s).
    tow : TowKernel
        The packed model and its thrust law.
    """
    q, v = np.zeros(N_COORDINATES), np.zeros(N_COORDINATES)
    q[3:], v[3:] = q_bodies, v_bodies
    diag = packed_forces(q, v, t, tow, False)[1]
    return q, v, diag.copy()


@njit(cache=True)
def _store_accelerations(v, force, work):
    a = accelerations(v, force, work[W_MASSES:W_INERTIA], work[W_INERTIA:W_INVERSE].reshape((2, 3, 3)),
                      work[W_INVERSE:W_ATTACH_CHASER].reshape((2, 3, 3)))
    start = int(work[W_ACCEL])
    work[start:start + N_COORDINATES] = a


@njit(cache=True)
def start_forces(q, v, t, tow):
    """Force at the state (q, v) at time ``t`` (s), the thrust law advanced (as at every step); stores
    the accelerations in ``tow.work`` for the next step; returns the force (15,).

    Parameters
    ----------
    q, v : (15,) float
        State, kernel layout (module doc); P's entries are overwritten with its implicit state at ``t``.
    t : float
        Time (s).
    tow : TowKernel
        The packed model and its thrust law.
    """
    force, _ = packed_forces(q, v, t, tow, True)
    _store_accelerations(v, force, tow.work)
    return force


# ---------------------------------------------------------------------------- the Verlet loop
#: numba signature of a load law ``law(t, q, v, p, work, xe, h, load)``: the further generalized
#: forces a caller adds each step (:func:`verlet_run`; the diagnosis' effects): ``t`` (s), the
#: evaluation state ``q``, ``v`` (15,) in the kernel layout (P's entries stale: read P from ``work``),
#: the law's parameters ``p``, the packed model ``work``, the caller's own states ``xe`` advanced in
#: place over ``h`` (s; 0: do not advance), ``load`` (15,) the loads it ADDS (forces N, inertial;
#: torques N m, body frames). Laws are compiled eagerly with it (first-class functions).
LOAD_LAW_SIGNATURE = types.void(types.float64, _VECTOR, _VECTOR, _VECTOR, _VECTOR, _VECTOR, types.float64, _VECTOR)
LOAD_LAW = types.FunctionType(LOAD_LAW_SIGNATURE)


@njit(LOAD_LAW_SIGNATURE, cache=True)
def no_load(t, q, v, p, work, xe, h, load):
    """The nominal model: no further loads (:data:`LOAD_LAW_SIGNATURE`; every argument unused).

    Parameters
    ----------
    t : float
        Time (s).
    q, v : (15,) float
        State, kernel layout (module doc): displacements from the reference positions (m, inertial)
        and rotation vectors body -> inertial (rad); velocities (m/s, inertial) and angular
        velocities (rad/s, body frames).
    p : (j,) float
        The law's parameters.
    work : (w,) float
        Packed model (:func:`pack`).
    xe : (e,) float
        The caller's own states.
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: nothing.
    """
    return


@njit(types.void(LOAD_LAW, types.float64, _VECTOR, _VECTOR, _VECTOR, _VECTOR, _VECTOR, types.float64, _VECTOR),
      cache=True)
def apply_loads(law, t, q, v, p, work, xe, h, load):
    """Evaluate ``law`` at (``t``, ``q``, ``v``) into ``load`` and make it the packed model's further
    forces for the coming force evaluation (advancing the states ``xe`` over ``h``).

    Parameters
    ----------
    law : first-class function
        Load law (:data:`LOAD_LAW_SIGNATURE`).
    t, q, v, p, xe, h
        As the law takes them (:func:`no_load`); ``xe`` advanced in place by the law.
    work : (w,) float
        Packed model (:func:`pack`); its further-forces section is overwritten with ``load``.
    load : (15,) float
        Scratch, overwritten with the law's generalized forces (N, inertial; N m, body frames).
    """
    load[:] = 0.0
    law(t, q, v, p, work, xe, h, load)
    extra = extra_forces(work)
    extra[:] = load


_MATRIX = types.float64[:, ::1]


@njit(types.void(TOW_KERNEL, LOAD_LAW, _VECTOR, _VECTOR, _VECTOR, types.float64, types.int64, _VECTOR,
                  types.int64[::1], _MATRIX, _MATRIX, _MATRIX, _MATRIX), cache=True)
def verlet_run(tow, law, p, q, v, t0, n_steps, xe, record, out_q, out_v, out_diag, out_xe):
    """Integrate the lower-order model ``tow`` from (``q``, ``v``) (15,) each at ``t0`` (s) with exactly
    the scheme Exudyn's VelocityVerlet applies to the coupled object: half kick, drift (Lie-group
    update of the rotation vectors, :func:`multibody.kernel.verlet_evaluation_state`), the load law
    ``law`` (:data:`LOAD_LAW_SIGNATURE`, parameters ``p``, states ``xe``; :func:`no_load` for the
    nominal model) then the forces at the new state (P stepped implicitly), half kick. Records
    state, diagnostics (at the recorded state, thrust law not advanced) and ``xe`` after the steps
    listed in ``record`` (non-decreasing step indices, 0 = the initial state) into the ``out_*``
    rows (record indices beyond ``n_steps`` are not reached). ``q``, ``v``, ``xe`` and ``tow.work``
    are updated in place.

    Parameters
    ----------
    tow : TowKernel
        The packed model and its thrust law (:func:`tow_kernel`).
    law : first-class function
        Load law (:data:`LOAD_LAW_SIGNATURE`), :func:`no_load` for none.
    p : (j,) float
        The law's parameters (at least one entry).
    q, v : (15,) float
        State, kernel layout (module doc): displacements from the reference positions (m, inertial)
        and rotation vectors body -> inertial (rad); velocities (m/s, inertial) and angular
        velocities (rad/s, body frames).
        Advanced in place.
    t0 : float
        Start time (s).
    n_steps : int
        Number of steps of the model's step ``work[W_STEP]`` (s).
    xe : (e,) float
        The law's own states (at least one entry), advanced in place.
    record : (r,) int64
        Step indices to record, non-decreasing.
    out_q, out_v : (r, 15) float
        Recorded states (kernel layout, units of ``q``, ``v``), written.
    out_diag : (r, ST_TENSION + n) float
        Recorded diagnostics (:func:`towing_forces`: N, m, m/s, N, N m, rad/s, N), written.
    out_xe : (r, e) float
        Recorded ``xe``, written.
    """
    work = tow.work
    step = work[W_STEP]
    load = np.zeros(N_COORDINATES)
    apply_loads(law, t0, q, v, p, work, xe, 0.0, load)
    start_forces(q, v, t0, tow)
    acc = work[int(work[W_ACCEL]):int(work[W_ACCEL]) + N_COORDINATES]     # the stored accelerations (a view)
    k = 0
    for n in range(n_steps + 1):
        t = t0 + n * step
        while k < record.shape[0] and record[k] == n:
            out_q[k], out_v[k], out_xe[k] = q, v, xe
            out_diag[k] = packed_forces(q.copy(), v.copy(), t, tow, False)[1]
            k += 1
        if n == n_steps:
            break
        q_next, v_half = verlet_evaluation_state(q, v, acc, step, 3, 2)
        apply_loads(law, t + step, q_next, v_half, p, work, xe, step, load)
        start_forces(q_next, v_half, t + step, tow)
        q[:] = q_next
        for i in range(N_COORDINATES):
            v[i] = v_half[i] + (0.5 * step) * acc[i]
