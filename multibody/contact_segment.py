"""Contact of a net thread (the segment between its two nodes) with the bodies' box shapes.

The node contact (:mod:`multibody.contact_kernel`, seed paper eq. (6)) acts on the nodes' spheres only,
so a thread whose two nodes lie on either side of a thin part (Envisat's 5 cm solar array, the 0.16 m
ASAR) passes through it with no force (:mod:`multibody.thread_crossing`). Here each thread is a capsule
of the thread's radius (the node contact radius, the smaller of its two nodes') around the segment, and
it touches a box shape under the same law as the nodes:

* **where**: the segment's deepest point against the box, :math:`t^* = \\arg\\min_t \\mathrm{sd}(a + t(b - a))`
  (the signed distance to a convex shape is convex along a line, and for a box it is piecewise a line,
  a square root of a quadratic or a maximum of lines between the points where the segment crosses the
  box's slab planes and mid-planes, so :func:`multibody.segment_box.segment_box_deepest` finds the minimum
  exactly). The force
  acts at that point (the middle of the part within :data:`TIE_DISTANCE` of it when several points tie, so a
  thread lying exactly flat across a plate narrower than the net's mesh takes its load at the middle of the
  overlap): there the force is the gradient of the contact's energy (envelope theorem: the depth's derivative
  along the segment is zero at its minimum). Until 2026-11-27 it acted at the centre of the part pressed at
  least half as deep, which is not that gradient: a thread turned by its contact (force off its nodes' centre
  of mass) gained energy (one thread falling flat at 20 m/s across a plate off its middle, s = 0.625: +33 % of
  its launch energy; helper peaks10, docs/model.md "Contact").
* **how much**: Hunt-Crossley normal force and the case's Hollar friction, as a node with the thread's
  radius at that point, integrated over the step by the thread's own sub-cycle (:mod:`multibody.segment_cycle`,
  helper thread12): its state is the two nodes (positions and velocities relative to the body, body frame), and
  at every sub-step the deepest point, its normal, its split and the excess q below are found again, so the
  point follows the thread as it rocks on a plate's two edges or turns round an edge (held over the step until
  2026-11-27, which made energy at each switch of the deepest point: +12 % of a 20 m/s strike's energy). The
  sub-steps are the node contact's rule (:func:`multibody.contact_kernel._substeps_to_resolve_contact`) for the
  point and for each node's own contact with the box; one sub-step when sub-cycling is off. Slow contacts are
  sub-cycled too (the node contact's implicit step would hold the point over the step).
* **the nodes' own contacts with the box**: integrated in the same sub-cycle, since the excess q depends on the
  deeper node's penetration, which changes within its own 0.15 ms impact. The threads in contact with a box that
  share nodes are integrated together as one cluster (:mod:`multibody.thread_cluster`, helper thread13): a node
  whose threads in contact all touch that box has its own contact with it integrated and applied there
  (``SegmentBuffers.owned_shape``; the node contact, :mod:`multibody.contact_kernel`, skips that node-box pair
  this step); a node with threads in contact with several boxes has it integrated by the node contact, and the
  clusters only predict it (it moves their nodes, its impulse is not applied twice). Until 2026-11-27 each thread
  had its own sub-cycle and owned a node's contact only when it was the node's one thread in contact. Measured
  (one thread striking over a plate's edge at 20 m/s, bench/bench_thread_strike_energy.py): the balance closes to
  +0.63 % with the node's contact owned, +1.7 % with it only predicted, +15.6 % with the node in free flight in
  the sub-cycle.
* **who carries it**: a force F at :math:`p = (1 - s) x_a + s x_b` is split (1 - s) F on node a and s F on
  node b, so the point's acceleration is F / m_p with the effective mass

  .. math:: m_p = \\Big(\\frac{(1 - s)^2}{m_a} + \\frac{s^2}{m_b}\\Big)^{-1}

  (2 m for the middle of a thread between equal nodes). The body takes each node's reaction at that node (the
  same moment as -F at p for the split, so linear and angular momentum are exchanged exactly); within the
  sub-cycle it recoils with its mass and inertia.
* **no double count**: the node contact already carries the nodes' own spheres, so a thread adds only
  where its interior is deeper than both its ends (the deepest point is interior), and only by its excess
  over the deeper node e when that node's sphere penetrates, :math:`q = \delta(t^*) - \max(0, \delta_a,
  \delta_b)`: a thread lying on a flat face (its penetration linear along it, deepest at an end) adds
  nothing; one bent over an edge, or across a plate narrower than the mesh, adds the whole contact. The
  forces are the gradient of the contact's energy :math:`k q^{n+1}/(n+1)`: besides F at the point, -F n_e on
  node e (it hands its load up to q over to the point) with its reaction on the body at the node, so the
  contact is conservative in q and momentum stays exact.
* **the normal**: from the box to the deepest point, perpendicular to the thread (outside the box the
  nearest-point direction is; inside, the combination of the two nearest faces that is), so the contact
  never pushes a thread along itself.

As in the node contact, each node's velocity change over the step is applied as the kick that makes the
integrator's next drift follow the sub-cycle's path, and its remainder (the end minus the mean change) is
carried to the next evaluation, per thread and node. Each thread's contact energy at a step's start less the
energy its sub-cycle ended the previous step with is summed per thread (``SegmentBuffers.energy_jump``: the
energy the splitting into steps made, the cause measured above), with the energy it dissipated
(``SegmentBuffers.dissipated``), so the balance can be checked contact by contact.

Shapes: boxes only (``ShapeArrays.is_box``; the Envisat array, ASAR and main body). Cylinders, spheres,
ellipsoids and mesh files keep node contact alone: their pass-throughs are still found and bounded by
:mod:`multibody.thread_crossing` and :mod:`structures.thread_gaps` (the Ka-band boom and dish).

Frames: LVLH unless named; the shapes in their body frames (origin at the body's CoM). SI units.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from multibody.broad_phase import box_signed_distance
from multibody.contact import hertz_elastic_energy

from multibody.contact_kernel import _effective_mass_of_body, _substeps_to_resolve_contact, add_body_reaction
from multibody.jit_cache import WITH_REFCOUNTS
from multibody.segment_box import MAX_BREAKPOINTS, segment_box_normal
from multibody.segment_cycle import ClusterWork, cluster_contact_over_step, cluster_work, thread_contact_geometry
from multibody.thread_cluster import group_pairs


class SegmentBuffers(NamedTuple):
    """The thread contact's switch, the impulses it carries from step to step, its per-thread energy record and
    work space (m threads, n nodes, ns shapes; zero-size arrays when off)."""

    enabled: int                    # 1: threads take segment contact (case key contact.thread_segments)
    lag_impulse_lvlh: np.ndarray    # (m, 2, 3) impulse still to apply on the thread's two nodes at the next evaluation
                                    # (N s), LVLH; the body's reaction at the nodes
    lag_body: np.ndarray            # (m,) int64 body of that impulse, -1 for none
    end_energy: np.ndarray          # (2, m) the thread's contact energy at the end of the last step's sub-cycles and of
                                    # this step's (J); -1: not known (a slow contact's implicit step)
    start_energy: np.ndarray        # (m,) the same at this evaluation's start (J), work
    energy_jump: np.ndarray         # (m,) per thread, the sum over steps of its contact energy at a step's start less
                                    # the energy its sub-cycle ended the last step with (J): energy the step made
    dissipated: np.ndarray          # (m,) per thread, the energy its contact dissipated (J)
    node_force_lvlh: np.ndarray     # (3, n) this pass's forces on the nodes (N), LVLH, coordinate-major
    lag_velocity_lvlh: np.ndarray   # (3, n) the carried impulses' velocity change of each node (m/s), LVLH
    centre_distance: np.ndarray     # (ns, n) each node's distance to each shape's bounding-sphere centre (m)
    node_speed: np.ndarray          # (n,) bound of each node's speed over the step (m/s)
    shape_work: np.ndarray          # (2, ns) each shape's bounding-sphere radius (m) and surface speed bound (m/s)
    breakpoints: np.ndarray         # (MAX_BREAKPOINTS,) work: a segment's sorted breakpoints
    contact_scalar: np.ndarray      # (5, 1) work: penetration, body mass (sub-step count)
    contact_vector: np.ndarray      # (6, 1, 3) work: relative velocity, normal (sub-step count)
    external_force: np.ndarray      # (3,) work: the point's non-contact force (N), LVLH
    cycle_out: np.ndarray           # (4, 3) work: the sub-cycle's mean and end velocity changes of the nodes
    owned_shape: np.ndarray         # (n,) int64 the box whose contact with the node a thread's sub-cycle integrates
                                    # this step (the node contact skips that pair); -1: none
    node_threads: np.ndarray        # (n,) int64 each node's threads in contact with a box this step
    node_shape: np.ndarray          # (n,) int64 the box all the node's threads in contact touch this step; -1: none,
                                    # -2: several boxes
    pair_thread: np.ndarray         # (m ns,) int64 this step's (thread, box) contact pairs: the thread
    pair_shape: np.ndarray          # (m ns,) int64 ... and the box
    pair_order: np.ndarray          # (m ns,) int64 work: the pairs cluster after cluster (multibody.thread_cluster)
    cluster_start: np.ndarray       # (m ns + 1,) int64 work: each cluster's first entry in pair_order
    cluster_parent: np.ndarray      # (ns n,) int64 work: union-find over (node, box)
    root_cluster: np.ndarray        # (ns n,) int64 work: each root's cluster, -1 between uses
    cluster: ClusterWork            # one cluster's nodes and threads for its sub-cycle (multibody.segment_cycle)
    sharing: np.ndarray             # (2, m) int64 the most threads in contact at either node of the thread, the last
                                    # step and this one (0: the thread not in contact)
    jump_by_sharing: np.ndarray     # (2, 6) the energy made between steps (J, row 0) and the thread-steps it sums (row
                                    # 1), by the thread's sharing in the step before (column: 1, 2, 3, 4 or more);
                                    # column 0: threads not in contact the step before (arrivals) with neither node
                                    # in its own contact with the box at the start, column 5: with one


def segment_buffers(n_threads: int, n_nodes: int, n_shapes: int, enabled: bool) -> SegmentBuffers:
    """Zeroed :class:`SegmentBuffers`; with ``enabled`` False every array is empty (nothing to carry).

    Parameters
    ----------
    n_threads, n_nodes, n_shapes : int
    enabled : bool
        The case's ``contact.thread_segments``.
    """
    m, n, ns = (n_threads, n_nodes, n_shapes) if enabled else (0, 0, 0)
    return SegmentBuffers(enabled=int(bool(enabled)), lag_impulse_lvlh=np.zeros((m, 2, 3)),
                          lag_body=np.full(m, -1, np.int64), end_energy=np.zeros((2, m)), start_energy=np.zeros(m),
                          energy_jump=np.zeros(m), dissipated=np.zeros(m),
                          node_force_lvlh=np.zeros((3, n)), lag_velocity_lvlh=np.zeros((3, n)),
                          centre_distance=np.zeros((ns, n)), node_speed=np.zeros(n), shape_work=np.zeros((2, ns)),
                          breakpoints=np.zeros(MAX_BREAKPOINTS), contact_scalar=np.zeros((5, 1)),
                          contact_vector=np.zeros((6, 1, 3)), external_force=np.zeros(3), cycle_out=np.zeros((4, 3)),
                          owned_shape=np.full(n, -1, np.int64), node_threads=np.zeros(n, np.int64),
                          node_shape=np.full(n, -1, np.int64), pair_thread=np.zeros(m * ns, np.int64),
                          pair_shape=np.zeros(m * ns, np.int64), pair_order=np.zeros(m * ns, np.int64),
                          cluster_start=np.zeros(m * ns + 1, np.int64), cluster_parent=np.zeros(ns * n, np.int64),
                          root_cluster=np.full(ns * n, -1, np.int64), cluster=cluster_work(n, m),
                          sharing=np.zeros((2, m), np.int64), jump_by_sharing=np.zeros((2, 6)))


@njit(cache=True, inline="always")
def point_effective_mass(mass_a, mass_b, split):
    """Mass (kg) a thread's point at ``split`` s shows to a force split (1 - s, s) over its nodes:
    1 / ((1 - s)^2 / m_a + s^2 / m_b) (module doc).

    Parameters
    ----------
    mass_a, mass_b : float
        Node masses (kg).
    split : float
        s in [0, 1] (-).
    """
    return 1.0 / ((1.0 - split) ** 2 / mass_a + split * split / mass_b)


@njit(cache=True, inline="always")
def _apply_at_point(a, b, split, body, fx, fy, fz, arm_x, arm_y, arm_z, weight, node_force_lvlh, body_force_lvlh,
                    torque_lvlh, out_body_impulse, out_node_impulse):
    """Force (fx, fy, fz) (N, LVLH) at a thread's point, split (1 - s, s) over nodes a and b, and its reaction
    on ``body`` at the same point (``arm``: from the body's CoM, LVLH, m); the impulses (times ``weight``)
    accumulate per body and per node."""
    wa, wb = 1.0 - split, split
    node_force_lvlh[0, a] += wa * fx
    node_force_lvlh[1, a] += wa * fy
    node_force_lvlh[2, a] += wa * fz
    node_force_lvlh[0, b] += wb * fx
    node_force_lvlh[1, b] += wb * fy
    node_force_lvlh[2, b] += wb * fz
    add_body_reaction(body, fx, fy, fz, arm_x, arm_y, arm_z, weight, body_force_lvlh, torque_lvlh, out_body_impulse)
    out_node_impulse[a, 0] += wa * fx * weight
    out_node_impulse[a, 1] += wa * fy * weight
    out_node_impulse[a, 2] += wa * fz * weight
    out_node_impulse[b, 0] += wb * fx * weight
    out_node_impulse[b, 1] += wb * fy * weight
    out_node_impulse[b, 2] += wb * fz * weight


@njit(cache=True)
def _release_carried(x, seg, threads, net_mass, states, step, stage_weight, body_force_lvlh, torque_lvlh,
                     out_body_impulse, out_node_impulse):
    """Apply every thread's impulses carried from the previous step (its contact's end minus mean velocity
    change of each node) as forces over this step on its two nodes, the body's reactions at the nodes, and note
    the velocity change they give each node (``seg.lag_velocity_lvlh``) for this step's contact start velocities;
    clears the carried impulses."""
    lag_velocity = seg.lag_velocity_lvlh
    lag_velocity[:] = 0.0
    com_lvlh = states.com_lvlh
    inverse_step = 1.0 / step
    for j in range(threads.shape[0]):
        b = seg.lag_body[j]
        if b < 0:
            continue
        for k in range(2):
            i = threads[j, k]
            jx, jy, jz = seg.lag_impulse_lvlh[j, k, 0], seg.lag_impulse_lvlh[j, k, 1], seg.lag_impulse_lvlh[j, k, 2]
            lag_velocity[0, i] += jx / net_mass[i]
            lag_velocity[1, i] += jy / net_mass[i]
            lag_velocity[2, i] += jz / net_mass[i]
            _apply_at_point(i, i, 0.0, b, jx * inverse_step, jy * inverse_step, jz * inverse_step,
                            x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2],
                            step * stage_weight, seg.node_force_lvlh, body_force_lvlh, torque_lvlh, out_body_impulse,
                            out_node_impulse)
        seg.lag_body[j] = -1


@njit(cache=True)
def _near_shapes(x, v, net_force_lvlh, net_mass, velocity_lag, seg, states, shapes, step):
    """Each node's speed bound over the step (``seg.node_speed``, m/s: L1 norms, an upper bound), each box
    shape's bounding sphere (radius) and surface speed bound (``seg.shape_work``), and each node's distance
    to each box's centre (``seg.centre_distance``, m), for the thread broad phase."""
    n = x.shape[1]
    speed = seg.node_speed
    lag = seg.lag_velocity_lvlh
    for i in range(n):
        speed[i] = (abs(v[0, i] + velocity_lag[0, i] + lag[0, i]) + abs(v[1, i] + velocity_lag[1, i] + lag[1, i])
                    + abs(v[2, i] + velocity_lag[2, i] + lag[2, i])
                    + step * (abs(net_force_lvlh[0, i]) + abs(net_force_lvlh[1, i]) + abs(net_force_lvlh[2, i]))
                    / net_mass[i])
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    box_min, box_max = shapes.box_min_body, shapes.box_max_body
    for s in range(shapes.body.shape[0]):
        if shapes.is_box[s] == 0:
            continue
        b = shapes.body[s]
        mx, my, mz = (0.5 * (box_min[s, 0] + box_max[s, 0]), 0.5 * (box_min[s, 1] + box_max[s, 1]),
                      0.5 * (box_min[s, 2] + box_max[s, 2]))
        cx = com_lvlh[b, 0] + body_to_lvlh[b, 0, 0] * mx + body_to_lvlh[b, 0, 1] * my + body_to_lvlh[b, 0, 2] * mz
        cy = com_lvlh[b, 1] + body_to_lvlh[b, 1, 0] * mx + body_to_lvlh[b, 1, 1] * my + body_to_lvlh[b, 1, 2] * mz
        cz = com_lvlh[b, 2] + body_to_lvlh[b, 2, 0] * mx + body_to_lvlh[b, 2, 1] * my + body_to_lvlh[b, 2, 2] * mz
        seg.shape_work[0, s] = 0.5 * math.sqrt((box_max[s, 0] - box_min[s, 0]) ** 2
                                               + (box_max[s, 1] - box_min[s, 1]) ** 2
                                               + (box_max[s, 2] - box_min[s, 2]) ** 2)
        extent = math.sqrt(max(box_min[s, 0] ** 2 + box_min[s, 1] ** 2 + box_min[s, 2] ** 2,
                               box_max[s, 0] ** 2 + box_max[s, 1] ** 2 + box_max[s, 2] ** 2))
        speed_b = math.sqrt(velocity_lvlh[b, 0] ** 2 + velocity_lvlh[b, 1] ** 2 + velocity_lvlh[b, 2] ** 2)
        spin_b = math.sqrt(omega_lvlh[b, 0] ** 2 + omega_lvlh[b, 1] ** 2 + omega_lvlh[b, 2] ** 2)
        seg.shape_work[1, s] = speed_b + spin_b * extent
        row = seg.centre_distance[s]
        x0, x1, x2 = x[0], x[1], x[2]
        for i in range(n):
            row[i] = math.sqrt((x0[i] - cx) ** 2 + (x1[i] - cy) ** 2 + (x2[i] - cz) ** 2)


