"""Compiled sums behind one output sample of the impact recorder (:mod:`multibody.recorder`).

A sample used to be some 200 small NumPy operations (about 0.6 ms, 12 % of the reference case's
run at one sample every 10 steps); :func:`sample_row` now computes the whole row in one compiled call
(:func:`net_sums` and :func:`body_sample` in one pass each; the joint loads by :func:`connector_load_into`, Exudyn's
connector law, which replaced eight ``GetObjectOutput`` calls a sample). Same definitions as before; frames in the
names, SI units.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit
from numba.experimental import structref

from multibody.jit_cache import UnliteralStructRef
from multibody.load_filter import advance, rest_at
from multibody.kernel import BENDING_ELASTIC, CONTACT_DISSIPATED, CONTACT_ELASTIC, THREAD_DISSIPATED, THREAD_ELASTIC
from multibody.maths.linalg3 import cross3, matmat3, mattmat3, mattvec3, matvec3
from multibody.maths.rotations import (half_rotation_matrix_into, rotation_matrix_from_rotation_vector_into,
                                      rotation_vector_from_matrix_into)
from multibody.node_frame import body_state_into


@njit(cache=True)
def net_sums(q, qt, offset, node_stride, coordinate_stride, reference, masses, n_orbit, out):
    """Net totals into ``out`` (8,): kinetic energy (J), Clohessy-Wiltshire potential
    :math:`\\sum m\\,\\tfrac12 n^2 (z^2 - 3x^2)` (J), linear momentum (3, kg m/s) and angular momentum
    about the LVLH origin (3, kg m^2/s); read from the net's state where it lives (no (n, 3) copies: they
    were 16 us of a sample's 90 us, and the snapshots that need them are one sample in twenty).

    Parameters
    ----------
    q, qt : (M,) float
        Node displacements from ``reference`` (m) and velocities (m/s), LVLH; node ``i``'s coordinate
        ``d`` at ``offset + i * node_stride + d * coordinate_stride``.
    offset, node_stride, coordinate_stride : int
    reference : (n, 3) float
        Node reference positions (m), LVLH.
    masses : (n,) float
        Node masses (kg).
    n_orbit : float
        Mean motion (rad/s); 0 without orbit.
    out : (8,) float
        Output.

    Returns
    -------
    float
        The sum of the net's coordinates and velocities: finite only when every one of them is (a
        finiteness check for the caller; a finite state whose sum overflows reads as not finite).
    """
    # the sums in local variables (the same additions in the same order as into ``out``): stores through
    # ``out`` inside the loop kept every sum in memory, about twice the time
    kinetic = potential = p0 = p1 = p2 = l0 = l1 = l2 = 0.0
    checksum = 0.0
    for i in range(masses.shape[0]):
        m = masses[i]
        base = offset + i * node_stride
        u0, u1, u2 = q[base], q[base + coordinate_stride], q[base + 2 * coordinate_stride]
        v0, v1, v2 = qt[base], qt[base + coordinate_stride], qt[base + 2 * coordinate_stride]
        checksum += (u0 + u1 + u2) + (v0 + v1 + v2)
        x0, x1, x2 = reference[i, 0] + u0, reference[i, 1] + u1, reference[i, 2] + u2
        px, py, pz = m * v0, m * v1, m * v2
        kinetic += 0.5 * (px * v0 + py * v1 + pz * v2)
        potential += m * 0.5 * n_orbit * n_orbit * (x2 * x2 - 3.0 * x0 * x0)
        p0 += px
        p1 += py
        p2 += pz
        l0 += x1 * pz - x2 * py
        l1 += x2 * px - x0 * pz
        l2 += x0 * py - x1 * px
    out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7] = kinetic, potential, p0, p1, p2, l0, l1, l2
    return checksum


class SampledBodies(NamedTuple):
    """The bodies' constants a sample needs (nb bodies)."""

    index: np.ndarray                 # (nb,) int64 where body b's coordinates start in Exudyn's vectors
    reference_com_lvlh: np.ndarray    # (nb, 3) reference CoM (m), LVLH
    mass: np.ndarray                  # (nb,) (kg)
    inertia_body: np.ndarray          # (nb, 3, 3) about the CoM, body frame (kg m^2)
    debris_mask: np.ndarray           # (nb,) int64, 1 for debris bodies
    chaser: int                       # the chaser's index, -1 for none
    node_to_body: np.ndarray          # (nb, 3, 3) each body's Exudyn node frame in its body frame (multibody.node_frame)


class SampledJoints(NamedTuple):
    """The joints' constants a sample needs (nj joints)."""

    parent: np.ndarray                # (nj,) int64 parent body
    child: np.ndarray                 # (nj,) int64 child body
    joint_to_parent: np.ndarray       # (nj, 3, 3) joint frame in the parent's body frame
    joint_to_child: np.ndarray        # (nj, 3, 3) joint frame in the child's body frame (unrotated)
    point_parent: np.ndarray          # (nj, 3) joint point, parent body frame (m)
    point_child: np.ndarray           # (nj, 3) joint point, child body frame (m)
    stiffness: np.ndarray             # (nj, 6) penalty (N/m) and torsion (N m/rad) diagonals, joint frame
    damping: np.ndarray               # (nj, 6) their dampers' diagonals (N s/m, N m s/rad), joint frame


