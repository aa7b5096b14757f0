"""A thread's contact with one box over one step, sub-cycled with its deepest point followed inside the step.

Until 2026-11-27 (helper thread12) the thread contact (:mod:`multibody.contact_segment`) picked the segment's
deepest point once a step and integrated a particle at that point along a normal held over the step. A thread
rocking on a plate's two edges, or turning round an edge, changes its deepest point inside the step: the point
held was then shallower than the deepest one, the other edge sank unresisted for the rest of the step, and the
next step's contact started deeper than any force had paid for. The stored energy only jumped up (first order
in the step: +12 % of a 20 m/s strike's launch energy at 1e-4 s, docs/model.md "Contact").

Here the nodes themselves are the sub-cycle's state (positions and velocities relative to the body, body
frame, the body's attitude held over the step as in the node contact), and at every sub-step the contact is
evaluated again from them: the deepest point t* (:func:`multibody.segment_box.segment_box_deepest`, the middle
of the tied part when points tie), its normal perpendicular to the thread, the excess q over the deeper node's
own penetration (the no-double-count coordinate of :mod:`multibody.contact_segment`) and the split (1 - s, s)
over the nodes. So the contact's potential k q^(n+1)/(n+1), a maximum over the segment's points, is followed as
the maximum moves, and a switch of the deepest point costs at most one sub-step's error instead of one step's.

The nodes' non-contact accelerations are held over the step (as every contact of the kernel holds them); each
node's own contact against the same box is included in the nodes' motion here, so that the excess q over a node in
its own 0.15 ms impact follows that node's rebound instead of a free flight into the face: integrated and applied
here when all the node's threads in contact touch this box (the node contact, :mod:`multibody.contact_kernel`, skips
the pair), predicted only otherwise (its impulse is applied by the node contact). The body recoils with its mass and
inertia (velocity and spin changes, body frame) at the nodes, where its reactions act.

Since helper thread13 (2026-11-27) the unit integrated is a cluster (:func:`cluster_contact_over_step`): the threads
in contact with one box that share nodes, transitively (:mod:`multibody.thread_cluster`), with their nodes' own
contacts, as one system. Before, each thread had its own sub-cycle and a node with two or more threads in contact
had its own contact integrated by the node contact while each of its threads' sub-cycles predicted it without the
other threads' pushes: the paths differed and the threads' contacts started each step away from where their
sub-cycles ended them (docs/model.md, "Contact": the reference case's energy gain with the key on). A cluster of one
thread is the earlier sub-cycle, operation for operation (the one-thread strikes of
bench/bench_thread_strike_energy.py print the same figures).

Returns each node's mean and end velocity change by the thread's contact over the step (the kick and the
remainder carried to the next step, as the node contact), the energy the contact dissipated (Hunt-Crossley
damping, friction, and stored energy lost when a fast separation clips the force), and the contact's elastic
energy at the end of the sub-cycle (its work is then booked per contact: docs/model.md, "Contact").
Frames: the box's body frame (origin at the body's CoM); SI units.
"""
from __future__ import annotations

import math

from typing import NamedTuple

import numpy as np
from numba import njit

from multibody.jit_cache import NO_REFCOUNTS

from multibody.broad_phase import box_signed_distance
from multibody.contact import _power, hollar_friction_coefficient_inverse
from multibody.segment_box import (TIE_DISTANCE, deepest_between_breakpoints, segment_box_breakpoints,
                                   segment_box_normal, sublevel_between_breakpoints)


