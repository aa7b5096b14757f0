"""The compiled force kernel that couples the net with the debris bodies in one Exudyn system.

Exudyn integrates every coordinate: the net nodes (one ``NodeGenericODE2``), the
debris rigid bodies (``NodeRigidBodyRotVecLG`` with Lie-group integration) and their
joints (penalty connectors). The forces that act between net and bodies, the thread
forces and the Clohessy-Wiltshire terms are computed here, in one numba function called
by an ``ObjectGenericODE2`` that spans the net node and all rigid-body nodes. Because
the contact force on a node and its reaction on the body are computed in the same call,
linear and angular momentum exchange is exact (the reaction acts on the body at the
node centre, on the same line of action).

Coordinate layout of the generic object (Exudyn ``q`` / ``q_t``):

* ``3 n`` net coordinates: node displacement from its reference position (m), LVLH;
  velocities (m/s), LVLH.
* 6 per rigid body: CoM displacement (m) and rotation vector node->LVLH (rad);
  velocities: CoM velocity (m/s), LVLH, and angular velocity (rad/s), node frame.
  The generalized force on the rotational part is the torque in the node frame
  (angular momentum conservation in ``tests/multibody/test_conservation.py`` depends on it).
  The node frame is the body frame turned by the fixed ``BodyArrays.node_to_body``
  (:mod:`multibody.node_frame`: it keeps Exudyn's rotation vectors away from zero);
  :func:`body_states` turns it back, so contact shapes and inertias stay in the body frame.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numba import njit

from multibody.contact_kernel import add_contact_forces
from multibody.contact_segment import SegmentBuffers, add_segment_contact_forces, segment_buffers
from multibody.net import ThreadRuns, add_bending_forces, add_thread_forces_runs
from multibody.jit_cache import NO_REFCOUNTS, WITH_REFCOUNTS
from multibody.orbit import clohessy_wiltshire_acceleration_xyz
from multibody.maths.rotations import compose_rotation_vectors_into
from multibody.node_frame import body_state_into

#: Indices into the kernel's scalar output buffer.
THREAD_ELASTIC, BENDING_ELASTIC, CONTACT_ELASTIC, THREAD_DISSIPATED, CONTACT_DISSIPATED, N_CONTACTS = range(6)
N_SCALARS = 6


@njit(cache=True)
def verlet_evaluation_state(q, qt, qtt, step, n_net_coordinates, n_bodies):
    """The state at which Exudyn's VelocityVerlet evaluates the forces of the step that starts
    at (q, qt, qtt): mid-step velocity qt + step/2 qtt and end position q + step * that;
    rigid-body rotation vectors are advanced by the Lie-group composition with the
    mid-step angular velocity (node frame), as Exudyn does.

    Parameters
    ----------
    q, qt, qtt : (N,) float
        Coordinates, velocities and accelerations at the step's start, in the module doc's layout.
    step : float
        (s).
    n_net_coordinates : int
        Net coordinates ahead of the bodies' (3 n; 0 when the kernel holds the net).
    n_bodies : int
        Rigid bodies after them (6 coordinates each).

    Returns
    -------
    q_next, v_half : (N,) float
        The evaluation state: end positions (rotation vectors composed) and mid-step velocities.
    """
    q_next, v_half = np.empty_like(q), np.empty_like(qt)
    verlet_evaluation_state_into(q, qt, qtt, step, n_net_coordinates, n_bodies, q_next, v_half)
    return q_next, v_half


@njit(cache=True, **NO_REFCOUNTS)  # no reference counts (jit_cache.NO_REFCOUNTS)
def verlet_evaluation_state_into(q, qt, qtt, step, n_net_coordinates, n_bodies, q_next, v_half):
    """:func:`verlet_evaluation_state` into ``q_next`` and ``v_half`` ((N,) float, preallocated): the net step
    calls it every step (its arrays and the per-body compositions were about 12 allocations a step).

    Parameters
    ----------
    q, qt, qtt, step, n_net_coordinates, n_bodies
        As :func:`verlet_evaluation_state`.
    q_next, v_half : (N,) float
        Output: end positions (rotation vectors composed) and mid-step velocities.
    """
    half = 0.5 * step
    for k in range(q.shape[0]):
        v_half[k] = qt[k] + half * qtt[k]
    for k in range(q.shape[0]):
        q_next[k] = q[k] + step * v_half[k]
    for b in range(n_bodies):
        base = n_net_coordinates + 6 * b + 3
        compose_rotation_vectors_into(q[base], q[base + 1], q[base + 2], step * v_half[base],
                                      step * v_half[base + 1], step * v_half[base + 2], q_next, base)


class NetArrays(NamedTuple):
    """The net's nodes, threads and bending triples (SI units; n nodes, m threads, k triples)."""

    reference_lvlh: np.ndarray     # (n, 3) reference node positions, LVLH (m)
    mass: np.ndarray               # (n,) node masses (kg)
    radius: np.ndarray             # (n,) node contact radii (m)
    threads: np.ndarray            # (m, 2) int64 node pairs
    rest_lengths: np.ndarray       # (m,) (m)
    thread_stiffness: np.ndarray   # (m,) (N/m)
    thread_damping: np.ndarray     # (m,) (N s/m)
    bending_triples: np.ndarray    # (k, 3) int64 node triples (end, middle, end)
    bending_stiffness: np.ndarray  # (k,) (N m/rad)
    thread_runs: ThreadRuns        # the threads regrouped for the vectorized pass (multibody.net.thread_runs)