class BodySample(NamedTuple):
    """One sample's body and joint values, written by :func:`body_sample` (preallocated)."""

    com_lvlh: np.ndarray              # (nb, 3) CoM (m)
    velocity_lvlh: np.ndarray         # (nb, 3) CoM velocity (m/s)
    body_to_lvlh: np.ndarray          # (nb, 3, 3) attitude
    omega_body: np.ndarray            # (nb, 3) angular velocity (rad/s), body frame
    force_lvlh: np.ndarray            # (nb, 3) mean contact force since the last sample (N)
    moment_lvlh: np.ndarray           # (nb, 3) its moment about the CoM (N m)
    force_body: np.ndarray            # (nb, 3) the same, body frame
    moment_body: np.ndarray           # (nb, 3)
    body_totals: np.ndarray           # (nb, 9) translational and rotational kinetic energy (J), CW potential (J),
    #                                   linear momentum (3, kg m/s), angular momentum about the LVLH origin (3, kg m^2/s)
    joint_rotation: np.ndarray        # (nj, 3) relative rotation vector (rad), joint frame
    joint_rate: np.ndarray            # (nj, 3) relative rate (rad/s), joint frame
    joint_energy: np.ndarray          # (nj,) elastic energy of the penalty spring (J)
    summary: np.ndarray               # (17,) debris CoM (3, m) and CoM velocity (3, m/s), LVLH; debris translational
    #                                   and rotational kinetic energy (J); CW potential of all bodies (J); the chaser's
    #                                   kinetic energy (J); linear (3) and angular (3) momentum of all bodies (as
    #                                   body_totals); joint elastic energy (J)
    node_to_lvlh: np.ndarray          # (nb, 3, 3) work space: each body's Exudyn node attitude (not recorded)
    omega_lvlh: np.ndarray            # (nb, 3) work space: angular velocity (rad/s), LVLH (not recorded)
    joint_force: np.ndarray           # (nj, 3) the connector's force on the child, joint frame (N): the load the parent
    #                                   exerts on the child (:func:`connector_load_into`); zero once released
    joint_moment: np.ndarray          # (nj, 3) its moment (N m), joint frame


@njit(cache=True)
def connector_load_into(frame, offset_joint, rotation, relative_velocity, relative_omega, stiffness, damping, force,
                        moment):
    """The load the parent exerts on the child through a penalty joint (Exudyn's
    ``ObjectConnectorRigidBodySpringDamper`` with ``useIntrinsicFormulation``, whose ``ForceLocal`` and
    ``TorqueLocal`` outputs this is with the sign reversed), into ``force`` (N) and ``moment`` (N m), joint frame.

    The intrinsic formulation (Exudyn's source, ``CObjectConnectorRigidBodySpringDamper::ComputeSpringForceTorque``
    and ``EXUlie::LogSE3Vector``): the relative motion of the child's joint frame to the parent's is the SE(3)
    logarithm (rotation vector ``r``, displacement ``T^-T(r) t`` with ``t`` the offset in the parent's joint frame
    and ``T^-1`` the inverse tangent operator of SO(3)); velocities are read in the mid frame
    ``frame Exp(r / 2)``; the connector's force is ``K u + D v`` on the six axes. Reproduces Exudyn's outputs to
    round-off (checked against ``GetObjectOutput`` on the reference run: moments within 1e-8, forces within 1e-5 N,
    the round-off of the positions 40 m from the origin times the 1e9 N/m penalty; tests/multibody/test_joint_loads.py).

    Parameters
    ----------
    frame : (3, 3) float
        The parent's joint frame in LVLH (columns: its axes).
    offset_joint : (3,) float
        The child's joint point relative to the parent's, parent's joint frame (m).
    rotation : (3,) float
        Rotation vector of the child's joint frame relative to the parent's (rad).
    relative_velocity, relative_omega : (3,) float
        The child's joint point's velocity (m/s) and angular velocity (rad/s) relative to the parent's, LVLH.
    stiffness, damping : (6,) float
        The connector's diagonal stiffness (N/m, N m/rad) and damping (N s/m, N m s/rad), joint frame.
    force, moment : (3,) float
        Output.
    """
    v, w = mid_frame_velocities(frame, rotation, relative_velocity, relative_omega)
    penalty_load_into(offset_joint, rotation, v, w, stiffness, damping, force, moment)