class ClusterWork(NamedTuple):
    """One cluster's nodes and threads for :func:`cluster_contact_over_step` (rows: the cluster's nodes, at most the
    net's n, and its threads, at most m; body frame of the cluster's body, SI units)."""

    n_nodes: np.ndarray         # (1,) int64 nodes in the cluster
    n_threads: np.ndarray       # (1,) int64 threads in the cluster
    node: np.ndarray            # (n,) int64 each row's net node
    thread: np.ndarray          # (m,) int64 each thread row's net thread; rows from n_threads on: threads on other boxes
                                # only that share the cluster's nodes (contact_segment._companion_threads), whose
                                # contacts are only predicted (foreign entries)
    threads: np.ndarray         # (m, 2) int64 each thread's two nodes as cluster rows
    row: np.ndarray             # (n,) int64 each net node's cluster row, -1 when not in the cluster being built
    carrier: np.ndarray         # (n,) int64 each node row's first thread row: the thread that carries its impulse
    position: np.ndarray        # (n, 3) the nodes, body frame (m); the sub-cycle moves them
    velocity: np.ndarray        # (n, 3) their start velocities relative to the body's material point (m/s)
    acceleration: np.ndarray    # (n, 3) their non-contact accelerations, held over the step (m/s^2)
    mass: np.ndarray            # (n,) node masses (kg)
    radius: np.ndarray          # (n,) node contact radii (m)
    own: np.ndarray             # (n,) int64 1: the node's own contact with the box is integrated here
    mean_change: np.ndarray     # (n, 3) out: each node's mean velocity change over the step (m/s)
    end_change: np.ndarray      # (n, 3) out: its velocity change at the step's end (m/s)
    predicted: np.ndarray       # (n, 3) work: the velocity change by a predicted own contact (m/s)
    relative: np.ndarray        # (n, 3) work: relative velocities at a sub-step (m/s)
    force: np.ndarray           # (n, 3) work: the threads' contact forces at a sub-step (N)
    own_force: np.ndarray       # (n, 3) work: the nodes' own contact forces at a sub-step (N)
    thread_energy: np.ndarray   # (m,) out: each thread's contact energy at the end of the sub-cycle (J)
    thread_lost: np.ndarray     # (m,) out: energy each thread's contact dissipated (J)
    node_lost: np.ndarray       # (n,) out: energy each owned node contact dissipated (J)
    # a thread of the cluster also in contact with another box this step (a thread pinched between two bodies): that
    # box's contact with it, predicted here (it moves the thread's nodes, its impulse is that box's cluster's)
    n_foreign: np.ndarray       # (1,) int64 such (thread row, other box) entries
    foreign_row: np.ndarray     # (m,) int64 the entry's thread row
    foreign_shape: np.ndarray   # (m,) int64 the other box
    foreign_rotation: np.ndarray  # (m, 3, 3) the other box's frame to this box's frame
    foreign_origin: np.ndarray  # (m, 3) the other body's CoM in this box's frame, relative to this body's (m)
    foreign_velocity: np.ndarray  # (m, 3) its velocity less this body's material point's there (m/s), this box's frame
    foreign_spin: np.ndarray    # (m, 3) its angular velocity less this body's (rad/s), this box's frame
    foreign_inverse_mass: np.ndarray  # (m,) 1 / the other body's mass (1/kg)
    foreign_work: np.ndarray    # (3, 2, 3) work: the thread's nodes' positions, velocities and forces in the other
                                # box's frame
    foreign_node: np.ndarray    # (2, 2) work: the thread's nodes' masses (kg) and radii (m)


def cluster_work(n_nodes: int, n_threads: int) -> ClusterWork:
    """Zeroed :class:`ClusterWork` for a net of ``n_nodes`` nodes and ``n_threads`` threads."""
    n, m = n_nodes, n_threads
    return ClusterWork(n_nodes=np.zeros(1, np.int64), n_threads=np.zeros(1, np.int64), node=np.zeros(n, np.int64),
                       thread=np.zeros(m, np.int64), threads=np.zeros((m, 2), np.int64), row=np.full(n, -1, np.int64),
                       carrier=np.zeros(n, np.int64), position=np.zeros((n, 3)), velocity=np.zeros((n, 3)),
                       acceleration=np.zeros((n, 3)), mass=np.ones(n), radius=np.zeros(n), own=np.zeros(n, np.int64),
                       mean_change=np.zeros((n, 3)),
                       end_change=np.zeros((n, 3)), predicted=np.zeros((n, 3)), relative=np.zeros((n, 3)),
                       force=np.zeros((n, 3)), own_force=np.zeros((n, 3)), thread_energy=np.zeros(m),
                       thread_lost=np.zeros(m), node_lost=np.zeros(n), n_foreign=np.zeros(1, np.int64),
                       foreign_row=np.zeros(m, np.int64), foreign_shape=np.zeros(m, np.int64),
                       foreign_rotation=np.zeros((m, 3, 3)), foreign_origin=np.zeros((m, 3)),
                       foreign_velocity=np.zeros((m, 3)), foreign_spin=np.zeros((m, 3)),
                       foreign_inverse_mass=np.zeros(m), foreign_work=np.zeros((3, 2, 3)),
                       foreign_node=np.ones((2, 2)))


