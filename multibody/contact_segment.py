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
  deeper node's penetration, which changes within its own 0.15 ms impact: the first thread of a step that takes
  a node integrates that node's contact with the box and applies it (``SegmentBuffers.owned_shape``; the node
  contact, :mod:`multibody.contact_kernel`, skips that node-box pair this step); the node's later threads in the
  step only predict it (it moves their nodes, its impulse is not applied twice). Measured (one thread striking
  over a plate's edge at 20 m/s, bench/bench_thread_strike_energy.py): the balance closes to +0.63 % with the
  node's contact owned, +1.7 % with it only predicted, +15.6 % with the node in free flight in the sub-cycle.
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

from multibody.contact import hertz_elastic_energy

from multibody.contact_kernel import _effective_mass_of_body, _substeps_to_resolve_contact, add_body_reaction
from multibody.jit_cache import WITH_REFCOUNTS
from multibody.segment_box import MAX_BREAKPOINTS, segment_box_normal
from multibody.segment_cycle import thread_contact_geometry, thread_contact_over_step


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
                          owned_shape=np.full(n, -1, np.int64), node_threads=np.zeros(n, np.int64))


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
    threads, net_mass, radius = net.threads, net.mass, net.radius
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
    seg.owned_shape[:] = -1
    seg.node_threads[:] = 0
    centre_distance, node_speed = seg.centre_distance, seg.node_speed
    sphere_radius, surface_speed = seg.shape_work[0], seg.shape_work[1]
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    box_min, box_max, shape_body, is_box = shapes.box_min_body, shapes.box_max_body, shapes.body, shapes.is_box
    # two passes: the first counts each node's threads in contact (a node with one integrates its own contact in that
    # thread's sub-cycle), the second integrates
    for count_only in range(1, -1, -1):
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
                e, k, w = _thread_on_box(j, a, c, s, b, pa, pc, count_only == 1, x, v, net_force_lvlh, net, states,
                                         bodies, shapes, law, step, n_substeps, stage_weight, buffers, body_force_lvlh,
                                         torque_lvlh)
                energy += e
                count += k
                dissipated += w
    net_force_lvlh += node_force
    if n_substeps > 1:
        # the energy each thread's contact starts this step with less what its sub-cycle ended the last with: the
        # energy made between the steps (one force evaluation a step: Verlet)
        for j in range(threads.shape[0]):
            if seg.end_energy[0, j] >= 0.0:
                seg.energy_jump[j] += seg.start_energy[j] - seg.end_energy[0, j]
    return energy, count, dissipated


@njit(cache=True, inline="always")
def _to_body(x, i, body_to_lvlh, com_lvlh, b):
    """Node ``i`` of the coordinate-major LVLH positions ``x`` in body ``b``'s frame (m), as a tuple."""
    ax, ay, az = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
    return (body_to_lvlh[b, 0, 0] * ax + body_to_lvlh[b, 1, 0] * ay + body_to_lvlh[b, 2, 0] * az,
            body_to_lvlh[b, 0, 1] * ax + body_to_lvlh[b, 1, 1] * ay + body_to_lvlh[b, 2, 1] * az,
            body_to_lvlh[b, 0, 2] * ax + body_to_lvlh[b, 1, 2] * ay + body_to_lvlh[b, 2, 2] * az)