@njit(cache=True)
def penalty_load_into(offset_joint, rotation, velocity_mid, omega_mid, stiffness, damping, force, moment):
    """The connector law of :func:`connector_load_into` from the relative motion already in the joint's frames:
    ``force = -(K u + D v)``, ``moment = -(K r + D w)`` with ``u = T^-T(r) t`` (N, N m, joint frame).

    Parameters
    ----------
    offset_joint : (3,) float
        The child's joint point relative to the parent's, parent's joint frame (m).
    rotation : (3,) float
        Rotation vector of the child's joint frame relative to the parent's (rad).
    velocity_mid, omega_mid : (3,) float
        Relative velocity (m/s) and angular velocity (rad/s), mid frame (:func:`mid_frame_velocities`).
    stiffness, damping : (6,) float
    force, moment : (3,) float
        Output.
    """
    r0, r1, r2 = rotation[0], rotation[1], rotation[2]
    t0, t1, t2 = offset_joint[0], offset_joint[1], offset_joint[2]
    angle2 = r0 * r0 + r1 * r1 + r2 * r2
    # T^-1(r)^T t = b t - (r x t) / 2 + c r (r . t), Exudyn's TExpSO3Inv (its series below 0.02 rad)
    b, c = 1.0, 0.0
    if angle2 > 0.0:
        angle = math.sqrt(angle2)
        if angle <= 0.02:
            c = 1.0 / 12 + angle2 / 720 + angle2 * angle2 / 30240
            b = 1.0 - c * angle2
        else:
            half = 0.5 * angle
            b = half / math.tan(half)
            c = (1.0 - b) / angle2
    along = r0 * t0 + r1 * t1 + r2 * t2
    u0 = b * t0 - 0.5 * (r1 * t2 - r2 * t1) + c * r0 * along
    u1 = b * t1 - 0.5 * (r2 * t0 - r0 * t2) + c * r1 * along
    u2 = b * t2 - 0.5 * (r0 * t1 - r1 * t0) + c * r2 * along
    force[0] = -(stiffness[0] * u0 + damping[0] * velocity_mid[0])
    force[1] = -(stiffness[1] * u1 + damping[1] * velocity_mid[1])
    force[2] = -(stiffness[2] * u2 + damping[2] * velocity_mid[2])
    for d in range(3):
        moment[d] = -(stiffness[3 + d] * rotation[d] + damping[3 + d] * omega_mid[d])


@njit(cache=True)
def mid_frame_velocities(frame, rotation, relative_velocity, relative_omega):
    """The relative velocities a penalty joint's dampers see: read in the mid frame ``frame Exp(r / 2)`` of Exudyn's
    intrinsic formulation (:func:`connector_load_into`).

    Parameters
    ----------
    frame : (3, 3) float
        The parent's joint frame in LVLH (columns: its axes).
    rotation : (3,) float
        Rotation vector of the child's joint frame relative to the parent's (rad).
    relative_velocity, relative_omega : (3,) float
        The child's joint point's velocity (m/s) and angular velocity (rad/s) relative to the parent's, LVLH.

    Returns
    -------
    velocity_mid, omega_mid : (3,) float
        The same, mid frame (m/s, rad/s).
    """
    half_turn = np.empty((1, 3, 3))
    rotation_matrix_from_rotation_vector_into(0.5 * rotation[0], 0.5 * rotation[1], 0.5 * rotation[2], half_turn, 0)
    mid = matmat3(frame, half_turn[0])
    return mattvec3(mid, relative_velocity), mattvec3(mid, relative_omega)


@njit(cache=True)
def joint_relative_motion_into(j, joints, com, vel, rot, omega, rotation_joint):
    """Joint ``j``'s relative motion from its bodies' states; its relative rotation vector into ``rotation_joint``.

    Parameters
    ----------
    j : int
    joints : SampledJoints
    com, vel : (nb, 3) float
        CoM (m) and CoM velocity (m/s), LVLH.
    rot : (nb, 3, 3) float
        Body to LVLH.
    omega : (nb, 3) float
        Angular velocity (rad/s), body frame.
    rotation_joint : (3,) float
        Output: rotation vector of the child's joint frame relative to the parent's (rad), joint frame.

    Returns
    -------
    frame : (3, 3) float
        The parent's joint frame in LVLH.
    offset_joint : (3,) float
        The child's joint point relative to the parent's (m), parent's joint frame.
    relative_velocity, relative_omega : (3,) float
        The child's joint point's velocity (m/s) and angular velocity (rad/s) relative to the parent's, LVLH.
    """
    p, c = joints.parent[j], joints.child[j]
    frame = matmat3(rot[p], joints.joint_to_parent[j])  # joint frame (parent side) in LVLH
    relative = mattmat3(frame, matmat3(rot[c], joints.joint_to_child[j]))
    rotation_vector_from_matrix_into(relative, rotation_joint)
    w = matvec3(rot[c], omega[c]) - matvec3(rot[p], omega[p])
    arm_child, arm_parent = matvec3(rot[c], joints.point_child[j]), matvec3(rot[p], joints.point_parent[j])
    offset = arm_child + com[c] - arm_parent - com[p]
    relative_velocity = (vel[c] + cross3(matvec3(rot[c], omega[c]), arm_child) - vel[p]
                         - cross3(matvec3(rot[p], omega[p]), arm_parent))
    return frame, mattvec3(frame, offset), relative_velocity, w