@njit(cache=True, **WITH_REFCOUNTS)  # allocates; called from a NO_REFCOUNTS kernel (jit_cache)
def add_segment_contact_forces(x, v, net, states, bodies, shapes, law, step, n_substeps, stage_weight, buffers,
                               net_force_lvlh, body_force_lvlh, torque_lvlh):
    """Add the threads' contact forces with the box shapes (module doc) to ``net_force_lvlh`` and their
    reactions to ``body_force_lvlh`` / ``torque_lvlh``; nothing when ``buffers.segments.enabled`` is 0.

    Runs before the node contact (:func:`multibody.contact_kernel.add_contact_forces`), so that the nodes' own
    contacts see these forces as part of their non-contact force, and the node contact's carried velocity
    (``buffers.velocity_lag``) still holds the previous step's.

    Parameters
    ----------
    x, v : (3, n) float
        Node positions (m) and mid-step velocities (m/s) at the evaluation state, LVLH, coordinate-major.
    net, states, bodies, shapes, law : NetArrays, BodyStates, BodyArrays, ShapeArrays, ContactLaw
        (:mod:`multibody.kernel`).
    step : float
        Integrator step (s).
    n_substeps : int
        Contact sub-steps per step (1: plain force evaluation, no sub-cycle and no implicit step).
    stage_weight : float
        Weight of the accumulated impulses and energies (1 / force evaluations per step).
    buffers : KernelBuffers
        Its ``segments`` (:class:`SegmentBuffers`), impulse accumulators and the node contact's carried velocity.
    net_force_lvlh : (3, n) float
        Enters holding the non-contact forces on the nodes (N, LVLH); the threads' contact forces are added.
    body_force_lvlh, torque_lvlh : (nb, 3) float
        The reactions are added: force (N) and torque about the CoM (N m), LVLH.

    Returns
    -------
    contact_energy : float
        Elastic energy of the threads' contacts (J) at this evaluation.
    n_contacts : int
        Penetrating thread contacts.
    dissipated : float
        Energy dissipated by them over the step (J, weighted by ``stage_weight``).
    """
    seg = buffers.segments
    if seg.enabled == 0:
        return 0.0, 0, 0.0
    threads, net_mass = net.threads, net.mass
    out_body_impulse, out_node_impulse = buffers.body_impulse_lvlh, buffers.node_impulse_lvlh
    node_force = seg.node_force_lvlh
    node_force[:] = 0.0
    _release_carried(x, seg, threads, net_mass, states, step, stage_weight, body_force_lvlh, torque_lvlh,
                               out_body_impulse, out_node_impulse)
    _near_shapes(x, v, net_force_lvlh, net_mass, buffers.velocity_lag, seg, states, shapes, step)
    energy, count, dissipated = 0.0, 0, 0.0
    # the per-thread energy record: this step's sub-cycles write their end energies into row 1
    seg.end_energy[0, :] = seg.end_energy[1, :]
    seg.end_energy[1, :] = 0.0
    seg.start_energy[:] = 0.0
    seg.sharing[0, :] = seg.sharing[1, :]
    seg.sharing[1, :] = 0
    seg.owned_shape[:] = -1
    seg.node_threads[:] = 0
    seg.node_shape[:] = -1
    n_pairs = _contact_pairs(x, v, net_force_lvlh, net, states, shapes, step, n_substeps, buffers)
    # the threads in contact with a box that share nodes, and those nodes' own contacts, as one system each
    n_clusters = group_pairs(seg.pair_thread, seg.pair_shape, n_pairs, threads, x.shape[1], seg.cluster_parent,
                             seg.root_cluster, seg.pair_order, seg.cluster_start)
    for k in range(n_clusters):
        e, count_k, w = _cluster_on_box(seg.cluster_start[k], seg.cluster_start[k + 1], x, v, net_force_lvlh, net,
                                        states, bodies, shapes, law, step, n_substeps, stage_weight, buffers,
                                        body_force_lvlh, torque_lvlh)
        energy += e
        count += count_k
        dissipated += w
    net_force_lvlh += node_force
    if n_substeps > 1:
        # the energy each thread's contact starts this step with less what its sub-cycle ended the last with: the
        # energy made between the steps (one force evaluation a step: Verlet)
        for j in range(threads.shape[0]):
            if seg.end_energy[0, j] >= 0.0:
                jump = seg.start_energy[j] - seg.end_energy[0, j]
                seg.energy_jump[j] += jump
                if jump != 0.0 or seg.sharing[0, j] != 0:
                    column = 5 if seg.sharing[0, j] < 0 else min(seg.sharing[0, j], 4)
                    seg.jump_by_sharing[0, column] += jump
                    seg.jump_by_sharing[1, column] += 1.0
    return energy, count, dissipated