@njit(cache=True, **NO_REFCOUNTS)
def thread_contact_geometry(pa, pc, box_min, box_max, s, radius_a, radius_c, work):
    """The thread's contact coordinate against box ``s`` for body-frame node positions ``pa``, ``pc`` (m).

    Parameters
    ----------
    pa, pc : tuple of 3 float
        The nodes, body frame (m).
    box_min, box_max : (ns, 3) float
        The shapes' corners, body frame (m); row ``s``.
    s : int
    radius_a, radius_c : float
        The nodes' contact radii (m); the thread's is the smaller.
    work : (MAX_BREAKPOINTS,) float
        Work space.

    Returns
    -------
    excess : float
        q (m): the deepest point's penetration less the deeper node's own (when it penetrates); -inf when the
        deepest point is not interior (not deeper than both nodes: a thread on a face adds nothing).
    depth : float
        The deepest point's penetration (m; negative for a gap).
    split : float
        s of the point (-).
    t_deepest : float
        The deepest point's parameter (-).
    end : int
        0: node a hands its load to the point, 1: node c, -1: neither penetrates.
    depth_a, depth_c : float
        The nodes' own penetrations (m).
    normal_a, normal_c : tuple of 3 float
        The box's normals at the nodes, body frame.
    """
    lo = (box_min[s, 0], box_min[s, 1], box_min[s, 2])
    hi = (box_max[s, 0], box_max[s, 1], box_max[s, 2])
    d = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    # the breakpoints sorted once for the deepest point and the tie interval (work is not written in between)
    k = segment_box_breakpoints(pa, d, lo, hi, work)
    t_deepest, distance = deepest_between_breakpoints(pa, d, lo, hi, work, k)
    gap_a, nax, nay, naz = box_signed_distance(pa[0], pa[1], pa[2], box_min, box_max, s)
    gap_c, ncx, ncy, ncz = box_signed_distance(pc[0], pc[1], pc[2], box_min, box_max, s)
    depth_a, depth_c = radius_a - gap_a, radius_c - gap_c
    depth = min(radius_a, radius_c) - distance
    end = -1
    if max(depth_a, depth_c) > 0.0:
        end = 0 if depth_a >= depth_c else 1
    excess = -math.inf
    split = t_deepest
    if depth > max(depth_a, depth_c) + TIE_DISTANCE:
        excess = depth - max(0.0, depth_a, depth_c)
        if excess > 0.0:
            t_low, t_high = sublevel_between_breakpoints(pa, d, lo, hi, distance + TIE_DISTANCE, work, k)
            if t_low <= t_high:
                split = 0.5 * (t_low + t_high)
    return (excess, depth, split, t_deepest, end, depth_a, depth_c, (nax, nay, naz), (ncx, ncy, ncz))


@njit(cache=True, inline="always")
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def _own_contact_kick(u0, u1, u2, p0, p1, p2, g0, g1, g2, inverse_mass, dt, own):
    """A node's own contact force ``g`` (body frame, N) over a sub-step: into the velocity change the sub-cycle
    integrates (``u``, m/s) when the thread owns the contact, else into the predicted change (``p``) that only
    moves the node here (the node contact integrates it). Returns the updated (u, p)."""
    if own:
        return u0 + dt * g0 * inverse_mass, u1 + dt * g1 * inverse_mass, u2 + dt * g2 * inverse_mass, p0, p1, p2
    return u0, u1, u2, p0 + dt * g0 * inverse_mass, p1 + dt * g1 * inverse_mass, p2 + dt * g2 * inverse_mass