def body_sample_buffers(n_bodies: int, n_joints: int) -> BodySample:
    """Zeroed :class:`BodySample` arrays.

    Parameters
    ----------
    n_bodies, n_joints : int
    """
    nb, nj = n_bodies, n_joints
    return BodySample(np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3, 3)), np.zeros((nb, 3)),
                      np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 9)),
                      np.zeros((nj, 3)), np.zeros((nj, 3)), np.zeros(nj), np.zeros(17), np.zeros((nb, 3, 3)),
                      np.zeros((nb, 3)), np.zeros((nj, 3)), np.zeros((nj, 3)))


@njit(cache=True)
def body_sample(q, qt, bodies, joints, active, impulse, interval, n_orbit, out):
    """Body and joint states of one sample, into ``out`` (preallocated).

    Parameters
    ----------
    q, qt : (N,) float
        Exudyn's coordinates and velocities; body ``b`` starts at ``bodies.index[b]`` (CoM displacement
        (m), rotation vector node->LVLH (rad); CoM velocity (m/s), omega (rad/s, node frame)); the
        sample turns the node's attitude and rate into the body's (:func:`multibody.node_frame.body_state_into`).
    bodies : SampledBodies
    joints : SampledJoints
    active : (nj,) float
        1.0 for a joint in place, 0.0 once released.
    impulse : (nb, 6) float
        Contact impulse and angular impulse about the CoM since the last sample (N s, N m s), LVLH;
        zeroed here.
    interval : float
        Time since the last sample (s); 0 gives zero contact force.
    n_orbit : float
        Mean motion (rad/s) of the Clohessy-Wiltshire potential; 0 without orbit.
    out : BodySample
    """
    body_reference, body_mass, inertia = bodies.reference_com_lvlh, bodies.mass, bodies.inertia_body
    body_index, debris_mask, chaser = bodies.index, bodies.debris_mask, bodies.chaser
    joint_parent, joint_stiffness = joints.parent, joints.stiffness
    com, vel, rot, omega = out.com_lvlh, out.velocity_lvlh, out.body_to_lvlh, out.omega_body
    force_lvlh, moment_lvlh, force_body, moment_body = out.force_lvlh, out.moment_lvlh, out.force_body, out.moment_body
    body_totals, joint_rotation, joint_rate = out.body_totals, out.joint_rotation, out.joint_rate
    joint_energy, summary = out.joint_energy, out.summary
    node_to_body, node_to_lvlh, omega_lvlh = bodies.node_to_body, out.node_to_lvlh, out.omega_lvlh
    nb = body_mass.shape[0]
    for b in range(nb):
        body_state_into(q, qt, body_index[b], b, body_reference, node_to_body, com, vel, node_to_lvlh, rot,
                        omega_lvlh, omega)
        for d in range(3):
            force_lvlh[b, d] = impulse[b, d] / interval if interval > 0.0 else 0.0
            moment_lvlh[b, d] = impulse[b, 3 + d] / interval if interval > 0.0 else 0.0
        force_body[b] = mattvec3(rot[b], force_lvlh[b])
        moment_body[b] = mattvec3(rot[b], moment_lvlh[b])
        for d in range(6):
            impulse[b, d] = 0.0
        m = body_mass[b]
        spin = matvec3(inertia[b], omega[b])  # body frame
        body_totals[b, 0] = 0.5 * m * (vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2)
        body_totals[b, 1] = 0.5 * (omega[b, 0] * spin[0] + omega[b, 1] * spin[1] + omega[b, 2] * spin[2])
        body_totals[b, 2] = m * 0.5 * n_orbit * n_orbit * (com[b, 2] ** 2 - 3.0 * com[b, 0] ** 2)
        spin_lvlh = matvec3(rot[b], spin)
        for d in range(3):
            body_totals[b, 3 + d] = m * vel[b, d]
        body_totals[b, 6] = m * (com[b, 1] * vel[b, 2] - com[b, 2] * vel[b, 1]) + spin_lvlh[0]
        body_totals[b, 7] = m * (com[b, 2] * vel[b, 0] - com[b, 0] * vel[b, 2]) + spin_lvlh[1]
        body_totals[b, 8] = m * (com[b, 0] * vel[b, 1] - com[b, 1] * vel[b, 0]) + spin_lvlh[2]
    for j in range(joint_parent.shape[0]):
        frame, offset_joint, relative_velocity, w = joint_relative_motion_into(j, joints, com, vel, rot, omega,
                                                                               joint_rotation[j])
        joint_rate[j] = mattvec3(frame, w)
        energy = 0.0
        for d in range(3):
            energy += joint_stiffness[j, d] * offset_joint[d] ** 2 + joint_stiffness[j, 3 + d] * joint_rotation[j, d] ** 2
        joint_energy[j] = 0.5 * energy * active[j]
        if active[j] == 0.0:
            out.joint_force[j] = 0.0   # released: the connector is off
            out.joint_moment[j] = 0.0
            continue
        connector_load_into(frame, offset_joint, joint_rotation[j], relative_velocity, w, joint_stiffness[j],
                            joints.damping[j], out.joint_force[j], out.joint_moment[j])
    for k in range(17):
        summary[k] = 0.0
    debris_mass = 0.0
    for b in range(nb):
        if debris_mask[b]:
            debris_mass += body_mass[b]
            for d in range(3):
                summary[d] += body_mass[b] * com[b, d]
                summary[3 + d] += body_mass[b] * vel[b, d]
            summary[6] += body_totals[b, 0]
            summary[7] += body_totals[b, 1]
        summary[8] += body_totals[b, 2]
        for d in range(6):
            summary[10 + d] += body_totals[b, 3 + d]
    if debris_mass > 0.0:
        for d in range(6):
            summary[d] /= debris_mass
    if chaser >= 0:
        summary[9] = body_totals[chaser, 0] + body_totals[chaser, 1]
    for j in range(joint_parent.shape[0]):
        summary[16] += joint_energy[j]