@njit(cache=True, inline="always")
def _to_body(x, i, body_to_lvlh, com_lvlh, b):
    """Node ``i`` of the coordinate-major LVLH positions ``x`` in body ``b``'s frame (m), as a tuple."""
    ax, ay, az = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
    return (body_to_lvlh[b, 0, 0] * ax + body_to_lvlh[b, 1, 0] * ay + body_to_lvlh[b, 2, 0] * az,
            body_to_lvlh[b, 0, 1] * ax + body_to_lvlh[b, 1, 1] * ay + body_to_lvlh[b, 2, 1] * az,
            body_to_lvlh[b, 0, 2] * ax + body_to_lvlh[b, 1, 2] * ay + body_to_lvlh[b, 2, 2] * az)


@njit(cache=True, inline="always")
def _node_motion(i, b, x, v, net_force_lvlh, net_mass, node_lag, lag, states, half_kick):
    """Node ``i``'s start velocity relative to body ``b``'s material point at it (as the node contact's, m/s) and its
    non-contact acceleration (m/s^2), both in the body frame, as two tuples."""
    rot, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    ux = v[0, i] + node_lag[0, i] + lag[0, i] + half_kick * net_force_lvlh[0, i] / net_mass[i]
    uy = v[1, i] + node_lag[1, i] + lag[1, i] + half_kick * net_force_lvlh[1, i] / net_mass[i]
    uz = v[2, i] + node_lag[2, i] + lag[2, i] + half_kick * net_force_lvlh[2, i] / net_mass[i]
    rx, ry, rz = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
    wx = ux - velocity_lvlh[b, 0] - (omega_lvlh[b, 1] * rz - omega_lvlh[b, 2] * ry)
    wy = uy - velocity_lvlh[b, 1] - (omega_lvlh[b, 2] * rx - omega_lvlh[b, 0] * rz)
    wz = uz - velocity_lvlh[b, 2] - (omega_lvlh[b, 0] * ry - omega_lvlh[b, 1] * rx)
    fx, fy = net_force_lvlh[0, i] / net_mass[i], net_force_lvlh[1, i] / net_mass[i]
    fz = net_force_lvlh[2, i] / net_mass[i]
    rel = (rot[b, 0, 0] * wx + rot[b, 1, 0] * wy + rot[b, 2, 0] * wz,
           rot[b, 0, 1] * wx + rot[b, 1, 1] * wy + rot[b, 2, 1] * wz,
           rot[b, 0, 2] * wx + rot[b, 1, 2] * wy + rot[b, 2, 2] * wz)
    acc = (rot[b, 0, 0] * fx + rot[b, 1, 0] * fy + rot[b, 2, 0] * fz,
           rot[b, 0, 1] * fx + rot[b, 1, 1] * fy + rot[b, 2, 1] * fz,
           rot[b, 0, 2] * fx + rot[b, 1, 2] * fy + rot[b, 2, 2] * fz)
    return rel, acc