class BodyArrays(NamedTuple):
    """The rigid bodies' constants (nb bodies)."""

    reference_com_lvlh: np.ndarray     # (nb, 3) reference CoM positions, LVLH (m)
    mass: np.ndarray                   # (nb,) (kg)
    inverse_inertia_body: np.ndarray   # (nb, 3, 3) inverse inertia about the CoM, body frame (1/(kg m^2))
    node_to_body: np.ndarray           # (nb, 3, 3) each body's Exudyn node frame in its body frame (multibody.node_frame)


class ShapeArrays(NamedTuple):
    """The bodies' closed contact shapes (ns shapes of T triangles in all), each a slice of the triangle
    arrays in its body's frame (origin at the body CoM). Signed distances are taken per shape, so shapes
    of one body may overlap."""

    triangles_body: np.ndarray     # (T, 3, 3) corners, body frame of the owning body (m)
    normals_body: np.ndarray       # (T, 3) outward unit normals, body frame
    body: np.ndarray               # (ns,) int64 body owning each shape
    triangle_range: np.ndarray     # (ns, 2) int64 triangle slice of each shape
    box_min_body: np.ndarray       # (ns, 3) body-frame bounding box of each shape (m)
    box_max_body: np.ndarray       # (ns, 3) (m)
    is_box: np.ndarray             # (ns,) int64, 1: the shape is its bounding box (multibody.broad_phase)


class ContactLaw(NamedTuple):
    """Hunt-Crossley normal force and Hollar friction (seed paper eqs. (6), (7)), and the contact's
    integration switch."""

    stiffness: float           # k_n (N/m^n)
    exponent: float            # n (-)
    damping: float             # d_n = 1.5 alpha k_n (N s/m^(n+1))
    mu_static: float           # (-)
    mu_kinetic: float          # (-)
    transition_speed: float    # Hollar's V_t (m/s)
    implicit_speed: float      # below this normal speed (m/s) a single contact takes the implicit step; 0: never


class Mounts(NamedTuple):
    """Net nodes mounted on a body (a chaser's net frame): one stiff spring-damper per mount (k mounts)."""

    node: np.ndarray           # (k,) int64 net node
    body: np.ndarray           # (k,) int64 body
    point_body: np.ndarray     # (k, 3) mount point, body frame (m)
    stiffness: float           # (N/m)
    damping: float             # (N s/m)


def no_mounts() -> Mounts:
    """:class:`Mounts` with none."""
    return Mounts(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)), 0.0, 0.0)