#: Starts of the columns :func:`sample_row` writes in a sample's flat row (``RecorderModel.columns``, in this order):
#: time, debris CoM, debris CoM velocity, the first energy term, the energy total, linear and angular momentum.
(COLUMN_TIME, COLUMN_DEBRIS_COM, COLUMN_DEBRIS_VELOCITY, COLUMN_ENERGY, COLUMN_ENERGY_TOTAL, COLUMN_MOMENTUM_LINEAR,
 COLUMN_MOMENTUM_ANGULAR) = range(7)
#: ``RecorderModel.extras``: the energy released by failed joints so far (J), the mean motion (rad/s, 0 without orbit),
#: the energy the joints' dampers dissipated so far (J, :func:`book_joint_dampers`).
EXTRA_RELEASED_ENERGY, EXTRA_MEAN_MOTION, EXTRA_JOINTS_DISSIPATED = range(3)
N_EXTRAS = 3


class DamperWork(NamedTuple):
    """Work space of :func:`book_joint_dampers` (preallocated; N Exudyn coordinates, nb bodies)."""

    velocity: np.ndarray              # (N,) the step's evaluation velocities (only the bodies' entries are written)
    com_lvlh: np.ndarray              # (nb, 3) CoM (m)
    velocity_lvlh: np.ndarray         # (nb, 3) CoM velocity (m/s)
    node_to_lvlh: np.ndarray          # (nb, 3, 3)
    body_to_lvlh: np.ndarray          # (nb, 3, 3)
    omega_lvlh: np.ndarray            # (nb, 3) (rad/s)
    omega_body: np.ndarray            # (nb, 3) (rad/s), body frame
    frames: np.ndarray                # (4, 3, 3) a joint's parent frame, child frame, relative rotation, mid frame
    half_turn: np.ndarray             # (1, 3, 3) Exp(r / 2)
    vectors: np.ndarray               # (4, 3) the arms on child and parent (m), relative velocity (m/s) and omega


def damper_work_buffers(n_coordinates: int, n_bodies: int) -> DamperWork:
    """Zeroed :class:`DamperWork` arrays.

    Parameters
    ----------
    n_coordinates : int
        Length of Exudyn's velocity vector the recorder reads.
    n_bodies : int
    """
    nb = n_bodies
    return DamperWork(np.zeros(n_coordinates), np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3, 3)),
                      np.zeros((nb, 3, 3)), np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((4, 3, 3)),
                      np.zeros((1, 3, 3)), np.zeros((4, 3)))


@structref.register
class RecorderModelType(UnliteralStructRef):
    """Numba type of :class:`RecorderModel`."""


class RecorderModel(structref.StructRefProxy):
    """Everything :func:`sample_row` reads and writes, as one numba structref: ``bodies`` (:class:`SampledBodies`),
    ``joints`` (:class:`SampledJoints`), ``active`` ((nj,) float, 1.0 for a joint in place), ``impulse`` ((nb, 6) the
    kernel's contact impulse accumulators), ``out`` (:class:`BodySample`), ``net_mass`` ((n,) kg), ``net_reference`` ((n, 3)
    node reference positions (m), LVLH), ``net_layout`` ((3,) int64: where node ``i``'s coordinate ``d`` sits in the
    net's state vectors, ``[offset, node_stride, coordinate_stride]``, :func:`net_sums`), ``net_totals`` ((8,) the
    net's sums, :func:`net_sums`), ``scalars`` (the force kernel's energies and contact count,
    :data:`multibody.kernel.N_SCALARS`), ``row`` (the recorder's flat row; ``out``'s arrays are views of it),
    ``columns`` ((7,) int64, :data:`COLUMN_TIME` ...), ``extras`` ((N_EXTRAS,) float, :data:`EXTRA_RELEASED_ENERGY`,
    :data:`EXTRA_MEAN_MOTION`, :data:`EXTRA_JOINTS_DISSIPATED`) and ``damper_work`` (:class:`DamperWork`). The same buffers as the recorder's and the kernel's: nothing is copied in or out.
    Handing numba the named tuples themselves cost its dispatcher about 10 us a sample (each tuple's 6-13 arrays
    typed and unboxed from Python); a structref is about 1 us.
    """


structref.define_proxy(RecorderModel, RecorderModelType,
                       ("bodies", "joints", "active", "impulse", "out", "net_mass", "net_reference", "net_layout",
                        "net_totals", "scalars", "row", "columns", "extras", "damper_work"))