@njit(cache=True)
def _contact_pairs(x, v, net_force_lvlh, net, states, shapes, step, n_substeps, buffers):
    """This step's (thread, box) contact pairs into ``seg.pair_thread`` / ``seg.pair_shape``: the thread's deepest
    point is interior and penetrates now, or does at the end of the step's free motion (a thread turning over an
    edge). Counts each node's threads in contact (``seg.node_threads``) and notes the box they touch
    (``seg.node_shape``). Returns the number of pairs."""
    seg = buffers.segments
    threads, net_mass, radius = net.threads, net.mass, net.radius
    centre_distance, node_speed = seg.centre_distance, seg.node_speed
    sphere_radius, surface_speed = seg.shape_work[0], seg.shape_work[1]
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    box_min, box_max, shape_body, is_box = shapes.box_min_body, shapes.box_max_body, shapes.body, shapes.is_box
    n_pairs = 0
    for j in range(threads.shape[0]):
        a, c = threads[j, 0], threads[j, 1]
        length = math.sqrt((x[0, c] - x[0, a]) ** 2 + (x[1, c] - x[1, a]) ** 2 + (x[2, c] - x[2, a]) ** 2)
        motion = step * max(node_speed[a], node_speed[c])
        thread_radius = min(radius[a], radius[c])
        for s in range(shape_body.shape[0]):
            if is_box[s] == 0:
                continue
            # what the thread and the surface can close within the step, plus the thread's radius
            reach = 1.001 * (thread_radius + motion + step * surface_speed[s])
            # every point of the segment is at least (|a - o| + |b - o| - L) / 2 from the box's centre o
            if 0.5 * (centre_distance[s, a] + centre_distance[s, c] - length) > sphere_radius[s] + reach:
                continue
            b = shape_body[s]
            pa = _to_body(x, a, body_to_lvlh, com_lvlh, b)
            pc = _to_body(x, c, body_to_lvlh, com_lvlh, b)
            if (min(pa[0], pc[0]) > box_max[s, 0] + reach or max(pa[0], pc[0]) < box_min[s, 0] - reach
                    or min(pa[1], pc[1]) > box_max[s, 1] + reach or max(pa[1], pc[1]) < box_min[s, 1] - reach
                    or min(pa[2], pc[2]) > box_max[s, 2] + reach or max(pa[2], pc[2]) < box_min[s, 2] - reach):
                continue
            if not _touches_within_step(a, c, s, b, pa, pc, x, v, net_force_lvlh, net_mass, radius, states, shapes,
                                        step, n_substeps, buffers):
                continue
            seg.pair_thread[n_pairs] = j
            seg.pair_shape[n_pairs] = s
            n_pairs += 1
            for i in (a, c):
                seg.node_threads[i] += 1
                if seg.node_shape[i] == -1:
                    seg.node_shape[i] = s
                elif seg.node_shape[i] != s:
                    seg.node_shape[i] = -2
    return n_pairs