class KernelBuffers(NamedTuple):
    """What the kernel writes: the force vector, accumulated impulses and energies, the contact lag it
    carries from step to step, and work space (so nothing is allocated per node)."""

    force: np.ndarray              # (3 n + 6 nb,) generalized forces (module doc)
    body_impulse_lvlh: np.ndarray  # (nb, 6) accumulated contact impulse (N s), angular impulse about CoM (N m s), LVLH
    node_impulse_lvlh: np.ndarray  # (n, 3) accumulated contact impulse on each net node (N s), LVLH
    velocity_lag: np.ndarray       # (3, n) true minus integrator velocity of sub-cycled nodes (m/s), LVLH,
                                   # coordinate-major
    lag_body: np.ndarray           # (n,) int64 body of the node's last contact, -1 for none
    scalars: np.ndarray            # (N_SCALARS,) energies (J) and contact count, indices above
    work: np.ndarray               # (4, n, 3) positions, forces (bending's node-major copies), non-contact
                                   # forces, start velocities of contact nodes
    work_node: np.ndarray          # (4, n) speed, acceleration bound, reach; 1 / mass
    candidates: np.ndarray         # (ns + 1, n) uint8 node near shape; last row: near any
    work_soa: np.ndarray           # (3, 3, n) positions, velocities, node forces, coordinate-major
    work_thread: np.ndarray        # (5, P) per padded thread: force on its node a, energy, power
    work_shape: np.ndarray         # (5, ns, 3) one node's contacts: normals, relative velocities, impulses;
                                   # sub-cycle recoils and forces (multibody.contact_kernel)
    work_shape_scalar: np.ndarray  # (6, ns) penetrations, effective masses, impulse norms, sub-cycle
                                   # penetrations; each shape's surface speed bound and reach within the step
    contact_body: np.ndarray       # (ns,) int64 the body of each of one node's contacts
    work_body: np.ndarray          # (2, nb, 3) the bodies' force and torque accumulators (LVLH)
    states: "BodyStates"           # the bodies' state at the evaluation (body_states_into)
    segments: SegmentBuffers       # the threads' contact (multibody.contact_segment): switch, carried impulses


def kernel_buffers(net: NetArrays, n_bodies: int, n_shapes: int, thread_segments: bool = False) -> KernelBuffers:
    """Zeroed :class:`KernelBuffers` for ``net`` and ``n_bodies`` bodies with ``n_shapes`` contact shapes.

    Parameters
    ----------
    net : NetArrays
    n_bodies, n_shapes : int
    thread_segments : bool
        Threads take contact with the box shapes too (:mod:`multibody.contact_segment`).
    """
    n = len(net.mass)
    work_node = np.zeros((4, n))
    work_node[3] = 1.0 / np.asarray(net.mass, float)  # constant: a product is cheaper than a division
    return KernelBuffers(force=np.zeros(3 * n + 6 * n_bodies), body_impulse_lvlh=np.zeros((n_bodies, 6)),
                         node_impulse_lvlh=np.zeros((n, 3)), velocity_lag=np.zeros((3, n)),
                         lag_body=np.full(n, -1, dtype=np.int64), scalars=np.zeros(N_SCALARS),
                         work=np.zeros((4, n, 3)), work_node=work_node,
                         candidates=np.zeros((n_shapes + 1, n), np.uint8), work_soa=np.zeros((3, 3, n)),
                         work_thread=np.zeros((5, len(net.thread_runs.rest_lengths))),
                         work_shape=np.zeros((5, n_shapes, 3)), work_shape_scalar=np.zeros((6, n_shapes)),
                         contact_body=np.zeros(n_shapes, np.int64), work_body=np.zeros((2, n_bodies, 3)),
                         states=BodyStates(np.zeros((n_bodies, 3, 3)), np.zeros((n_bodies, 3)),
                                           np.zeros((n_bodies, 3)), np.zeros((n_bodies, 3)),
                                           np.zeros((n_bodies, 3, 3)), np.zeros((n_bodies, 3))),
                         segments=segment_buffers(len(net.threads), n, n_shapes, n_bodies, thread_segments))