@njit(cache=True)
def new_recorder_model(bodies, joints, active, impulse, out, net_mass, net_reference, net_layout, net_totals, scalars,
                       row, columns, extras, damper_work):
    """``RecorderModel(...)`` (its fields in order), compiled once into numba's on-disk cache: the proxy class's own
    constructor is compiled afresh in every process, 1.0 s CPU before a run's first step (measured by helper speed22,
    2026-11-28, load 13; the net's structref had the same, :func:`multibody.kernel_net._new_net_step_model`)."""
    return RecorderModel(bodies, joints, active, impulse, out, net_mass, net_reference, net_layout, net_totals,
                         scalars, row, columns, extras, damper_work)


@njit(cache=True)
def _all_finite(values) -> bool:
    for k in range(values.shape[0]):
        if not math.isfinite(values[k]):
            return False
    return True


@njit(cache=True)
def sample_row(m, q, qt, net_q, net_qt, t, interval):
    """One output sample into ``m.row`` (:class:`RecorderModel`): the bodies and joints with the joints' loads
    (:func:`body_sample`, which also zeroes the contact impulses), the
    net's sums (:func:`net_sums`), the energy terms in the order of :data:`multibody.recorder.ENERGY_TERMS` (then the
    chaser's kinetic energy with a chaser) and their total, added in that order from 0.0 (as Python's ``sum`` of
    them), and the momenta. One compiled call instead of some 60 lines of Python and NumPy: inside the run, where the
    kernel evicts the interpreter's code and data between samples, a sample cost two to three times its cost alone.

    Parameters
    ----------
    m : RecorderModel
    q, qt : (N,) float
        Exudyn's coordinates and velocities (:func:`body_sample`).
    net_q, net_qt : (M,) float
        The net's displacements (m) and velocities (m/s), LVLH, laid out as ``m.net_layout`` says.
    t : float
        Time of the sample (s).
    interval : float
        Time since the last sample (s); 0 gives zero contact force.

    Returns
    -------
    finite : bool
        Every coordinate and velocity of Exudyn's and of the net is finite; when not, nothing is written (the
        caller's full check names the entry).
    total : float
        The energy balance's total of the row (J), without the work of recorded loads (the caller adds it).
    """
    layout, totals, extras = m.net_layout, m.net_totals, m.extras
    n_orbit = extras[EXTRA_MEAN_MOTION]
    checksum = net_sums(net_q, net_qt, layout[0], layout[1], layout[2], m.net_reference, m.net_mass, n_orbit, totals)
    # the checksum is finite only when every entry is; a finite state whose sum overflows gets the exact test
    if not (math.isfinite(checksum) or (_all_finite(net_q) and _all_finite(net_qt))):
        return False, 0.0
    if not (_all_finite(q) and _all_finite(qt)):
        return False, 0.0
    out = m.out
    body_sample(q, qt, m.bodies, m.joints, m.active, m.impulse, interval, n_orbit, out)
    row, columns, summary, scalars = m.row, m.columns, out.summary, m.scalars
    row[columns[COLUMN_TIME]] = t
    for d in range(3):
        row[columns[COLUMN_DEBRIS_COM] + d] = summary[d]
        row[columns[COLUMN_DEBRIS_VELOCITY] + d] = summary[3 + d]
    e = columns[COLUMN_ENERGY]
    row[e] = totals[0]
    row[e + 1] = scalars[THREAD_ELASTIC]
    row[e + 2] = scalars[BENDING_ELASTIC]
    row[e + 3] = scalars[CONTACT_ELASTIC]
    row[e + 4] = summary[6]
    row[e + 5] = summary[7]
    row[e + 6] = summary[16]
    row[e + 7] = extras[EXTRA_RELEASED_ENERGY]
    row[e + 8] = totals[1] + summary[8] if n_orbit != 0.0 else 0.0
    row[e + 9] = scalars[THREAD_DISSIPATED]
    row[e + 10] = scalars[CONTACT_DISSIPATED]
    row[e + 11] = extras[EXTRA_JOINTS_DISSIPATED]
    n_terms = 12
    if m.bodies.chaser >= 0:
        row[e + 12] = summary[9]
        n_terms = 13
    total = 0.0
    for k in range(n_terms):
        total += row[e + k]
    row[columns[COLUMN_ENERGY_TOTAL]] = total
    for d in range(3):
        row[columns[COLUMN_MOMENTUM_LINEAR] + d] = totals[2 + d] + summary[10 + d]
        row[columns[COLUMN_MOMENTUM_ANGULAR] + d] = totals[5 + d] + summary[13 + d]
    return True, total


