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
* 6 per rigid body: CoM displacement (m) and rotation vector body->LVLH (rad);
  velocities: CoM velocity (m/s), LVLH, and angular velocity (rad/s), body frame.
  The generalized force on the rotational part is the torque in the body frame
  (angular momentum conservation in ``tests/multibody/test_conservation.py`` depends on it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from multibody.contact_kernel import add_contact_forces
from multibody.net import add_bending_forces, add_thread_forces
from multibody.orbit import (
    clohessy_wiltshire_acceleration,
    clohessy_wiltshire_acceleration_xyz,
)
from multibody.rotations import compose_rotation_vectors, rotation_matrix_from_rotation_vector

#: Indices into the kernel's scalar output buffer.
THREAD_ELASTIC, BENDING_ELASTIC, CONTACT_ELASTIC, THREAD_DISSIPATED, CONTACT_DISSIPATED, N_CONTACTS = range(6)
N_SCALARS = 6


@njit(cache=True)
def verlet_evaluation_state(q, qt, qtt, step, n_net_coordinates, n_bodies):
    """The state at which Exudyn's VelocityVerlet evaluates the forces of the step that starts
    at (q, qt, qtt): mid-step velocity qt + step/2 qtt and end position q + step * that;
    rigid-body rotation vectors are advanced by the Lie-group composition with the
    mid-step angular velocity (body frame), as Exudyn does. Layout as in the module doc."""
    v_half = qt + (0.5 * step) * qtt
    q_next = q + step * v_half
    for b in range(n_bodies):
        base = n_net_coordinates + 6 * b + 3
        q_next[base:base + 3] = compose_rotation_vectors(q[base:base + 3], step * v_half[base:base + 3])
    return q_next, v_half


@dataclass
class KernelData:
    """Everything the kernel needs, as contiguous arrays (SI units).

    Body geometry is a list of closed contact shapes (one per primitive or mesh file),
    each a slice of the triangle arrays in its body's frame (origin at the body CoM).
    Signed distances are taken per shape, so shapes of one body may overlap.
    """

    net_reference: np.ndarray        # (n, 3) reference node positions, LVLH (m)
    net_mass: np.ndarray             # (n,) (kg)
    net_radius: np.ndarray           # (n,) (m)
    threads: np.ndarray              # (m, 2) int
    rest_lengths: np.ndarray         # (m,) (m)
    thread_stiffness: np.ndarray     # (m,) (N/m)
    thread_damping: np.ndarray       # (m,) (N s/m)
    bending_triples: np.ndarray      # (b, 3) int
    bending_stiffness: np.ndarray    # (b,) (N m/rad)
    body_reference: np.ndarray       # (nb, 3) reference CoM positions, LVLH (m)
    body_mass: np.ndarray            # (nb,) (kg)
    body_inverse_inertia: np.ndarray # (nb, 3, 3) inverse inertia about the CoM, body frame (1/(kg m^2))
    triangles: np.ndarray            # (T, 3, 3) corners, body frame of the owning body (m)
    triangle_normals: np.ndarray     # (T, 3) outward normals, body frame
    shape_body: np.ndarray           # (ns,) int, body owning each contact shape
    shape_triangle_range: np.ndarray # (ns, 2) int, triangle slice of each shape
    shape_box_min: np.ndarray        # (ns, 3) body-frame bounding box of each shape (m)
    shape_box_max: np.ndarray        # (ns, 3)
    shape_is_box: np.ndarray         # (ns,) int, 1: the shape is its bounding box (multibody.broad_phase)
    contact_stiffness: float         # k_n (N/m^n)
    contact_exponent: float          # n (-)
    contact_damping: float           # d_n = 1.5 alpha k_n
    mu_static: float
    mu_kinetic: float
    transition_speed: float          # (m/s)
    mean_motion: float               # (rad/s); 0 without orbit
    step: float                      # integrator step (s)
    contact_substep: float           # shortest contact sub-step (s); >= step disables sub-cycling
    stage_weight: float = 1.0        # 1 / force evaluations per integrator step
    implicit_contact_speed: float = 0.0  # (m/s) below it a single contact takes the implicit step; 0: never
    # Net nodes mounted on a body (a chaser's net frame): one stiff spring-damper per mount
    mount_node: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))   # (k,) net node
    mount_body: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))   # (k,) body
    mount_point_body: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (k, 3) body frame (m)
    mount_stiffness: float = 0.0     # (N/m)
    mount_damping: float = 0.0       # (N s/m)
    force: np.ndarray = field(init=False)
    body_impulse: np.ndarray = field(init=False)   # (nb, 6) accumulated contact impulse and angular impulse about CoM, LVLH
    node_impulse: np.ndarray = field(init=False)   # (n, 3) accumulated contact impulse on each net node (N s), LVLH
    velocity_lag: np.ndarray = field(init=False)   # (n, 3) true minus integrator velocity of sub-cycled nodes (m/s)
    lag_body: np.ndarray = field(init=False)       # (n,) body of the node's last contact, -1 for none
    scalars: np.ndarray = field(init=False)
    work: np.ndarray = field(init=False)          # (4, n, 3) work space: positions, forces, non-contact forces, start velocities
    work_node: np.ndarray = field(init=False)     # (4, n) work space: speed, acceleration bound, reach; 1 / mass
    candidates: np.ndarray = field(init=False)    # (ns + 1, n) uint8 work space: node near shape; last row: near any

    def __post_init__(self):
        n = len(self.net_mass)
        nb = len(self.body_mass)
        self.work = np.zeros((4, n, 3))
        self.work_node = np.zeros((4, n))
        self.work_node[3] = 1.0 / np.asarray(self.net_mass, float)  # constant: a product is cheaper than a division
        self.candidates = np.zeros((len(self.shape_body) + 1, n), np.uint8)
        self.force = np.zeros(3 * n + 6 * nb)
        self.body_impulse = np.zeros((nb, 6))
        self.node_impulse = np.zeros((n, 3))
        self.scalars = np.zeros(N_SCALARS)
        self.velocity_lag = np.zeros((n, 3))
        self.lag_body = np.full(n, -1, dtype=np.int64)

    @property
    def n_nodes(self) -> int:
        return len(self.net_mass)

    @property
    def n_bodies(self) -> int:
        return len(self.body_mass)

    def evaluate(self, q, qt, time=1.0):
        """Generalized forces for coordinates ``q`` and velocities ``qt`` ((3n + 6nb,) each).

        At ``time`` 0 (the solver's initial-acceleration evaluation, which Verlet applies as
        a half kick only) the contact is evaluated without sub-cycling.
        """
        n_sub = max(1, int(math.ceil(self.step / self.contact_substep - 1e-9))) if time > 0.0 else 1
        coupled_generalized_forces(
            q, qt, self.net_reference, self.net_mass, self.net_radius,
            self.threads, self.rest_lengths, self.thread_stiffness, self.thread_damping,
            self.bending_triples, self.bending_stiffness,
            self.body_reference, self.body_mass, self.body_inverse_inertia, self.triangles, self.triangle_normals,
            self.shape_body, self.shape_triangle_range, self.shape_box_min, self.shape_box_max, self.shape_is_box,
            self.contact_stiffness, self.contact_exponent, self.contact_damping,
            self.mu_static, self.mu_kinetic, self.transition_speed,
            self.mean_motion, self.step, n_sub, self.stage_weight, self.implicit_contact_speed,
            self.velocity_lag, self.lag_body,
            self.mount_node, self.mount_body, self.mount_point_body, self.mount_stiffness, self.mount_damping,
            self.force, self.body_impulse, self.node_impulse, self.scalars, self.work, self.work_node,
            self.candidates)
        return self.force