@njit(cache=True, inline="always")
def _node_contact_force(depth, w, normal, mass, inverse_body_mass, stiffness, exponent, damping, mu_s, mu_k,
                        inverse_transition_speed, dt, friction):
    """A node's own contact force with the box at a sub-step (body frame, N): Hunt-Crossley along the box's normal
    at the node and, when ``friction`` (an owned contact), Hollar friction against its slip (never reversing it
    within the sub-step), as :func:`multibody.contact.contact_over_step`; with the energy it dissipates (J, zero
    unless ``friction``: a predicted contact books nothing)."""
    if depth <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    dn = _power(depth, exponent)
    elastic = stiffness * dn
    rate = -(w[0] * normal[0] + w[1] * normal[1] + w[2] * normal[2])
    fn = max(elastic + damping * dn * rate, 0.0)
    fx, fy, fz = fn * normal[0], fn * normal[1], fn * normal[2]
    if not friction:
        return fx, fy, fz, 0.0
    lost = (fn - elastic) * rate * dt
    gx, gy, gz = w[0] + rate * normal[0], w[1] + rate * normal[1], w[2] + rate * normal[2]
    slip = math.sqrt(gx * gx + gy * gy + gz * gz)
    if fn > 0.0 and slip > 0.0:
        mu = hollar_friction_coefficient_inverse(slip, mu_s, mu_k, inverse_transition_speed)
        reduced = 1.0 / (1.0 / mass + inverse_body_mass)
        magnitude = min(mu * fn, reduced * slip / dt)
        along = magnitude / slip
        fx -= along * gx
        fy -= along * gy
        fz -= along * gz
        lost += magnitude * slip * dt
    return fx, fy, fz, lost


@njit(cache=True, inline="always")
def _relative_velocity(rel, acc, u, p, x, i, t, bv0, bv1, bv2, bw0, bw1, bw2):
    """Node ``i``'s velocity relative to the body's material point at it, sub-cycle time ``t`` (m/s, body frame):
    start + non-contact + contact changes - the body's recoil there."""
    return (rel[i, 0] + acc[i, 0] * t + u[i, 0] + p[i, 0] - (bv0 + bw1 * x[i, 2] - bw2 * x[i, 1]),
            rel[i, 1] + acc[i, 1] * t + u[i, 1] + p[i, 1] - (bv1 + bw2 * x[i, 0] - bw0 * x[i, 2]),
            rel[i, 2] + acc[i, 2] * t + u[i, 2] + p[i, 2] - (bv2 + bw0 * x[i, 1] - bw1 * x[i, 0]))


@njit(cache=True, **NO_REFCOUNTS)
def _thread_contact_force(ka, kc, x, w, mass, box_min, box_max, s, radius, law, inverse_body_mass, dt, work, force):
    """The thread (cluster nodes ``ka``, ``kc``) contact's forces on its nodes at a sub-step, added to ``force``
    (body frame, N): F at the deepest point split (1 - s, s), and -(F . n) n_e on the deeper node e, which hands its
    load up to q to the point (the gradient of k q^(n+1)/(n+1); module doc). Returns the energy it dissipated over
    the sub-step (J) and 1 if it acted."""
    pa = (x[ka, 0], x[ka, 1], x[ka, 2])
    pc = (x[kc, 0], x[kc, 1], x[kc, 2])
    geometry = thread_contact_geometry(pa, pc, box_min, box_max, s, radius[ka], radius[kc], work)
    excess, depth, split, t_deepest, end, depth_a, depth_c, n_a, n_c = geometry
    if excess <= 0.0:
        return 0.0, 0
    wa = (w[ka, 0], w[ka, 1], w[ka, 2])
    wc = (w[kc, 0], w[kc, 1], w[kc, 2])
    wp, wq = 1.0 - split, split
    v = (wp * wa[0] + wq * wc[0], wp * wa[1] + wq * wc[1], wp * wa[2] + wq * wc[2])
    d = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    lo = (box_min[s, 0], box_min[s, 1], box_min[s, 2])
    hi = (box_max[s, 0], box_max[s, 1], box_max[s, 2])
    nx, ny, nz, slope = segment_box_normal(pa[0] + t_deepest * d[0], pa[1] + t_deepest * d[1],
                                           pa[2] + t_deepest * d[2], d[0], d[1], d[2], lo, hi, v[0], v[1], v[2])
    # q's rate: the point's closing speed times the depth's slope along the normal (below 1 where the point lies
    # inside the box, between two faces: segment_box_normal) ...
    rate = -slope * (v[0] * nx + v[1] * ny + v[2] * nz)
    me = (0.0, 0.0, 0.0)
    if end == 0:
        me = n_a
        rate += wa[0] * me[0] + wa[1] * me[1] + wa[2] * me[2]   # ... less node e's own
    elif end == 1:
        me = n_c
        rate += wc[0] * me[0] + wc[1] * me[1] + wc[2] * me[2]
    dn = _power(excess, law.exponent)
    elastic = law.stiffness * dn
    fn = max(elastic + law.damping * dn * rate, 0.0)
    dissipated = (fn - elastic) * rate * dt
    normal_speed = v[0] * nx + v[1] * ny + v[2] * nz
    gx, gy, gz = v[0] - normal_speed * nx, v[1] - normal_speed * ny, v[2] - normal_speed * nz
    # the point's normal force: the gradient of k q^(n+1)/(n+1), fn times the slope (fn alone made energy where the
    # point lies inside the box: segment_box_normal)
    pressure = fn * slope
    fx, fy, fz = pressure * nx, pressure * ny, pressure * nz
    slip = math.sqrt(gx * gx + gy * gy + gz * gz)
    if fn > 0.0 and slip > 0.0:
        mu = hollar_friction_coefficient_inverse(slip, law.mu_static, law.mu_kinetic, 1.0 / law.transition_speed)
        reduced = 1.0 / (wp * wp / mass[ka] + wq * wq / mass[kc] + inverse_body_mass)
        magnitude = min(mu * pressure, reduced * slip / dt)   # may stop the slip within a sub-step, not reverse it
        along = magnitude / slip
        fx -= along * gx
        fy -= along * gy
        fz -= along * gz
        dissipated += magnitude * slip * dt
    force[ka, 0] += wp * fx
    force[ka, 1] += wp * fy
    force[ka, 2] += wp * fz
    force[kc, 0] += wq * fx
    force[kc, 1] += wq * fy
    force[kc, 2] += wq * fz
    e = ka if end == 0 else kc
    if end >= 0:
        force[e, 0] -= fn * me[0]
        force[e, 1] -= fn * me[1]
        force[e, 2] -= fn * me[2]
    return dissipated, 1