@njit(cache=True)
def _mid_step_body_states_into(m, q, qt, qtt, half_kick):
    """Every body's state with VelocityVerlet's half-step velocity v(n+1/2) = v(n+1) - h/2 a(n+1) (the velocity the
    forces of the step acted with; half_kick 0 gives v(n+1)) into ``m.damper_work`` (com, velocity, attitude and
    angular velocity, LVLH / body frame)."""
    bodies, work = m.bodies, m.damper_work
    velocity = work.velocity
    for b in range(bodies.mass.shape[0]):
        i = bodies.index[b]
        for k in range(6):
            velocity[i + k] = qt[i + k] - half_kick * qtt[i + k]
        body_state_into(q, velocity, i, b, bodies.reference_com_lvlh, bodies.node_to_body, work.com_lvlh,
                        work.velocity_lvlh, work.node_to_lvlh, work.body_to_lvlh, work.omega_lvlh, work.omega_body)


@njit(cache=True)
def book_joint_dampers(m, q, qt, qtt, half_kick, step):
    """Add the energy the joints' dampers dissipated over the step that just ended to
    ``m.extras[EXTRA_JOINTS_DISSIPATED]`` (J) and return it.

    Exudyn's VelocityVerlet evaluates every force of a step, its connectors' included, once, at the end position
    ``q`` and the mid-step velocity ``v = qt - h/2 qtt`` (``qt``, ``qtt``: the step's end velocity and the
    acceleration of that evaluation; :class:`multibody.impact.VerletForces`): the damping force ``-D v`` acts over
    the step's displacement ``h v``, so the step's damper work is :func:`_joint_damper_power` at that state times ``h``,
    the same rule as the threads' Kelvin-Voigt dampers (:func:`multibody.net.kelvin_voigt_dissipated_power`).
    A joint released (``m.active`` 0) dissipates nothing. With another integrator (``half_kick`` 0) the end-of-step
    velocity stands for the step's: first order in the step.

    Parameters
    ----------
    m : RecorderModel
    q, qt, qtt : (N,) float
        Exudyn's coordinates (the step's end), velocities and accelerations (:func:`body_sample`'s layout).
    half_kick : float
        Half the step for VelocityVerlet, 0 for another integrator (s).
    step : float
        (s).

    Returns
    -------
    float
        The step's dissipated energy (J).
    """
    joints, work = m.joints, m.damper_work
    _mid_step_body_states_into(m, q, qt, qtt, half_kick)
    power = 0.0
    for j in range(joints.parent.shape[0]):
        if m.active[j] != 0.0:
            power += _joint_damper_power(j, joints, work)
    m.extras[EXTRA_JOINTS_DISSIPATED] += power * step
    return power * step


@njit(cache=True)
def _matmat_into(a, b, out):
    """``out = a b`` for (3, 3) arrays, without allocating."""
    for i in range(3):
        for k in range(3):
            out[i, k] = a[i, 0] * b[0, k] + a[i, 1] * b[1, k] + a[i, 2] * b[2, k]


@njit(cache=True)
def _joint_damper_power(j, joints, work) -> float:
    """Power joint ``j``'s dampers dissipate (W) at the bodies' state in ``work`` (:class:`DamperWork`): with the
    connector's diagonal damping ``D`` and the relative velocities ``v``, ``w`` in the mid frame (the kinematics of
    :func:`joint_relative_motion_into` and :func:`mid_frame_velocities`, written out into ``work`` because the
    booking runs every step and their small arrays were some 20 allocations a joint, about 5 us a step on the
    reference case), the damping force is ``-D (v, w)`` (:func:`connector_load_into`), so

    .. math:: P = \\sum_{k=1}^{3} D_k v_k^2 + \\sum_{k=1}^{3} D_{3+k} w_k^2 \\geq 0.
    """
    _joint_kinematics_into(j, joints, work)
    mid, relative_velocity, relative_omega = work.frames[3], work.vectors[2], work.vectors[3]
    damping = joints.damping[j]
    power = 0.0
    for d in range(3):   # mid^T (v, w): the mid frame's components
        v = mid[0, d] * relative_velocity[0] + mid[1, d] * relative_velocity[1] + mid[2, d] * relative_velocity[2]
        w = mid[0, d] * relative_omega[0] + mid[1, d] * relative_omega[1] + mid[2, d] * relative_omega[2]
        power += damping[d] * v * v + damping[3 + d] * w * w
    return power