@njit(cache=True)
def coupled_generalized_forces(q, qt, net_reference, net_mass, net_radius,
                               threads, rest_lengths, thread_stiffness, thread_damping,
                               bending_triples, bending_stiffness,
                               body_reference, body_mass_all, inverse_inertia, triangles, triangle_normals,
                               shape_body, shape_triangle_range, shape_box_min, shape_box_max, shape_is_box,
                               k_contact, exponent, d_contact, mu_s, mu_k, v_transition,
                               n_orbit, step, n_substeps, stage_weight, implicit_speed, velocity_lag, lag_body,
                               mount_node, mount_body, mount_point_body, k_mount, d_mount,
                               out_force, out_body_impulse, out_node_impulse, out_scalars, work, work_node,
                               candidates):
    """Fill ``out_force`` with the generalized forces of the coupled system (see module doc).

    Also accumulates, per body, the contact impulse (N s) and angular impulse about the
    CoM (N m s) in LVLH into ``out_body_impulse``, per net node the contact impulse (N s, LVLH)
    into ``out_node_impulse``, the dissipated energies into
    ``out_scalars`` and sets the current elastic energies there. Accumulations are
    weighted by ``stage_weight`` (1 / force evaluations per step: exact for
    VelocityVerlet's single evaluation, an average for Runge-Kutta stages). ``work``,
    ``work_node``, ``candidates``: work space (:class:`KernelData`), so nothing is allocated per node.
    """
    n = net_mass.shape[0]
    nb = body_mass_all.shape[0]
    x, f_net = work[0], work[1]
    for i in range(n):
        for d in range(3):
            x[i, d] = net_reference[i, d] + q[3 * i + d]
            f_net[i, d] = 0.0
    v = qt[: 3 * n].reshape(n, 3)

    elastic, power = add_thread_forces(x, v, threads, rest_lengths, thread_stiffness, thread_damping, f_net)
    out_scalars[THREAD_ELASTIC] = elastic
    out_scalars[BENDING_ELASTIC] = add_bending_forces(x, bending_triples, bending_stiffness, f_net)
    out_scalars[THREAD_DISSIPATED] += power * step * stage_weight

    if n_orbit != 0.0:
        for i in range(n):
            ax, ay, az = clohessy_wiltshire_acceleration_xyz(x[i, 0], x[i, 2], v[i, 0], v[i, 1], n_orbit)
            f_net[i, 0] += net_mass[i] * ax
            f_net[i, 1] += net_mass[i] * ay
            f_net[i, 2] += net_mass[i] * az

    rots, coms, vels, omegas = body_states(q, qt, n, body_reference)
    f_body = np.zeros((nb, 3))
    if n_orbit != 0.0:
        for b in range(nb):
            f_body[b] += body_mass_all[b] * clohessy_wiltshire_acceleration(coms[b], vels[b], n_orbit)
    torque_lvlh = np.zeros((nb, 3))
    mount_elastic, mount_power = add_mount_forces(x, v, coms, vels, rots, omegas, mount_node, mount_body,
                                                  mount_point_body, k_mount, d_mount, f_net, f_body, torque_lvlh)
    # Mounts are the rods that hold the net's rim on the chaser: booked with the threads.
    out_scalars[THREAD_ELASTIC] += mount_elastic
    out_scalars[THREAD_DISSIPATED] += mount_power * step * stage_weight
    contact_energy, n_contacts, contact_dissipated = add_contact_forces(
        x, v, net_mass, net_radius, rots, coms, vels, omegas, body_mass_all, inverse_inertia,
        triangles, triangle_normals, shape_body, shape_triangle_range, shape_box_min, shape_box_max, shape_is_box,
        k_contact, exponent, d_contact, mu_s, mu_k, v_transition, step, n_substeps, stage_weight, implicit_speed,
        velocity_lag, lag_body, f_net, f_body, torque_lvlh, out_body_impulse, out_node_impulse,
        work[2], work[3], work_node, candidates)
    for b in range(nb):
        base = 3 * n + 6 * b
        out_force[base:base + 3] = f_body[b]
        for r in range(3):  # body-frame torque R^T t, in scalars (no BLAS call)
            out_force[base + 3 + r] = (rots[b, 0, r] * torque_lvlh[b, 0] + rots[b, 1, r] * torque_lvlh[b, 1]
                                       + rots[b, 2, r] * torque_lvlh[b, 2])
    out_scalars[CONTACT_ELASTIC] = contact_energy
    out_scalars[N_CONTACTS] = n_contacts
    out_scalars[CONTACT_DISSIPATED] += contact_dissipated
    for i in range(n):
        for d in range(3):
            out_force[3 * i + d] = f_net[i, d]
    return out_force