@njit(cache=True, **NO_REFCOUNTS)
def _foreign_contact_kick(cluster, f, x, w, mass, radius, box_min, box_max, law, t, dt, work, p):
    """Entry ``f`` of the cluster's other-box contacts over a sub-step at time ``t``: the thread's contact with the
    other box (held in its start pose relative to this body, moving with its start relative velocity and spin) from
    the nodes' current positions ``x`` and velocities ``w`` (relative to this body, this box's frame), into their
    predicted velocity changes ``p`` (m/s). The other body is carried along by this body's recoil within the step (the
    sub-cycle's frame), its own recoil is not followed: a recoil moves a body by about F h^2 / (2 m) within a step,
    3e-9 m for a 500 N squeeze of the 832 kg ASAR at 1e-4 s, against a 0.2 mm squeeze."""
    r = cluster.foreign_row[f]
    s2 = cluster.foreign_shape[f]
    rot, origin = cluster.foreign_rotation[f], cluster.foreign_origin[f]
    velocity, spin = cluster.foreign_velocity[f], cluster.foreign_spin[f]
    position2, velocity2, force2 = cluster.foreign_work[0], cluster.foreign_work[1], cluster.foreign_work[2]
    rows = (cluster.threads[r, 0], cluster.threads[r, 1])
    for k in range(2):
        i = rows[k]
        # the node relative to the other body's CoM, and to its material point there, this box's frame
        dx = x[i, 0] - origin[0] - velocity[0] * t
        dy = x[i, 1] - origin[1] - velocity[1] * t
        dz = x[i, 2] - origin[2] - velocity[2] * t
        vx = w[i, 0] - velocity[0] - (spin[1] * dz - spin[2] * dy)
        vy = w[i, 1] - velocity[1] - (spin[2] * dx - spin[0] * dz)
        vz = w[i, 2] - velocity[2] - (spin[0] * dy - spin[1] * dx)
        for d in range(3):      # into the other box's frame (the transpose of its rotation to this frame)
            position2[k, d] = rot[0, d] * dx + rot[1, d] * dy + rot[2, d] * dz
            velocity2[k, d] = rot[0, d] * vx + rot[1, d] * vy + rot[2, d] * vz
        force2[k, 0] = force2[k, 1] = force2[k, 2] = 0.0
    pair = cluster.foreign_node     # the two nodes' masses (row 0) and radii (row 1)
    for k in range(2):
        pair[0, k], pair[1, k] = mass[rows[k]], radius[rows[k]]
    _thread_contact_force(0, 1, position2, velocity2, pair[0], box_min, box_max, s2, pair[1], law,
                          cluster.foreign_inverse_mass[f], dt, work, force2)
    for k in range(2):
        i = rows[k]
        for d in range(3):
            p[i, d] += dt * (rot[d, 0] * force2[k, 0] + rot[d, 1] * force2[k, 1] + rot[d, 2] * force2[k, 2]) / mass[i]