class BodyStates(NamedTuple):
    """The bodies' state at a force evaluation (nb bodies), from :func:`body_states`."""

    body_to_lvlh: np.ndarray   # (nb, 3, 3) attitude
    com_lvlh: np.ndarray       # (nb, 3) CoM (m)
    velocity_lvlh: np.ndarray  # (nb, 3) CoM velocity (m/s)
    omega_lvlh: np.ndarray     # (nb, 3) angular velocity (rad/s)
    node_to_lvlh: np.ndarray   # (nb, 3, 3) the Exudyn node's attitude (its frame carries the generalized torque)
    omega_body: np.ndarray     # (nb, 3) angular velocity (rad/s), body frame


@dataclass
class KernelData:
    """Everything the kernel needs, grouped (SI units; frames in the groups' field names).

    Parameters
    ----------
    net, bodies, shapes, law, mounts
        :class:`NetArrays`, :class:`BodyArrays`, :class:`ShapeArrays`, :class:`ContactLaw`, :class:`Mounts`.
    mean_motion : float
        Orbit mean motion (rad/s) of the Clohessy-Wiltshire terms; 0 without orbit.
    step : float
        Integrator step (s).
    contact_substep : float
        Shortest contact sub-step (s); >= ``step`` (or inf) disables sub-cycling.
    stage_weight : float
        1 / force evaluations per integrator step.
    thread_segments : bool
        Threads take contact with the box shapes too (:mod:`multibody.contact_segment`).
    """

    net: NetArrays
    bodies: BodyArrays
    shapes: ShapeArrays
    law: ContactLaw
    mean_motion: float
    step: float
    contact_substep: float
    stage_weight: float = 1.0
    mounts: Mounts = field(default_factory=no_mounts)
    thread_segments: bool = False
    buffers: KernelBuffers = field(init=False)

    def __post_init__(self):
        self.buffers = kernel_buffers(self.net, self.n_bodies, len(self.shapes.body), self.thread_segments)

    @property
    def n_nodes(self) -> int:
        return len(self.net.mass)

    @property
    def n_bodies(self) -> int:
        return len(self.bodies.mass)

    def evaluate(self, q, qt, time=1.0):
        """Generalized forces (3 n + 6 nb,) at coordinates ``q`` and velocities ``qt`` (module doc).

        Parameters
        ----------
        q, qt : (3 n + 6 nb,) float
            Coordinates and velocities in the module doc's layout.
        time : float
            Time of the evaluation (s). At 0 (the solver's initial-acceleration evaluation, which
            Verlet applies as a half kick only) the contact is evaluated without sub-cycling.
        """
        n_sub = max(1, int(math.ceil(self.step / self.contact_substep - 1e-9))) if time > 0.0 else 1
        return coupled_generalized_forces(q, qt, self.net, self.bodies, self.shapes, self.law, self.mounts,
                                          self.mean_motion, self.step, n_sub, self.stage_weight, self.buffers)


@njit(cache=True)
def coupled_generalized_forces(q, qt, net, bodies, shapes, law, mounts, n_orbit, step, n_substeps, stage_weight,
                               buffers):
    """Fill ``buffers.force`` with the generalized forces of the coupled system (see module doc); returns it.

    The net's part goes through :func:`coupled_forces_soa` on coordinate-major copies of the net's
    coordinates (the layout the kernel path keeps its state in, :mod:`multibody.kernel_net`).

    Parameters
    ----------
    q, qt : (3 n + 6 nb,) float
        Coordinates and velocities in the module doc's layout.
    net, bodies, shapes, law, mounts : NetArrays, BodyArrays, ShapeArrays, ContactLaw, Mounts
    n_orbit : float
        Mean motion (rad/s) of the Clohessy-Wiltshire terms; 0 without orbit.
    step : float
        Integrator step (s).
    n_substeps : int
        Contact sub-steps per step (1: none).
    stage_weight : float
        1 / force evaluations per step: accumulations are weighted by it (exact for VelocityVerlet's
        single evaluation, an average for Runge-Kutta stages).
    buffers : KernelBuffers
        Also accumulates, per body, the contact impulse (N s) and angular impulse about the CoM
        (N m s) in LVLH, per net node the contact impulse (N s, LVLH), the dissipated energies, and
        sets the current elastic energies (``scalars``).
    """
    out_force = buffers.force
    net_reference = net.reference_lvlh
    n = net.mass.shape[0]
    x_soa, v_soa, force_soa = buffers.work_soa[0], buffers.work_soa[1], buffers.work_soa[2]
    for d in range(3):
        for i in range(n):
            x_soa[d, i] = net_reference[i, d] + q[3 * i + d]
            v_soa[d, i] = qt[3 * i + d]
    coupled_forces_soa(x_soa, v_soa, q[3 * n:], qt[3 * n:], net, bodies, shapes, law, mounts, n_orbit, step,
                       n_substeps, stage_weight, buffers, force_soa, out_force[3 * n:])
    for i in range(n):
        for d in range(3):
            out_force[3 * i + d] = force_soa[d, i]
    return out_force