@njit(cache=True)
def _touches_within_step(a, c, s, b, pa, pc, x, v, net_force_lvlh, net_mass, radius, states, shapes, step, n_substeps,
                         buffers):
    """Whether thread (a, c)'s contact with box ``s`` can act within the step: it penetrates now, or at the end of
    the step's free motion (a thread turning over an edge, whose deepest point is not yet interior at the start), or
    exactly one of its nodes is in its own contact with the box now or then.

    The last: a thread with one node striking a face and the other beyond the face's edge lies flat at first (its
    deepest point ties with the node: no excess), then turns over the edge within the node's own 0.15 ms impact,
    which the free motion does not foresee (the node's rebound raises the edge point's excess over it). Found late,
    such a thread started the next step up to about a millimetre into its contact, energy no force paid for:
    measured, 24 such arrivals made +2.87 % of the reference case's energy at its ASAR strike (0.049 s; helper
    thread13, bench/thread_contact_drift.py, the record's "arrivals (a node in its own contact)")."""
    seg = buffers.segments
    box_min, box_max = shapes.box_min_body, shapes.box_max_body
    now = thread_contact_geometry(pa, pc, box_min, box_max, s, radius[a], radius[c], seg.breakpoints)
    if now[0] > 0.0 or (now[5] > 0.0) != (now[6] > 0.0):
        return True
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    rel_a, acc_a = _node_motion(a, b, x, v, net_force_lvlh, net_mass, buffers.velocity_lag, seg.lag_velocity_lvlh,
                                states, half_kick)
    rel_c, acc_c = _node_motion(c, b, x, v, net_force_lvlh, net_mass, buffers.velocity_lag, seg.lag_velocity_lvlh,
                                states, half_kick)
    h2 = 0.5 * step * step
    qa = (pa[0] + step * rel_a[0] + h2 * acc_a[0], pa[1] + step * rel_a[1] + h2 * acc_a[1],
          pa[2] + step * rel_a[2] + h2 * acc_a[2])
    qc = (pc[0] + step * rel_c[0] + h2 * acc_c[0], pc[1] + step * rel_c[1] + h2 * acc_c[1],
          pc[2] + step * rel_c[2] + h2 * acc_c[2])
    ahead = thread_contact_geometry(qa, qc, box_min, box_max, s, radius[a], radius[c], seg.breakpoints)
    return ahead[0] > 0.0 or (ahead[5] > 0.0) != (ahead[6] > 0.0)


