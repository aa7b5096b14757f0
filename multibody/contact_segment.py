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
  +0.63 % with the node's contact owned (+0.52 % since the force follows the energy's slope at an edge, helper
  keyon19), +1.7 % with it only predicted, +15.6 % with the node in free flight in the sub-cycle.
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

Which threads may touch which boxes within the step (broad and narrow phase) is found in
:mod:`multibody.segment_pairs`.

Frames: LVLH unless named; the shapes in their body frames (origin at the body's CoM). SI units.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from multibody.broad_phase import box_signed_distance
from multibody.contact import hertz_elastic_energy

from multibody.contact_kernel import _effective_mass_of_body, _substeps_to_resolve_contact, add_body_reaction
from multibody.jit_cache import NO_REFCOUNTS
from multibody.segment_box import MAX_BREAKPOINTS, segment_box_normal
from multibody.segment_cycle import ClusterWork, cluster_contact_over_step, cluster_work, thread_contact_geometry
from multibody.segment_candidates import CANDIDATE_SKIN, refresh_candidates
from multibody.segment_pairs import _contact_pairs, _near_shapes, _node_motion, _to_body
from multibody.thread_cluster import group_pairs


class SegmentBuffers(NamedTuple):
    """The thread contact's switch, the impulses it carries from step to step, its per-thread energy record and
    work space (m threads, n nodes, ns shapes; zero-size arrays when off)."""

    enabled: int                    # 1: threads take segment contact (case key contact.thread_segments)
    lag_impulse_lvlh: np.ndarray    # (2, m, 2, 3) impulse still to apply on the thread's two nodes at the next
                                    # evaluation (N s), LVLH; the body's reaction at the nodes; slot 1: a second box's
                                    # (a thread in contact with two boxes in one step)
    lag_body: np.ndarray            # (2, m) int64 body of that impulse, -1 for none
    end_energy: np.ndarray          # (2, m) the thread's contact energy at the end of the last step's sub-cycles and of
                                    # this step's (J); -1: not known (a slow contact's implicit step)
    start_energy: np.ndarray        # (m,) the same at this evaluation's start (J), work
    energy_jump: np.ndarray         # (m,) per thread, the sum over steps of its contact energy at a step's start less
                                    # the energy its sub-cycle ended the last step with (J): energy the step made
    dissipated: np.ndarray          # (m,) per thread, the energy its contact dissipated (J)
    node_force_lvlh: np.ndarray     # (3, n) this pass's forces on the nodes (N), LVLH, coordinate-major
    lag_velocity_lvlh: np.ndarray   # (3, n) the carried impulses' velocity change of each node (m/s), LVLH
    node_speed: np.ndarray          # (n,) bound of each node's speed over the step (m/s)
    shape_work: np.ndarray          # (7, ns) each shape's bounding-sphere radius (m), surface speed bound (m/s),
                                    # bounding-sphere centre (rows 2-4, LVLH, m), its body's speed (m/s) and spin
                                    # (rad/s) (rows 5, 6)
    candidate_thread: np.ndarray    # (m ns,) int64 the candidate (thread, box) pairs (multibody.segment_candidates):
                                    # the thread
    candidate_shape: np.ndarray     # (m ns,) int64 ... and the box
    candidate_count: np.ndarray     # (4,) int64 the pairs listed; the builds so far; the pair tests skipped so far, a
                                    # pair's whole step by its clearance, and the test at the end of the free motion
                                    # alone (multibody.segment_pairs: counted, their answer known to be no)
    candidate_scalar: np.ndarray    # (3,) the skin (m); the step of the last build (s), 0 before the first; 1: skip
                                    # the pair tests whose answer the bounds prove no (the default), 0: test every
                                    # listed pair at both states (main before helper speed23, for A/B runs)
    built_position_body: np.ndarray  # (nb, 3, n) each node's position in each box-carrying body's frame at the last
                                     # build (m)
    built_speed: np.ndarray         # (n,) node_speed at the last build (m/s)
    built_surface_speed: np.ndarray  # (ns,) shape_work[1] at the last build (m/s)
    candidate_clearance: np.ndarray  # (m ns,) per candidate pair, a bound C (m) of its thread's distance to its box
                                     # less its nodes' displacement since the last build (-inf: none; segment_pairs)
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
    companions: np.ndarray          # (1,) int64 1: a cluster also follows the threads on other boxes only that share
                                    # its nodes (_companion_threads; the default), 0: not (main before helper cluster22,
                                    # for A/B runs switched from outside the kernel)
    sharing: np.ndarray             # (2, m) int64 the most threads in contact at either node of the thread, the last
                                    # step and this one (0: the thread not in contact)
    jump_by_sharing: np.ndarray     # (2, 6) the energy made between steps (J, row 0) and the thread-steps it sums (row
                                    # 1), by the thread's sharing in the step before (column: 1, 2, 3, 4 or more);
                                    # column 0: threads not in contact the step before (arrivals) with neither node
                                    # in its own contact with the box at the start, column 5: with one


def segment_buffers(n_threads: int, n_nodes: int, n_shapes: int, n_bodies: int, enabled: bool,
                    skin: float = CANDIDATE_SKIN) -> SegmentBuffers:
    """Zeroed :class:`SegmentBuffers`; with ``enabled`` False every array is empty (nothing to carry).

    Parameters
    ----------
    n_threads, n_nodes, n_shapes, n_bodies : int
    enabled : bool
        The case's ``contact.thread_segments``.
    skin : float
        The candidate pairs' skin (m; :mod:`multibody.segment_candidates`): it changes the cost only; 0 rebuilds them
        at every evaluation.
    """
    m, n, ns, nb = (n_threads, n_nodes, n_shapes, n_bodies) if enabled else (0, 0, 0, 0)
    return SegmentBuffers(enabled=int(bool(enabled)), lag_impulse_lvlh=np.zeros((2, m, 2, 3)),
                          lag_body=np.full((2, m), -1, np.int64), end_energy=np.zeros((2, m)), start_energy=np.zeros(m),
                          energy_jump=np.zeros(m), dissipated=np.zeros(m),
                          node_force_lvlh=np.zeros((3, n)), lag_velocity_lvlh=np.zeros((3, n)),
                          node_speed=np.zeros(n), shape_work=np.zeros((7, ns)),
                          candidate_thread=np.zeros(m * ns, np.int64), candidate_shape=np.zeros(m * ns, np.int64),
                          candidate_count=np.zeros(4, np.int64), candidate_scalar=np.array([float(skin), 0.0, 1.0]),
                          built_position_body=np.zeros((nb, 3, n)), built_speed=np.zeros(n),
                          built_surface_speed=np.zeros(ns),
                          candidate_clearance=np.full(m * ns, -np.inf),
                          breakpoints=np.zeros(MAX_BREAKPOINTS), contact_scalar=np.zeros((5, 1)),
                          contact_vector=np.zeros((6, 1, 3)), external_force=np.zeros(3), cycle_out=np.zeros((4, 3)),
                          owned_shape=np.full(n, -1, np.int64), node_threads=np.zeros(n, np.int64),
                          node_shape=np.full(n, -1, np.int64), pair_thread=np.zeros(m * ns, np.int64),
                          pair_shape=np.zeros(m * ns, np.int64), pair_order=np.zeros(m * ns, np.int64),
                          cluster_start=np.zeros(m * ns + 1, np.int64), cluster_parent=np.zeros(ns * n, np.int64),
                          root_cluster=np.full(ns * n, -1, np.int64), cluster=cluster_work(n, m),
                          companions=np.ones(1, np.int64),
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


@njit(cache=True, **NO_REFCOUNTS)
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
        for slot in range(2):
            b = seg.lag_body[slot, j]
            if b < 0:
                break
            for k in range(2):
                i = threads[j, k]
                jx, jy, jz = (seg.lag_impulse_lvlh[slot, j, k, 0], seg.lag_impulse_lvlh[slot, j, k, 1],
                              seg.lag_impulse_lvlh[slot, j, k, 2])
                lag_velocity[0, i] += jx / net_mass[i]
                lag_velocity[1, i] += jy / net_mass[i]
                lag_velocity[2, i] += jz / net_mass[i]
                _apply_at_point(i, i, 0.0, b, jx * inverse_step, jy * inverse_step, jz * inverse_step,
                                x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2],
                                step * stage_weight, seg.node_force_lvlh, body_force_lvlh, torque_lvlh,
                                out_body_impulse, out_node_impulse)
            seg.lag_body[slot, j] = -1


# no reference counts (jit_cache.NO_REFCOUNTS), nor in its callees (numba compiles them with its setting): with counts,
# every call below the step's entry (per candidate pair, cluster and thread) took and dropped a reference to every array
# of the named tuples it was handed (KernelBuffers, SegmentBuffers, ClusterWork: some 100 arrays a call), and these
# atomic counts were 52-60 % of a wrapped capture's CPU (perf, helper speed20, docs/model.md "Speed"). Its callees state
# NO_REFCOUNTS themselves: numba keys neither its on-disk cache nor a dispatcher's compiled versions by this setting, so
# a callee first compiled from Python (a test) kept its counts inside the kernel too (measured: 18 % of the samples)
@njit(cache=True, **NO_REFCOUNTS)
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
    refresh_candidates(x, threads, net.radius, seg, states, shapes, step)
    energy, count, dissipated = 0.0, 0, 0.0
    # the per-thread energy record: this step's sub-cycles write their end energies into row 1
    # row to row element by element: a slice assignment between arrays allocates (its overlap copy)
    for j in range(threads.shape[0]):
        seg.end_energy[0, j] = seg.end_energy[1, j]
        seg.sharing[0, j] = seg.sharing[1, j]
    seg.end_energy[1, :] = 0.0
    seg.start_energy[:] = 0.0
    seg.sharing[1, :] = 0
    seg.owned_shape[:] = -1
    seg.node_threads[:] = 0
    seg.node_shape[:] = -1
    n_pairs = _contact_pairs(x, v, net_force_lvlh, net, states, shapes, step, n_substeps, buffers)
    # the threads in contact with a box that share nodes, and those nodes' own contacts, as one system each
    n_clusters = group_pairs(seg.pair_thread, seg.pair_shape, n_pairs, threads, x.shape[1], seg.cluster_parent,
                             seg.root_cluster, seg.pair_order, seg.cluster_start)
    for k in range(n_clusters):
        e, count_k, w = _cluster_on_box(seg.cluster_start[k], seg.cluster_start[k + 1], n_pairs, x, v,
                                        net_force_lvlh, net, states, bodies, shapes, law, step, n_substeps,
                                        stage_weight, buffers, body_force_lvlh, torque_lvlh)
        energy += e
        count += count_k
        dissipated += w
    for d in range(3):      # element by element (an array's += allocates)
        for i in range(node_force.shape[1]):
            net_force_lvlh[d, i] += node_force[d, i]
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


@njit(cache=True, **NO_REFCOUNTS)
def _cluster_on_box(first, last, n_pairs, x, v, net_force_lvlh, net, states, bodies, shapes, law, step, n_substeps,
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
    reaction at the nodes. The threads of the cluster also in contact with other boxes, and the threads on other
    boxes only that share its nodes (:func:`_companion_threads`), feel those boxes' contacts in the sub-cycle as
    predictions (:func:`_foreign_boxes`)."""
    seg = buffers.segments
    cw = seg.cluster
    threads, radius = net.threads, net.radius
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
                cw.own[k] = 1 if seg.node_shape[i] == s else 0
                _node_row(i, k, r, b, x, v, net_force_lvlh, net, states, half_kick, buffers)
                if cw.own[k] == 1:
                    seg.owned_shape[i] = s
                    depth = radius[i] - box_signed_distance(cw.position[k, 0], cw.position[k, 1], cw.position[k, 2],
                                                            box_min, box_max, s)[0]
                    if depth > 0.0:
                        energy += hertz_elastic_energy(depth, law.stiffness, law.exponent)
                        count += 1
                k += 1
            cw.threads[r, e] = cw.row[i]
    m = last - first
    cw.n_foreign[0] = 0
    for r in range(m):
        p = seg.pair_order[first + r]
        if (p > 0 and seg.pair_thread[p - 1] == cw.thread[r]) or (p + 1 < n_pairs
                                                                   and seg.pair_thread[p + 1] == cw.thread[r]):
            _foreign_boxes(r, p, n_pairs, s, b, states, bodies, shapes, seg, cw)
    if seg.companions[0] != 0:
        k = _companion_threads(k, m, n_pairs, s, b, x, v, net_force_lvlh, net, states, bodies, shapes, half_kick,
                               buffers)
    cw.n_nodes[0], cw.n_threads[0] = k, m
    n_cycle = 1
    for r in range(m):
        j = cw.thread[r]
        e, touching, n_thread = _thread_start(r, j, s, b, x, cw, shapes, bodies, rot, com_lvlh, law, step, n_substeps,
                                              seg)
        energy += e
        count += touching
        n_cycle = max(n_cycle, n_thread)
    if cw.n_foreign[0] > 0:
        # a thread between two boxes feels both contacts: their stiffnesses add (omega^2), the sub-steps sized for
        # one are doubled (at most sqrt(2) were needed for two equal contacts)
        n_cycle = min(n_substeps, 2 * n_cycle)
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


@njit(cache=True, **NO_REFCOUNTS)
def _node_row(i, k, r, b, x, v, net_force_lvlh, net, states, half_kick, buffers):
    """Net node ``i`` as row ``k`` of the cluster on body ``b``, carried by thread row ``r``: its position in the
    body's frame (m), its velocity relative to the body's material point (m/s) and its non-contact acceleration held
    over the step (m/s^2), its mass (kg) and contact radius (m). ``cw.own[k]`` is the caller's."""
    seg = buffers.segments
    cw = seg.cluster
    cw.row[i] = k
    cw.node[k] = i
    cw.carrier[k] = r
    position = _to_body(x, i, states.body_to_lvlh, states.com_lvlh, b)
    rel, acc = _node_motion(i, b, x, v, net_force_lvlh, net.mass, buffers.velocity_lag, seg.lag_velocity_lvlh,
                            states, half_kick)
    for d in range(3):
        cw.position[k, d], cw.velocity[k, d], cw.acceleration[k, d] = position[d], rel[d], acc[d]
    cw.mass[k], cw.radius[k] = net.mass[i], net.radius[i]


@njit(cache=True, **NO_REFCOUNTS)
def _companion_threads(k, m, n_pairs, s, b, x, v, net_force_lvlh, net, states, bodies, shapes, half_kick, buffers):
    """The threads in contact with other boxes only that share a node with the cluster on box ``s`` (transitively,
    through their own nodes), as rows ``m``, ``m + 1``, ... of the cluster after its ``m`` own threads, their new
    nodes as rows ``k``, ``k + 1``, ...; each of their boxes an entry of the cluster's other-box contacts
    (:func:`_foreign_boxes`): the sub-cycle moves the shared nodes under those contacts too (predicted; they are
    applied and booked by the other boxes' clusters). Returns the cluster's nodes.

    Sample 9 of the 1.0 m/s row (docs/model.md, "A net pinched between two bodies"): thread 419 pinched between the
    main body and the ASAR, thread 423 (node 224 to bullet 228) on the ASAR alone. The main body's cluster moved node
    224 without thread 423's contact, the ASAR's with it: the two clusters followed two paths of the shared node."""
    seg = buffers.segments
    cw = seg.cluster
    threads = net.threads
    rows = m
    added = True
    while added:
        added = False
        p = 0
        while p < n_pairs:
            j, first = seg.pair_thread[p], p
            on_box = False
            while p < n_pairs and seg.pair_thread[p] == j:      # a thread's pairs lie next to each other
                on_box = on_box or seg.pair_shape[p] == s
                p += 1
            if on_box or (cw.row[threads[j, 0]] < 0 and cw.row[threads[j, 1]] < 0):
                continue
            known = False
            for r in range(m, rows):
                known = known or cw.thread[r] == j
            if known:
                continue
            cw.thread[rows] = j
            for e in range(2):
                i = threads[j, e]
                if cw.row[i] < 0:
                    cw.own[k] = 0
                    _node_row(i, k, rows, b, x, v, net_force_lvlh, net, states, half_kick, buffers)
                    k += 1
                cw.threads[rows, e] = cw.row[i]
            _foreign_boxes(rows, first, n_pairs, s, b, states, bodies, shapes, seg, cw)
            rows += 1
            added = True
    return k


@njit(cache=True, **NO_REFCOUNTS)
def _foreign_boxes(r, p, n_pairs, s, b, states, bodies, shapes, seg, cw):
    """Thread row ``r`` of the cluster on box ``s`` (body ``b``), whose thread also has contact pairs on other boxes
    this step (``seg.pair_thread`` holds a thread's pairs next to each other, around pair ``p``): each other box as an
    entry of the cluster's other-box contacts (``cw.n_foreign`` ...: its pose, velocity and spin relative to body
    ``b`` in box ``s``'s frame), which the sub-cycle predicts (:func:`multibody.segment_cycle._foreign_contact_kick`).

    Each box's cluster integrated the thread against its own box only. A thread pinched between two boxes was
    pushed out of each by its sub-cycle as if the other were not there; the two kicks, applied together, cancel,
    so the thread stayed where it was, and each sub-cycle booked the damping of an escape that never happened
    (Envisat sample 9 at 1.0 m/s, 87.7-87.95 s: 4.9 J booked against 0.34 J of net kinetic energy lost;
    ``tests/multibody/test_contact_pinch.py``). Now both clusters follow the thread under both contacts, and each
    applies and books its own box's (docs/model.md, "A net pinched between two bodies")."""
    j = cw.thread[r]
    rot, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    q = p
    while q > 0 and seg.pair_thread[q - 1] == j:
        q -= 1
    while q < n_pairs and seg.pair_thread[q] == j:
        s2 = seg.pair_shape[q]
        q += 1
        if s2 == s:
            continue
        b2 = shapes.body[s2]
        f = cw.n_foreign[0]
        if f == cw.foreign_row.shape[0]:
            return      # more other-box contacts than the net has threads: the rest not predicted
        cw.n_foreign[0] = f + 1
        cw.foreign_row[f], cw.foreign_shape[f] = r, s2
        cw.foreign_inverse_mass[f] = 1.0 / bodies.mass[b2]
        ox, oy, oz = com_lvlh[b2, 0] - com_lvlh[b, 0], com_lvlh[b2, 1] - com_lvlh[b, 1], com_lvlh[b2, 2] - com_lvlh[b, 2]
        wx, wy, wz = omega_lvlh[b, 0], omega_lvlh[b, 1], omega_lvlh[b, 2]
        # body b2's CoM velocity less body b's material point there, and the spins' difference (LVLH)
        vx = velocity_lvlh[b2, 0] - velocity_lvlh[b, 0] - (wy * oz - wz * oy)
        vy = velocity_lvlh[b2, 1] - velocity_lvlh[b, 1] - (wz * ox - wx * oz)
        vz = velocity_lvlh[b2, 2] - velocity_lvlh[b, 2] - (wx * oy - wy * ox)
        sx, sy, sz = omega_lvlh[b2, 0] - wx, omega_lvlh[b2, 1] - wy, omega_lvlh[b2, 2] - wz
        for d in range(3):      # into box s's frame: R_b^T
            cw.foreign_origin[f, d] = rot[b, 0, d] * ox + rot[b, 1, d] * oy + rot[b, 2, d] * oz
            cw.foreign_velocity[f, d] = rot[b, 0, d] * vx + rot[b, 1, d] * vy + rot[b, 2, d] * vz
            cw.foreign_spin[f, d] = rot[b, 0, d] * sx + rot[b, 1, d] * sy + rot[b, 2, d] * sz
            for e in range(3):  # box s2's frame to box s's: R_b^T R_b2
                cw.foreign_rotation[f, d, e] = (rot[b, 0, d] * rot[b2, 0, e] + rot[b, 1, d] * rot[b2, 1, e]
                                                + rot[b, 2, d] * rot[b2, 2, e])


@njit(cache=True, **NO_REFCOUNTS)
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
    # the unit normal; its slope (below 1 inside the box) only softens the contact, so the sub-steps sized for 1 hold
    nbx, nby, nbz, _ = segment_box_normal(pa[0] + t_deepest * d[0], pa[1] + t_deepest * d[1],
                                          pa[2] + t_deepest * d[2], d[0], d[1], d[2], lo, hi, w[0], w[1], w[2])
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


@njit(cache=True, **NO_REFCOUNTS)
def _apply_thread_impulses(j, a, c, b, impulses, x, com_lvlh, step, stage_weight, seg, body_force_lvlh, torque_lvlh,
                           buffers):
    """Each node's mean impulse over the step (``impulses`` rows 0 and 2, N s, LVLH) as a force now, the body's
    reaction at the node; the rest (rows 1 and 3 less 0 and 2) carried to the next evaluation (a second box's in the
    second slot), or applied now when the thread already carries two from other shapes this step (momentum stays
    exact either way). Until 2026-11-28 a second box's was applied now: a thread pinched between two boxes took one
    box's push half now, half a step later, and the other's whole now, a zigzag of its point by about F h^2 / m_p
    a step (0.06 mm against a 0.2 mm squeeze in Envisat sample 9), whose damping the sub-cycles booked."""
    inverse_step = 1.0 / step
    weight = step * stage_weight
    slot = 0 if seg.lag_body[0, j] < 0 else 1
    carry_now = seg.lag_body[slot, j] >= 0
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
                seg.lag_impulse_lvlh[slot, j, k, d] = impulses[end, d] - impulses[mean, d]
    if not carry_now:
        seg.lag_body[slot, j] = b


@njit(cache=True, **NO_REFCOUNTS)
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