# no reference counts (jit_cache.NO_REFCOUNTS), and so a call again: inlined into its callers (as until now), its
# reads of the named tuples' arrays were still counted, some 100 a step, and as a counted call it counted every
# array it was handed at its entry and exit
@njit(cache=True, **NO_REFCOUNTS)
def coupled_forces_soa(x_soa, v_soa, q_bodies, qt_bodies, net, bodies, shapes, law, mounts, n_orbit, step,
                       n_substeps, stage_weight, buffers, force_soa, body_force):
    """The coupled forces with the net coordinate-major: ``force_soa`` (3, n) on the nodes (N, LVLH),
    ``body_force`` (6 nb,) on the bodies (module doc's layout: force, LVLH; torque, node frame).

    Coordinate-major (3, n) arrays let the passes over all nodes vectorize (threads, orbit terms, the
    contact's reach and box tests) without copies in and out of the node-major layout, about 10 us a
    step for the reference net; :mod:`multibody.kernel_net` keeps the net's state so.

    Parameters
    ----------
    x_soa, v_soa : (3, n) float
        Node positions (m) and velocities (m/s), LVLH, coordinate-major; read only.
    q_bodies, qt_bodies : (6 nb,) float
        The bodies' coordinates and velocities (module doc's layout).
    net, bodies, shapes, law, mounts, n_orbit, step, n_substeps, stage_weight, buffers
        As :func:`coupled_generalized_forces`.
    force_soa : (3, n) float
        Output, overwritten: the forces on the nodes (N, LVLH).
    body_force : (6 nb,) float
        Output, overwritten: the bodies' generalized forces.
    """
    out_scalars = buffers.scalars
    net_mass = net.mass
    n = net_mass.shape[0]
    nb = bodies.mass.shape[0]
    force_soa[:] = 0.0
    elastic, power = add_thread_forces_runs(x_soa, v_soa, net.thread_runs, force_soa, buffers.work_thread)
    out_scalars[THREAD_ELASTIC] = elastic
    # the calls below only when they have work: a call reference-counts every array it is handed, at entry
    # and exit (bending off and no mounts, the impact's usual case, had 40 of a step's some 500 counts)
    out_scalars[BENDING_ELASTIC] = (_add_bending_forces_soa(x_soa, net.bending_triples, net.bending_stiffness,
                                                            force_soa, buffers.work[0], buffers.work[1])
                                    if net.bending_stiffness.shape[0] > 0 else 0.0)
    out_scalars[THREAD_DISSIPATED] += power * step * stage_weight

    if n_orbit != 0.0:
        x0, x2, v0, v1 = x_soa[0], x_soa[2], v_soa[0], v_soa[1]
        f0, f1, f2 = force_soa[0], force_soa[1], force_soa[2]
        for i in range(n):
            ax, ay, az = clohessy_wiltshire_acceleration_xyz(x0[i], x2[i], v0[i], v1[i], n_orbit)
            f0[i] += net_mass[i] * ax
            f1[i] += net_mass[i] * ay
            f2[i] += net_mass[i] * az

    states = buffers.states
    body_states_into(q_bodies, qt_bodies, 0, bodies.reference_com_lvlh, bodies.node_to_body, states)
    node_to_lvlh, com_lvlh, velocity_lvlh = states.node_to_lvlh, states.com_lvlh, states.velocity_lvlh
    # accumulators from the buffers, and the orbit terms in scalars: allocations here were about 12 a step
    body_force_lvlh, torque_lvlh = buffers.work_body[0], buffers.work_body[1]
    body_force_lvlh[:] = 0.0
    torque_lvlh[:] = 0.0
    if n_orbit != 0.0:
        for b in range(nb):
            ax, ay, az = clohessy_wiltshire_acceleration_xyz(com_lvlh[b, 0], com_lvlh[b, 2], velocity_lvlh[b, 0],
                                                             velocity_lvlh[b, 1], n_orbit)
            body_force_lvlh[b, 0] += bodies.mass[b] * ax
            body_force_lvlh[b, 1] += bodies.mass[b] * ay
            body_force_lvlh[b, 2] += bodies.mass[b] * az
    mount_elastic, mount_power = (add_mount_forces(x_soa, v_soa, states, mounts, force_soa, body_force_lvlh,
                                                   torque_lvlh) if mounts.node.shape[0] > 0 else (0.0, 0.0))
    # Mounts are the rods that hold the net's rim on the chaser: booked with the threads.
    out_scalars[THREAD_ELASTIC] += mount_elastic
    out_scalars[THREAD_DISSIPATED] += mount_power * step * stage_weight
    # the threads' own contact first (off unless the case asks): the nodes' contacts then see it as an outside force
    # (measured: after them, the thread's point saw the nodes' impact kicks as its own motion and the energy
    # balance of envisat_small's first 0.4 s drifted 12 % instead of 2.8 %)
    # called only when on: a call reference-counts every array it is handed (the default path pays nothing)
    thread_energy, thread_contacts, thread_dissipated = (add_segment_contact_forces(
        x_soa, v_soa, net, states, bodies, shapes, law, step, n_substeps, stage_weight, buffers, force_soa,
        body_force_lvlh, torque_lvlh) if buffers.segments.enabled != 0 else (0.0, 0, 0.0))
    contact_energy, n_contacts, contact_dissipated = add_contact_forces(
        x_soa, v_soa, net, states, bodies, shapes, law, step, n_substeps, stage_weight, buffers, force_soa,
        body_force_lvlh, torque_lvlh)
    contact_energy += thread_energy
    n_contacts += thread_contacts
    contact_dissipated += thread_dissipated
    for b in range(nb):
        base = 6 * b
        for r in range(3):  # element by element: a slice assignment allocates (its overlap copy)
            body_force[base + r] = body_force_lvlh[b, r]
        for r in range(3):  # node-frame torque R^T t, in scalars (no BLAS call)
            body_force[base + 3 + r] = (node_to_lvlh[b, 0, r] * torque_lvlh[b, 0]
                                        + node_to_lvlh[b, 1, r] * torque_lvlh[b, 1]
                                        + node_to_lvlh[b, 2, r] * torque_lvlh[b, 2])
    out_scalars[CONTACT_ELASTIC] = contact_energy
    out_scalars[N_CONTACTS] = n_contacts
    out_scalars[CONTACT_DISSIPATED] += contact_dissipated