@njit(cache=True)
def _cluster_on_box(first, last, x, v, net_force_lvlh, net, states, bodies, shapes, law, step, n_substeps,
                    stage_weight, buffers, body_force_lvlh, torque_lvlh):
    """The cluster of (thread, box) pairs ``seg.pair_order[first:last]`` (one box, threads sharing nodes:
    :mod:`multibody.thread_cluster`) over the step as one system (:func:`multibody.segment_cycle.
    cluster_contact_over_step`); returns the contacts' elastic energy at the start (J), the penetrating contacts,
    and the energy they dissipated (J, weighted).

    Each thread's contact coordinate is the excess q = delta(t*) - delta_e of its deepest point over the deeper
    node e when that node's own sphere penetrates (else q = delta(t*)), and its forces are its energy's gradient
    (module doc). A node's own contact with the box is integrated in the cluster (the node contact skips that pair
    this step) when all the node's threads in contact touch this box; otherwise (threads on several boxes) the
    node contact integrates it with all the threads' pushes and the cluster only predicts it. Each node's impulse
    goes through the first of its threads in the cluster (its carried remainder too); the body takes every
    reaction at the nodes."""
    seg = buffers.segments
    cw = seg.cluster
    threads, net_mass, radius = net.threads, net.mass, net.radius
    rot, com_lvlh = states.body_to_lvlh, states.com_lvlh
    s = seg.pair_shape[seg.pair_order[first]]
    b = shapes.body[s]
    box_min, box_max = shapes.box_min_body, shapes.box_max_body
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    energy, count = 0.0, 0
    k = 0
    for r in range(last - first):
        j = seg.pair_thread[seg.pair_order[first + r]]
        cw.thread[r] = j
        for e in range(2):
            i = threads[j, e]
            if cw.row[i] < 0:
                cw.row[i] = k
                cw.node[k] = i
                cw.carrier[k] = r
                position = _to_body(x, i, rot, com_lvlh, b)
                rel, acc = _node_motion(i, b, x, v, net_force_lvlh, net_mass, buffers.velocity_lag,
                                        seg.lag_velocity_lvlh, states, half_kick)
                for d in range(3):
                    cw.position[k, d], cw.velocity[k, d], cw.acceleration[k, d] = position[d], rel[d], acc[d]
                cw.mass[k], cw.radius[k] = net_mass[i], radius[i]
                cw.own[k] = 1 if seg.node_shape[i] == s else 0
                if cw.own[k] == 1:
                    seg.owned_shape[i] = s
                    depth = radius[i] - box_signed_distance(position[0], position[1], position[2], box_min, box_max,
                                                            s)[0]
                    if depth > 0.0:
                        energy += hertz_elastic_energy(depth, law.stiffness, law.exponent)
                        count += 1
                k += 1
            cw.threads[r, e] = cw.row[i]
    m = last - first
    cw.n_nodes[0], cw.n_threads[0] = k, m
    n_cycle = 1
    for r in range(m):
        j = cw.thread[r]
        e, touching, n_thread = _thread_start(r, j, s, b, x, cw, shapes, bodies, rot, com_lvlh, law, step, n_substeps,
                                              seg)
        energy += e
        count += touching
        n_cycle = max(n_cycle, n_thread)
    cluster_contact_over_step(cw, box_min, box_max, s, bodies.mass[b], bodies.inverse_inertia_body, b, law, step,
                              n_cycle, seg.breakpoints)
    lost_total = 0.0
    impulses = seg.cycle_out   # rows: node a's mean and end impulse (LVLH, N s), node c's
    for r in range(m):
        j = cw.thread[r]
        lost = cw.thread_lost[r]
        carries = False
        for e in range(2):
            q = cw.threads[r, e]
            impulses[2 * e:2 * e + 2] = 0.0
            if cw.carrier[q] != r:
                continue
            carries = True
            lost += cw.node_lost[q]
            for d in range(3):
                impulses[2 * e, d] = cw.mass[q] * (rot[b, d, 0] * cw.mean_change[q, 0] + rot[b, d, 1]
                                                   * cw.mean_change[q, 1] + rot[b, d, 2] * cw.mean_change[q, 2])
                impulses[2 * e + 1, d] = cw.mass[q] * (rot[b, d, 0] * cw.end_change[q, 0] + rot[b, d, 1]
                                                       * cw.end_change[q, 1] + rot[b, d, 2] * cw.end_change[q, 2])
        if seg.end_energy[1, j] >= 0.0:
            seg.end_energy[1, j] += cw.thread_energy[r]
        seg.dissipated[j] += lost * stage_weight
        lost_total += lost * stage_weight
        if carries:
            _apply_thread_impulses(j, threads[j, 0], threads[j, 1], b, impulses, x, com_lvlh, step, stage_weight, seg,
                                   body_force_lvlh, torque_lvlh, buffers)
    for q in range(k):
        cw.row[cw.node[q]] = -1
    return energy, count, lost_total