@njit(cache=True)
def _joint_kinematics_into(j, joints, work):
    """Joint ``j``'s frames and relative velocities at the bodies' state in ``work`` (:class:`DamperWork`), into
    ``work.frames`` (the parent's joint frame in LVLH, the child's, the relative rotation, the mid frame) and
    ``work.vectors`` (the arms on child and parent (m), the relative velocity (m/s) and angular velocity (rad/s),
    LVLH): the kinematics of :func:`joint_relative_motion_into` and :func:`mid_frame_velocities` without allocating."""
    p, c = joints.parent[j], joints.child[j]
    rot, omega, vel = work.body_to_lvlh, work.omega_lvlh, work.velocity_lvlh
    frame, child_frame, relative, mid = work.frames[0], work.frames[1], work.frames[2], work.frames[3]
    arm_child, arm_parent, relative_velocity, relative_omega = (work.vectors[0], work.vectors[1], work.vectors[2],
                                                                work.vectors[3])
    _matmat_into(rot[p], joints.joint_to_parent[j], frame)       # the parent's joint frame in LVLH
    _matmat_into(rot[c], joints.joint_to_child[j], child_frame)
    for i in range(3):
        for k in range(3):
            relative[i, k] = frame[0, i] * child_frame[0, k] + frame[1, i] * child_frame[1, k] + frame[2, i] * child_frame[2, k]
    half_rotation_matrix_into(relative, work.half_turn, 0)   # Exp(r / 2), r the relative rotation vector
    _matmat_into(frame, work.half_turn[0], mid)
    point_child, point_parent = joints.point_child[j], joints.point_parent[j]
    for d in range(3):
        arm_child[d] = rot[c, d, 0] * point_child[0] + rot[c, d, 1] * point_child[1] + rot[c, d, 2] * point_child[2]
        arm_parent[d] = rot[p, d, 0] * point_parent[0] + rot[p, d, 1] * point_parent[1] + rot[p, d, 2] * point_parent[2]
    for d in range(3):   # v_c + w_c x a_c - v_p - w_p x a_p and w_c - w_p, LVLH
        e, f = (d + 1) % 3, (d + 2) % 3
        relative_velocity[d] = (vel[c, d] + omega[c, e] * arm_child[f] - omega[c, f] * arm_child[e] - vel[p, d]
                                - (omega[p, e] * arm_parent[f] - omega[p, f] * arm_parent[e]))
        relative_omega[d] = omega[c, d] - omega[p, d]


@njit(cache=True)
def filter_joint_loads(m, bank, scratch, q, qt, qtt, half_kick, first):
    """Advance the joints' load filters (:mod:`multibody.load_filter`) by the step that just ended: each joint's
    load (:func:`connector_load_into`, the load the parent exerts on the child, joint frame) at the state Exudyn's
    VelocityVerlet evaluated the step's forces at (the end position, the mid-step velocity ``qt - h/2 qtt``, as
    :func:`book_joint_dampers`), through its row of ``bank``. A released joint (``m.active`` 0) feeds 0 (the
    connector is off). Run every step, so the filter sees the penalty modes the output would alias.

    Parameters
    ----------
    m : RecorderModel
    bank : (nj, 6, S, 8) float
        The filter bank (:func:`multibody.load_filter.filter_bank`); its last section's ``OUTPUT`` column holds the filtered
        force (N, axes 0-2) and moment (N m, axes 3-5), joint frame.
    scratch : (6, 3) float
        Work space (:func:`_joint_load_into`).
    q, qt, qtt : (N,) float
        Exudyn's coordinates (the step's end), velocities and accelerations (:func:`body_sample`'s layout).
    half_kick : float
        Half the step for VelocityVerlet, 0 for another integrator (s).
    first : bool
        The first step: each filter starts at rest under its first load (no start-up transient).
    """
    joints, work = m.joints, m.damper_work
    _mid_step_body_states_into(m, q, qt, qtt, half_kick)
    load = scratch[:2]    # the joint's force and moment
    for j in range(joints.parent.shape[0]):
        if m.active[j] != 0.0:
            _joint_load_into(j, joints, work, scratch)
        else:
            for d in range(3):
                load[0, d] = 0.0
                load[1, d] = 0.0
        for axis in range(6):
            value = load[axis // 3, axis % 3]
            if first:
                rest_at(bank, j, axis, value)
            advance(bank, j, axis, value)


@njit(cache=True)
def _joint_load_into(j, joints, work, scratch):
    """Joint ``j``'s load (:func:`connector_load_into`) at the bodies' state in ``work`` (:class:`DamperWork`), into
    ``scratch[0]`` (force, N) and ``scratch[1]`` (moment, N m), joint frame; ``scratch[2:6]`` work space (the relative
    rotation vector, the offset in the parent's joint frame, the mid-frame velocities). Without allocating: it runs
    every step for every joint (:func:`filter_joint_loads`; the allocating path was about 5 us a step on the
    reference case)."""
    _joint_kinematics_into(j, joints, work)
    p, c = joints.parent[j], joints.child[j]
    frame, mid = work.frames[0], work.frames[3]
    arm_child, arm_parent, relative_velocity, relative_omega = (work.vectors[0], work.vectors[1], work.vectors[2],
                                                                work.vectors[3])
    rotation, offset_joint, velocity_mid, omega_mid = scratch[2], scratch[3], scratch[4], scratch[5]
    rotation_vector_from_matrix_into(work.frames[2], rotation)
    com = work.com_lvlh
    for d in range(3):   # frame^T (a_c + x_c - a_p - x_p), and mid^T (v, w)
        offset_joint[d] = 0.0
        velocity_mid[d] = 0.0
        omega_mid[d] = 0.0
        for e in range(3):
            offset_joint[d] += frame[e, d] * (arm_child[e] + com[c, e] - arm_parent[e] - com[p, e])
            velocity_mid[d] += mid[e, d] * relative_velocity[e]
            omega_mid[d] += mid[e, d] * relative_omega[e]
    penalty_load_into(offset_joint, rotation, velocity_mid, omega_mid, joints.stiffness[j], joints.damping[j],
                      scratch[0], scratch[1])