@njit(cache=True)
def _thread_on_box(j, a, c, s, b, pa, pc, count_only, x, v, net_force_lvlh, net, states, bodies, shapes, law, step,
                   n_substeps, stage_weight, buffers, body_force_lvlh, torque_lvlh):
    """Thread ``j`` (nodes a, c; body-frame ends ``pa``, ``pc``) against box shape ``s`` of body ``b`` over the
    step (module doc); returns the contact's elastic energy (J), 1 if it penetrates (else 0), and the energy
    it dissipated (J, weighted).

    The contact's coordinate is the excess q = delta(t*) - delta_e of the deepest point over the deeper node
    e when that node's own sphere penetrates (else q = delta(t*)), and the forces are its energy's gradient:
    F (1 - s) n and F s n on the nodes at the point, and -F n_e on node e, which hands the load its own
    contact carried up to q to the point (module doc); the body takes every reaction at the nodes. A fast
    contact follows its deepest point through the step (:mod:`multibody.segment_cycle`); a slow one takes the
    node contact's implicit step at the point found at the start."""
    seg = buffers.segments
    net_mass, radius = net.mass, net.radius
    geometry = thread_contact_geometry(pa, pc, shapes.box_min_body, shapes.box_max_body, s, radius[a], radius[c],
                                       seg.breakpoints)
    penetration, depth, split, t_deepest, end_index, depth_a, depth_c, normal_a, normal_c = geometry
    rot, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    lag, node_lag = seg.lag_velocity_lvlh, buffers.velocity_lag
    # each node's start velocity relative to the body (as the node contact's) and non-contact acceleration, body
    # frame; rows: node a, node c
    rel = np.empty((2, 3))
    acc = np.empty((2, 3))
    for k in range(2):
        i = a if k == 0 else c
        ux = v[0, i] + node_lag[0, i] + lag[0, i] + half_kick * net_force_lvlh[0, i] / net_mass[i]
        uy = v[1, i] + node_lag[1, i] + lag[1, i] + half_kick * net_force_lvlh[1, i] / net_mass[i]
        uz = v[2, i] + node_lag[2, i] + lag[2, i] + half_kick * net_force_lvlh[2, i] / net_mass[i]
        rx, ry, rz = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
        wx = ux - velocity_lvlh[b, 0] - (omega_lvlh[b, 1] * rz - omega_lvlh[b, 2] * ry)
        wy = uy - velocity_lvlh[b, 1] - (omega_lvlh[b, 2] * rx - omega_lvlh[b, 0] * rz)
        wz = uz - velocity_lvlh[b, 2] - (omega_lvlh[b, 0] * ry - omega_lvlh[b, 1] * rx)
        fx, fy, fz = net_force_lvlh[0, i] / net_mass[i], net_force_lvlh[1, i] / net_mass[i], net_force_lvlh[2, i] / net_mass[i]
        for d in range(3):
            rel[k, d] = rot[b, 0, d] * wx + rot[b, 1, d] * wy + rot[b, 2, d] * wz
            acc[k, d] = rot[b, 0, d] * fx + rot[b, 1, d] * fy + rot[b, 2, d] * fz
    # does the contact act within the step: now, or at the end of the step's free motion (a thread turning over an
    # edge, whose deepest point is not yet interior at the start)
    if penetration <= 0.0:
        h2 = 0.5 * step * step
        qa = (pa[0] + step * rel[0, 0] + h2 * acc[0, 0], pa[1] + step * rel[0, 1] + h2 * acc[0, 1],
              pa[2] + step * rel[0, 2] + h2 * acc[0, 2])
        qc = (pc[0] + step * rel[1, 0] + h2 * acc[1, 0], pc[1] + step * rel[1, 1] + h2 * acc[1, 1],
              pc[2] + step * rel[1, 2] + h2 * acc[1, 2])
        ahead = thread_contact_geometry(qa, qc, shapes.box_min_body, shapes.box_max_body, s, radius[a], radius[c],
                                        seg.breakpoints)
        if ahead[0] <= 0.0:
            return 0.0, 0, 0.0
    if count_only:
        # first pass: each node's threads in contact this step (who integrates its own contact)
        seg.node_threads[a] += 1
        seg.node_threads[c] += 1
        return 0.0, 0, 0.0
    start_energy = hertz_elastic_energy(penetration, law.stiffness, law.exponent) if penetration > 0.0 else 0.0
    seg.start_energy[j] += start_energy
    # the nodes' own contacts with this box: integrated here with the thread's (the node contact skips them this
    # step) when this is the node's only thread in contact this step; otherwise the node contact integrates it
    # with all its threads' forces and the sub-cycles only predict it
    own_a = seg.node_threads[a] == 1
    own_c = seg.node_threads[c] == 1 and c != a
    node_energy, node_count = 0.0, 0
    if own_a:
        seg.owned_shape[a] = s
        if depth_a > 0.0:
            node_energy += hertz_elastic_energy(depth_a, law.stiffness, law.exponent)
            node_count += 1
    if own_c:
        seg.owned_shape[c] = s
        if depth_c > 0.0:
            node_energy += hertz_elastic_energy(depth_c, law.stiffness, law.exponent)
            node_count += 1
    wa, wc = 1.0 - split, split
    point_mass = point_effective_mass(net_mass[a], net_mass[c], split)
    # the point's relative velocity and the normal at the start (body frame): the slow-contact test, the sub-steps
    w = (wa * rel[0, 0] + wc * rel[1, 0], wa * rel[0, 1] + wc * rel[1, 1], wa * rel[0, 2] + wc * rel[1, 2])
    lo = (shapes.box_min_body[s, 0], shapes.box_min_body[s, 1], shapes.box_min_body[s, 2])
    hi = (shapes.box_max_body[s, 0], shapes.box_max_body[s, 1], shapes.box_max_body[s, 2])
    d = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    nbx, nby, nbz = segment_box_normal(pa[0] + t_deepest * d[0], pa[1] + t_deepest * d[1], pa[2] + t_deepest * d[2],
                                       d[0], d[1], d[2], lo, hi, w[0], w[1], w[2])
    arm_x = wa * x[0, a] + wc * x[0, c] - com_lvlh[b, 0]
    arm_y = wa * x[1, a] + wc * x[1, c] - com_lvlh[b, 1]
    arm_z = wa * x[2, a] + wc * x[2, c] - com_lvlh[b, 2]
    nx = rot[b, 0, 0] * nbx + rot[b, 0, 1] * nby + rot[b, 0, 2] * nbz
    ny = rot[b, 1, 0] * nbx + rot[b, 1, 1] * nby + rot[b, 1, 2] * nbz
    nz = rot[b, 2, 0] * nbx + rot[b, 2, 1] * nby + rot[b, 2, 2] * nbz
    body_mass = _effective_mass_of_body(rot, bodies.inverse_inertia_body, b, bodies.mass[b], arm_x, arm_y, arm_z,
                                        nx, ny, nz)
    impulses = seg.cycle_out   # rows: node a's mean and end impulse (LVLH, N s), node c's
    # every thread contact is sub-cycled, slow ones too: the node contact's implicit step holds its point over the
    # step, which in a slow rocking or turning thread is the error this sub-cycle removes (measured: a thread striking
    # over an edge at 2 m/s, +2.97 % of its launch energy with the implicit step for slow contacts, +0.98 % without)
    n_cycle = n_substeps
    if n_substeps > 1:
        n_cycle = _substeps_to_resolve(penetration, w, (nbx, nby, nbz), point_mass, body_mass, acc, wa, wc, rel,
                                       depth_a, depth_c, normal_a, normal_c, net_mass[a], net_mass[c], law, step,
                                       n_substeps, seg)
    lost, end_energy, touched = thread_contact_over_step(
        pa, pc, (rel[0, 0], rel[0, 1], rel[0, 2]), (rel[1, 0], rel[1, 1], rel[1, 2]),
        (acc[0, 0], acc[0, 1], acc[0, 2]), (acc[1, 0], acc[1, 1], acc[1, 2]), net_mass[a], net_mass[c],
        radius[a], radius[c], shapes.box_min_body, shapes.box_max_body, s, bodies.mass[b],
        bodies.inverse_inertia_body, b, law, step, n_cycle, own_a, own_c, seg.breakpoints, impulses)
    # velocity changes (body frame) to impulses (LVLH)
    for r in range(4):
        mass = net_mass[a] if r < 2 else net_mass[c]
        gx, gy, gz = impulses[r, 0], impulses[r, 1], impulses[r, 2]
        for k in range(3):
            impulses[r, k] = mass * (rot[b, k, 0] * gx + rot[b, k, 1] * gy + rot[b, k, 2] * gz)
    if end_energy >= 0.0 and seg.end_energy[1, j] >= 0.0:
        seg.end_energy[1, j] += end_energy
    else:
        seg.end_energy[1, j] = -1.0
    seg.dissipated[j] += lost * stage_weight
    _apply_thread_impulses(j, a, c, b, impulses, x, com_lvlh, step, stage_weight, seg, body_force_lvlh, torque_lvlh,
                           buffers)
    return start_energy + node_energy, (1 if penetration > 0.0 else 0) + node_count, lost * stage_weight


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
def _substeps_to_resolve(penetration, w, normal, point_mass, body_mass, acc, wa, wc, rel, depth_a, depth_c, normal_a,
                         normal_c, mass_a, mass_c, law, step, n_substeps, seg):
    """Sub-steps for the thread's sub-cycle (:mod:`multibody.segment_cycle`): enough to resolve its point's contact
    and each node's own contact with the box it predicts (the node contact's rule,
    :func:`multibody.contact_kernel._substeps_to_resolve_contact`), at most ``n_substeps``. Body frame."""
    scalar, vector, external = seg.contact_scalar, seg.contact_vector, seg.external_force
    n_cycle = 1
    for r in range(3):
        if r == 0:
            mass, depth, nrm = point_mass, penetration, normal
            vel = w
            ext = ((wa * acc[0, 0] + wc * acc[1, 0]) * point_mass, (wa * acc[0, 1] + wc * acc[1, 1]) * point_mass,
                   (wa * acc[0, 2] + wc * acc[1, 2]) * point_mass)
        elif r == 1:
            if depth_a + step * (abs(rel[0, 0]) + abs(rel[0, 1]) + abs(rel[0, 2])) <= 0.0:
                continue
            mass, depth, nrm = mass_a, depth_a, normal_a
            vel = (rel[0, 0], rel[0, 1], rel[0, 2])
            ext = (acc[0, 0] * mass_a, acc[0, 1] * mass_a, acc[0, 2] * mass_a)
        else:
            if depth_c + step * (abs(rel[1, 0]) + abs(rel[1, 1]) + abs(rel[1, 2])) <= 0.0:
                continue
            mass, depth, nrm = mass_c, depth_c, normal_c
            vel = (rel[1, 0], rel[1, 1], rel[1, 2])
            ext = (acc[1, 0] * mass_c, acc[1, 1] * mass_c, acc[1, 2] * mass_c)
        scalar[0, 0], scalar[1, 0] = depth, body_mass
        vector[0, 0, 0], vector[0, 0, 1], vector[0, 0, 2] = vel
        vector[1, 0, 0], vector[1, 0, 1], vector[1, 0, 2] = nrm
        external[0], external[1], external[2] = ext
        n_cycle = max(n_cycle, _substeps_to_resolve_contact(scalar[0], vector[0], vector[1], scalar[1], 1, external,
                                                            mass, step, law.stiffness, law.exponent, law.damping))
    return min(n_substeps, n_cycle)