@njit(cache=True)
def _thread_start(r, j, s, b, x, cw, shapes, bodies, rot, com_lvlh, law, step, n_substeps, seg):
    """Thread row ``r`` (net thread ``j``) of the cluster at the step's start: books its contact energy
    (``seg.start_energy``) and its nodes' sharing; returns that energy (J), 1 if it penetrates (else 0), and the
    sub-steps its contact and its nodes' own contacts need (:func:`_substeps_to_resolve`)."""
    ka, kc = cw.threads[r, 0], cw.threads[r, 1]
    pa = (cw.position[ka, 0], cw.position[ka, 1], cw.position[ka, 2])
    pc = (cw.position[kc, 0], cw.position[kc, 1], cw.position[kc, 2])
    geometry = thread_contact_geometry(pa, pc, shapes.box_min_body, shapes.box_max_body, s, cw.radius[ka],
                                       cw.radius[kc], seg.breakpoints)
    penetration, depth, split, t_deepest, end_index, depth_a, depth_c, normal_a, normal_c = geometry
    start_energy = hertz_elastic_energy(penetration, law.stiffness, law.exponent) if penetration > 0.0 else 0.0
    seg.start_energy[j] += start_energy
    seg.sharing[1, j] = max(seg.sharing[1, j], seg.node_threads[cw.node[ka]], seg.node_threads[cw.node[kc]])
    if seg.sharing[0, j] == 0 and max(depth_a, depth_c) > 0.0:
        seg.sharing[0, j] = -1      # an arrival with a node in its own contact (the record's column 5)
    if n_substeps <= 1:
        return start_energy, 1 if penetration > 0.0 else 0, n_substeps
    wa, wc = 1.0 - split, split
    point_mass = point_effective_mass(cw.mass[ka], cw.mass[kc], split)
    rel, acc = cw.velocity, cw.acceleration
    # the point's relative velocity and the normal at the start (body frame): the sub-steps
    w = (wa * rel[ka, 0] + wc * rel[kc, 0], wa * rel[ka, 1] + wc * rel[kc, 1], wa * rel[ka, 2] + wc * rel[kc, 2])
    lo = (shapes.box_min_body[s, 0], shapes.box_min_body[s, 1], shapes.box_min_body[s, 2])
    hi = (shapes.box_max_body[s, 0], shapes.box_max_body[s, 1], shapes.box_max_body[s, 2])
    d = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    nbx, nby, nbz = segment_box_normal(pa[0] + t_deepest * d[0], pa[1] + t_deepest * d[1], pa[2] + t_deepest * d[2],
                                       d[0], d[1], d[2], lo, hi, w[0], w[1], w[2])
    a, c = cw.node[ka], cw.node[kc]
    arm_x = wa * x[0, a] + wc * x[0, c] - com_lvlh[b, 0]
    arm_y = wa * x[1, a] + wc * x[1, c] - com_lvlh[b, 1]
    arm_z = wa * x[2, a] + wc * x[2, c] - com_lvlh[b, 2]
    nx = rot[b, 0, 0] * nbx + rot[b, 0, 1] * nby + rot[b, 0, 2] * nbz
    ny = rot[b, 1, 0] * nbx + rot[b, 1, 1] * nby + rot[b, 1, 2] * nbz
    nz = rot[b, 2, 0] * nbx + rot[b, 2, 1] * nby + rot[b, 2, 2] * nbz
    body_mass = _effective_mass_of_body(rot, bodies.inverse_inertia_body, b, bodies.mass[b], arm_x, arm_y, arm_z,
                                        nx, ny, nz)
    # every thread contact is sub-cycled, slow ones too: the node contact's implicit step holds its point over the
    # step, which in a slow rocking or turning thread is the error this sub-cycle removes (measured: a thread striking
    # over an edge at 2 m/s, +2.97 % of its launch energy with the implicit step for slow contacts, +0.98 % without)
    n_cycle = _substeps_to_resolve(penetration, w, (nbx, nby, nbz), point_mass, body_mass, acc, wa, wc, rel, ka, kc,
                                   depth_a, depth_c, normal_a, normal_c, cw.mass[ka], cw.mass[kc], law, step,
                                   n_substeps, seg)
    return start_energy, 1 if penetration > 0.0 else 0, n_cycle