@njit(cache=True, **WITH_REFCOUNTS)  # allocates; called from a NO_REFCOUNTS kernel (jit_cache)
def _add_bending_forces_soa(x_soa, triples, bending_stiffness, force_soa, x_work, force_work):
    """:func:`multibody.net.add_bending_forces` on coordinate-major arrays, through node-major copies
    (``x_work``, ``force_work``: (n, 3) work space), so each node's sum is the same to the bit; nothing
    to do, and no copy, when every bending stiffness is zero (bending off, the default). Returns the
    bending energy (J)."""
    active = False
    for t in range(bending_stiffness.shape[0]):
        if bending_stiffness[t] != 0.0:
            active = True
            break
    if not active:
        return 0.0
    n = x_soa.shape[1]
    for i in range(n):
        for d in range(3):
            x_work[i, d] = x_soa[d, i]
            force_work[i, d] = force_soa[d, i]
    energy = add_bending_forces(x_work, triples, bending_stiffness, force_work)
    for d in range(3):
        for i in range(n):
            force_soa[d, i] = force_work[i, d]
    return energy


@njit(cache=True, **WITH_REFCOUNTS)  # allocates; called from a NO_REFCOUNTS kernel (jit_cache)
def add_mount_forces(x, v, states, mounts, net_force_lvlh, body_force_lvlh, torque_lvlh):
    """Spring-dampers from mounted net nodes to their points on a body, all LVLH.

    The node's force and the body's reaction act on the same line, through the mount point, so linear
    and angular momentum are exchanged exactly. Returns the elastic energy (J) and the dissipated
    power (W).

    Parameters
    ----------
    x, v : (3, n) float
        Node positions (m) and velocities (m/s), LVLH, coordinate-major.
    states : BodyStates
    mounts : Mounts
    net_force_lvlh : (3, n) float
        Node force accumulator (N), LVLH, coordinate-major.
    body_force_lvlh, torque_lvlh : (nb, 3) float
        Body force (N) and torque about the CoM (N m) accumulators, LVLH.
    """
    k, d = mounts.stiffness, mounts.damping
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    elastic = 0.0
    power = 0.0
    if mounts.node.shape[0] == 0:
        return 0.0, 0.0     # none (the impact's usual case): nothing to allocate
    node_x = np.empty(3)
    node_v = np.empty(3)
    for m in range(mounts.node.shape[0]):
        i = mounts.node[m]
        b = mounts.body[m]
        for c in range(3):
            node_x[c] = x[c, i]
            node_v[c] = v[c, i]
        arm = body_to_lvlh[b] @ mounts.point_body[m]
        gap = node_x - (com_lvlh[b] + arm)
        rate = node_v - (velocity_lvlh[b] + np.cross(omega_lvlh[b], arm))
        f = -k * gap - d * rate
        for c in range(3):
            net_force_lvlh[c, i] += f[c]
        body_force_lvlh[b] -= f
        torque_lvlh[b] -= np.cross(arm, f)
        elastic += 0.5 * k * (gap @ gap)
        power += d * (rate @ rate)
    return elastic, power