@njit(cache=True)
def add_mount_forces(x, v, coms, vels, rots, omegas, mount_node, mount_body, mount_point_body, k, d,
                     f_net, f_body, torque_lvlh):
    """Spring-dampers (k, d) from mounted net nodes to their points on a body, all LVLH.

    The node's force and the body's reaction act on the same line, through the mount point,
    so linear and angular momentum are exchanged exactly. Returns the elastic energy (J)
    and the dissipated power (W).
    """
    elastic = 0.0
    power = 0.0
    for m in range(mount_node.shape[0]):
        i = mount_node[m]
        b = mount_body[m]
        arm = rots[b] @ mount_point_body[m]
        gap = x[i] - (coms[b] + arm)
        rate = v[i] - (vels[b] + np.cross(omegas[b], arm))
        f = -k * gap - d * rate
        f_net[i] += f
        f_body[b] -= f
        torque_lvlh[b] -= np.cross(arm, f)
        elastic += 0.5 * k * (gap @ gap)
        power += d * (rate @ rate)
    return elastic, power


@njit(cache=True)
def body_states(q, qt, n_nodes, body_reference):
    """Per body: attitude body->LVLH, CoM (m), CoM velocity (m/s), angular velocity (rad/s), LVLH."""
    nb = body_reference.shape[0]
    rots = np.empty((nb, 3, 3))
    coms = np.empty((nb, 3))
    vels = np.empty((nb, 3))
    omegas = np.empty((nb, 3))
    for b in range(nb):
        base = 3 * n_nodes + 6 * b
        coms[b] = body_reference[b] + q[base:base + 3]
        vels[b] = qt[base:base + 3]
        rots[b] = rotation_matrix_from_rotation_vector(q[base + 3:base + 6])
        # in scalars: numba sends small matrix products to BLAS, microseconds a call
        for r in range(3):
            omegas[b, r] = rots[b, r, 0] * qt[base + 3] + rots[b, r, 1] * qt[base + 4] + rots[b, r, 2] * qt[base + 5]
    return rots, coms, vels, omegas