@njit(cache=True)
def _apply_thread_impulses(j, a, c, b, impulses, x, com_lvlh, step, stage_weight, seg, body_force_lvlh, torque_lvlh,
                           buffers):
    """Each node's mean impulse over the step (``impulses`` rows 0 and 2, N s, LVLH) as a force now, the body's
    reaction at the node; the rest (rows 1 and 3 less 0 and 2) carried to the next evaluation, or applied now when
    the thread already carries one from another shape this step (momentum stays exact either way)."""
    inverse_step = 1.0 / step
    weight = step * stage_weight
    carry_now = seg.lag_body[j] >= 0
    for k in range(2):
        i = a if k == 0 else c
        mean, end = 2 * k, 2 * k + 1
        scale_x, scale_y, scale_z = impulses[mean, 0], impulses[mean, 1], impulses[mean, 2]
        if carry_now:
            scale_x, scale_y, scale_z = impulses[end, 0], impulses[end, 1], impulses[end, 2]
        _apply_at_point(i, i, 0.0, b, scale_x * inverse_step, scale_y * inverse_step, scale_z * inverse_step,
                        x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2], weight,
                        seg.node_force_lvlh, body_force_lvlh, torque_lvlh, buffers.body_impulse_lvlh,
                        buffers.node_impulse_lvlh)
        if not carry_now:
            for d in range(3):
                seg.lag_impulse_lvlh[j, k, d] = impulses[end, d] - impulses[mean, d]
    if not carry_now:
        seg.lag_body[j] = b


@njit(cache=True)
def _substeps_to_resolve(penetration, w, normal, point_mass, body_mass, acc, wa, wc, rel, ka, kc, depth_a, depth_c,
                         normal_a, normal_c, mass_a, mass_c, law, step, n_substeps, seg):
    """Sub-steps for the thread's sub-cycle (:mod:`multibody.segment_cycle`): enough to resolve its point's contact
    and each node's own contact with the box it predicts (the node contact's rule,
    :func:`multibody.contact_kernel._substeps_to_resolve_contact`), at most ``n_substeps``. Body frame."""
    scalar, vector, external = seg.contact_scalar, seg.contact_vector, seg.external_force
    n_cycle = 1
    for r in range(3):
        if r == 0:
            mass, depth, nrm = point_mass, penetration, normal
            vel = w
            ext = ((wa * acc[ka, 0] + wc * acc[kc, 0]) * point_mass, (wa * acc[ka, 1] + wc * acc[kc, 1]) * point_mass,
                   (wa * acc[ka, 2] + wc * acc[kc, 2]) * point_mass)
        elif r == 1:
            if depth_a + step * (abs(rel[ka, 0]) + abs(rel[ka, 1]) + abs(rel[ka, 2])) <= 0.0:
                continue
            mass, depth, nrm = mass_a, depth_a, normal_a
            vel = (rel[ka, 0], rel[ka, 1], rel[ka, 2])
            ext = (acc[ka, 0] * mass_a, acc[ka, 1] * mass_a, acc[ka, 2] * mass_a)
        else:
            if depth_c + step * (abs(rel[kc, 0]) + abs(rel[kc, 1]) + abs(rel[kc, 2])) <= 0.0:
                continue
            mass, depth, nrm = mass_c, depth_c, normal_c
            vel = (rel[kc, 0], rel[kc, 1], rel[kc, 2])
            ext = (acc[kc, 0] * mass_c, acc[kc, 1] * mass_c, acc[kc, 2] * mass_c)
        scalar[0, 0], scalar[1, 0] = depth, body_mass
        vector[0, 0, 0], vector[0, 0, 1], vector[0, 0, 2] = vel
        vector[1, 0, 0], vector[1, 0, 1], vector[1, 0, 2] = nrm
        external[0], external[1], external[2] = ext
        n_cycle = max(n_cycle, _substeps_to_resolve_contact(scalar[0], vector[0], vector[1], scalar[1], 1, external,
                                                            mass, step, law.stiffness, law.exponent, law.damping))
    return min(n_substeps, n_cycle)