@njit(cache=True, **NO_REFCOUNTS)
def thread_contact_energy(ka, kc, x, box_min, box_max, s, radius, law, work):
    """The thread's (cluster nodes ``ka``, ``kc``) contact elastic energy k q^(n+1)/(n+1) at positions ``x`` (J)."""
    geometry = thread_contact_geometry((x[ka, 0], x[ka, 1], x[ka, 2]), (x[kc, 0], x[kc, 1], x[kc, 2]), box_min,
                                       box_max, s, radius[ka], radius[kc], work)
    excess = geometry[0]
    if excess <= 0.0:
        return 0.0
    return law.stiffness * _power(excess, law.exponent) * excess / (law.exponent + 1.0)


@njit(cache=True, **NO_REFCOUNTS)
def cluster_contact_over_step(cluster, box_min, box_max, s, body_mass, inverse_inertia_body, b, law, step,
                              n_substeps, work):
    """A cluster of threads in contact with box ``s`` of body ``b`` (threads that share nodes, and those nodes'
    own contacts with the box) over one step, as one system: every thread's contact and every node's own contact
    re-evaluated at every sub-step from the nodes' state (module doc).

    Parameters
    ----------
    cluster : ClusterWork
        The cluster's nodes and threads (:class:`ClusterWork`): in its first ``n_nodes`` rows the nodes at the
        evaluation (``position``, body frame, m), their velocities relative to the body's material point at each
        (``velocity``, m/s, body frame), their non-contact accelerations held over the step (``acceleration``,
        m/s^2, body frame), masses (kg), contact radii (m) and whether each node's own contact with this box is
        integrated here (``own``; else it only moves the node: a prediction); in its first ``n_threads`` rows the
        threads' nodes as cluster rows. On return ``mean_change`` and ``end_change`` hold each node's mean and end
        velocity change by the contacts integrated here (m/s, body frame), ``thread_energy`` each thread's contact
        energy at the end of the sub-cycle (J), ``thread_lost`` the energy each thread's contact dissipated and
        ``node_lost`` each owned node contact's (J).
    box_min, box_max : (ns, 3) float
        The shapes' corners, body frame (m); row ``s``.
    s : int
    body_mass : float
        The body's mass (kg).
    inverse_inertia_body : (nb, 3, 3) float
        Inverse inertia about the CoM, body frame (1 / (kg m^2)); row ``b``.
    b : int
    law : ContactLaw
        (:mod:`multibody.kernel`).
    step : float
        Integrator step (s).
    n_substeps : int
        Sub-steps (1: the plain force evaluation at the start).
    work : (MAX_BREAKPOINTS,) float
        Work space.

    Returns
    -------
    touched : int
        1 if a thread's contact acted in any sub-step.
    """
    k, m = cluster.n_nodes[0], cluster.n_threads[0]
    x, rel, acc, mass, radius = cluster.position, cluster.velocity, cluster.acceleration, cluster.mass, cluster.radius
    u, p, integral = cluster.end_change, cluster.predicted, cluster.mean_change
    w, force, own_force = cluster.relative, cluster.force, cluster.own_force
    threads, own = cluster.threads, cluster.own
    k_contact, exponent, damping = law.stiffness, law.exponent, law.damping
    mu_s, mu_k = law.mu_static, law.mu_kinetic
    inverse_transition_speed = 1.0 / law.transition_speed
    dt = step / n_substeps
    inv_body = 1.0 / body_mass
    j_inv = inverse_inertia_body
    u[:k] = 0.0             # the velocity change of each node by the contacts integrated here
    p[:k] = 0.0             # by its own contact when predicted only
    integral[:k] = 0.0      # the time integral of u
    cluster.thread_lost[:m] = 0.0
    cluster.node_lost[:k] = 0.0
    bv0 = bv1 = bv2 = bw0 = bw1 = bw2 = 0.0     # the body's velocity and spin change (body frame)
    touched = 0
    for j in range(n_substeps):
        t = j * dt
        for i in range(k):
            w[i, 0], w[i, 1], w[i, 2] = _relative_velocity(rel, acc, u, p, x, i, t, bv0, bv1, bv2, bw0, bw1, bw2)
        force[:k] = 0.0
        for r in range(m):
            lost, acted = _thread_contact_force(threads[r, 0], threads[r, 1], x, w, mass, box_min, box_max, s,
                                                radius, law, inv_body, dt, work, force)
            cluster.thread_lost[r] += lost
            touched = max(touched, acted)
        # each node's own contact with the box: integrated (owned) or predicted (module doc)
        for i in range(k):
            gap, nbx, nby, nbz = box_signed_distance(x[i, 0], x[i, 1], x[i, 2], box_min, box_max, s)
            gx, gy, gz, lost = _node_contact_force(radius[i] - gap, (w[i, 0], w[i, 1], w[i, 2]), (nbx, nby, nbz),
                                                   mass[i], inv_body, k_contact, exponent, damping, mu_s, mu_k,
                                                   inverse_transition_speed, dt, own[i] != 0)
            own_force[i, 0], own_force[i, 1], own_force[i, 2] = gx, gy, gz
            cluster.node_lost[i] += lost
        # the other boxes' contacts with the cluster's threads: predicted (they move the nodes, not applied here)
        for f in range(cluster.n_foreign[0]):
            _foreign_contact_kick(cluster, f, x, w, mass, radius, box_min, box_max, law, t, dt, work, p)
        # velocity updates (symplectic Euler, as the node contact's sub-cycle) and the body's recoil: every reaction
        # acts at the node it came from
        f0 = f1 = f2 = l0 = l1 = l2 = 0.0
        for i in range(k):
            inverse_mass = 1.0 / mass[i]
            u[i, 0] += dt * force[i, 0] * inverse_mass
            u[i, 1] += dt * force[i, 1] * inverse_mass
            u[i, 2] += dt * force[i, 2] * inverse_mass
            u[i, 0], u[i, 1], u[i, 2], p[i, 0], p[i, 1], p[i, 2] = _own_contact_kick(
                u[i, 0], u[i, 1], u[i, 2], p[i, 0], p[i, 1], p[i, 2], own_force[i, 0], own_force[i, 1],
                own_force[i, 2], inverse_mass, dt, own[i] != 0)
            total = (force[i, 0] + own_force[i, 0], force[i, 1] + own_force[i, 1], force[i, 2] + own_force[i, 2])
            f0, f1, f2 = f0 + total[0], f1 + total[1], f2 + total[2]
            moment = _cross((x[i, 0], x[i, 1], x[i, 2]), total)
            l0, l1, l2 = l0 + moment[0], l1 + moment[1], l2 + moment[2]
        bv0 -= dt * f0 * inv_body
        bv1 -= dt * f1 * inv_body
        bv2 -= dt * f2 * inv_body
        bw0 -= dt * (j_inv[b, 0, 0] * l0 + j_inv[b, 0, 1] * l1 + j_inv[b, 0, 2] * l2)
        bw1 -= dt * (j_inv[b, 1, 0] * l0 + j_inv[b, 1, 1] * l1 + j_inv[b, 1, 2] * l2)
        bw2 -= dt * (j_inv[b, 2, 0] * l0 + j_inv[b, 2, 1] * l1 + j_inv[b, 2, 2] * l2)
        # positions: the non-contact acceleration at mid-sub-step, the changes after the kick
        tm = t + 0.5 * dt
        for i in range(k):
            x[i, 0] += dt * (rel[i, 0] + acc[i, 0] * tm + u[i, 0] + p[i, 0] - (bv0 + bw1 * x[i, 2] - bw2 * x[i, 1]))
            x[i, 1] += dt * (rel[i, 1] + acc[i, 1] * tm + u[i, 1] + p[i, 1] - (bv1 + bw2 * x[i, 0] - bw0 * x[i, 2]))
            x[i, 2] += dt * (rel[i, 2] + acc[i, 2] * tm + u[i, 2] + p[i, 2] - (bv2 + bw0 * x[i, 1] - bw1 * x[i, 0]))
            integral[i, 0] += dt * u[i, 0]
            integral[i, 1] += dt * u[i, 1]
            integral[i, 2] += dt * u[i, 2]
    for i in range(k):
        integral[i, 0] /= step
        integral[i, 1] /= step
        integral[i, 2] /= step
    for r in range(m):
        cluster.thread_energy[r] = thread_contact_energy(threads[r, 0], threads[r, 1], x, box_min, box_max, s, radius,
                                                         law, work)
    return touched