@njit(cache=True)
def body_states(q, qt, n_nodes, reference_com_lvlh, node_to_body):
    """:class:`BodyStates` (attitude body->LVLH, CoM (m), CoM velocity (m/s), angular velocity (rad/s),
    LVLH; the node's attitude; the angular velocity in the body frame) from the coordinates in the module doc's layout.

    Parameters
    ----------
    q, qt : (3 n + 6 nb,) float
        Coordinates and velocities (module doc).
    n_nodes : int
        Net nodes ahead of the bodies (0 when the kernel holds the net).
    reference_com_lvlh : (nb, 3) float
        Reference CoM positions (m), LVLH.
    node_to_body : (nb, 3, 3) float
        Each body's node frame in its body frame (:mod:`multibody.node_frame`).
    """
    nb = reference_com_lvlh.shape[0]
    states = BodyStates(np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3)), np.empty((nb, 3)),
                        np.empty((nb, 3, 3)), np.empty((nb, 3)))
    body_states_into(q, qt, n_nodes, reference_com_lvlh, node_to_body, states)
    return states


@njit(cache=True, **NO_REFCOUNTS)  # no reference counts (jit_cache.NO_REFCOUNTS)
def body_states_into(q, qt, n_nodes, reference_com_lvlh, node_to_body, states):
    """:func:`body_states` into ``states`` (:class:`BodyStates`, preallocated: the kernel's buffers).

    Parameters
    ----------
    q, qt, n_nodes, reference_com_lvlh, node_to_body
        As :func:`body_states`.
    states : BodyStates
        Output.
    """
    com_lvlh, velocity_lvlh, node_to_lvlh = states.com_lvlh, states.velocity_lvlh, states.node_to_lvlh
    body_to_lvlh, omega_lvlh, omega_body = states.body_to_lvlh, states.omega_lvlh, states.omega_body
    for b in range(reference_com_lvlh.shape[0]):
        body_state_into(q, qt, 3 * n_nodes + 6 * b, b, reference_com_lvlh, node_to_body, com_lvlh, velocity_lvlh,
                        node_to_lvlh, body_to_lvlh, omega_lvlh, omega_body)
