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
  radius at that point, through the node contact's own integration over the step (the implicit step of
  :mod:`multibody.contact_implicit` for a slow contact, the sub-cycle of :func:`multibody.contact.contact_over_step`
  otherwise; one sub-step when sub-cycling is off).
* **who carries it**: a force F at :math:`p = (1 - s) x_a + s x_b` is split (1 - s) F on node a and s F on
  node b, so the point's acceleration is F / m_p with the effective mass

  .. math:: m_p = \\Big(\\frac{(1 - s)^2}{m_a} + \\frac{s^2}{m_b}\\Big)^{-1}

  (2 m for the middle of a thread between equal nodes): the contact's normal motion is that of a particle
  of mass :math:`m_p` with the nodes' non-contact accelerations interpolated, :math:`f_p = m_p((1-s) f_a/m_a
  + s f_b/m_b)`. The reaction -F acts on the body at p, on the same line, so linear and angular momentum are
  exchanged exactly.
* **no double count**: the node contact already carries the nodes' own spheres, so a thread adds only
  where its interior is deeper than both its ends (the deepest point is interior), and only by its excess
  over the deeper node e when that node's sphere penetrates, :math:`q = \delta(t^*) - \max(0, \delta_a,
  \delta_b)`: a thread lying on a flat face (its penetration linear along it, deepest at an end) adds
  nothing; one bent over an edge, or across a plate narrower than the mesh, adds the whole contact. The
  forces are the gradient of the contact's energy :math:`k q^{n+1}/(n+1)`: besides F at the point, -F n_e on
  node e (it hands its load up to q over to the point) with its reaction on the body at the node, so the
  contact is conservative in q and momentum stays exact; the coordinate moves as a particle of mass
  :math:`(|J_a|^2/m_a + |J_b|^2/m_b)^{-1}`, J the nodes' shares of n (less n_e for node e).
* **the normal**: from the box to the deepest point, perpendicular to the thread (outside the box the
  nearest-point direction is; inside, the combination of the two nearest faces that is), so the contact
  never pushes a thread along itself.

As in the node contact, the velocity change over the step is applied as the kick that makes the
integrator's next drift follow the contact's path, and its remainder (the end minus the mean change) is
carried to the next evaluation, here per thread: impulse, body, split and point (body frame).

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
from multibody.contact import contact_over_step, hertz_elastic_energy
from multibody.contact_implicit import contact_implicit_step_xyz
from multibody.contact_kernel import _effective_mass_of_body, _substeps_to_resolve_contact, add_body_reaction
from multibody.segment_box import (
    MAX_BREAKPOINTS,
    TIE_DISTANCE,
    segment_box_deepest,
    segment_box_normal,
    segment_box_sublevel,
)


class SegmentBuffers(NamedTuple):
    """The thread contact's switch, the impulse it carries from step to step, and work space
    (m threads, n nodes, ns shapes; zero-size arrays when off)."""

    enabled: int                    # 1: threads take segment contact (case key contact.thread_segments)
    lag_impulse_lvlh: np.ndarray    # (m, 3) impulse still to apply at the next evaluation (N s), LVLH
    lag_body: np.ndarray            # (m,) int64 body of that impulse, -1 for none
    lag_split: np.ndarray           # (m,) its point's position along the thread, s (-)
    lag_point_body: np.ndarray      # (m, 3) its point, body frame of lag_body (m)
    lag_end_node: np.ndarray        # (m,) int64 the node that handed its load to the point (-1: none)
    lag_end_impulse_lvlh: np.ndarray  # (m, 3) the impulse still to apply on that node (N s), LVLH
    node_force_lvlh: np.ndarray     # (3, n) this pass's forces on the nodes (N), LVLH, coordinate-major
    lag_velocity_lvlh: np.ndarray   # (3, n) the carried impulses' velocity change of each node (m/s), LVLH
    centre_distance: np.ndarray     # (ns, n) each node's distance to each shape's bounding-sphere centre (m)
    node_speed: np.ndarray          # (n,) bound of each node's speed over the step (m/s)
    shape_work: np.ndarray          # (2, ns) each shape's bounding-sphere radius (m) and surface speed bound (m/s)
    breakpoints: np.ndarray         # (MAX_BREAKPOINTS,) work: a segment's sorted breakpoints
    contact_scalar: np.ndarray      # (5, 1) work: penetration, body mass, delta (sub-cycle), ...
    contact_vector: np.ndarray      # (6, 1, 3) work: relative velocity, normal, impulse, recoil, forces, ...
    external_force: np.ndarray      # (3,) work: the point's non-contact force (N), LVLH


def segment_buffers(n_threads: int, n_nodes: int, n_shapes: int, enabled: bool) -> SegmentBuffers:
    """Zeroed :class:`SegmentBuffers`; with ``enabled`` False every array is empty (nothing to carry).

    Parameters
    ----------
    n_threads, n_nodes, n_shapes : int
    enabled : bool
        The case's ``contact.thread_segments``.
    """
    m, n, ns = (n_threads, n_nodes, n_shapes) if enabled else (0, 0, 0)
    return SegmentBuffers(enabled=int(bool(enabled)), lag_impulse_lvlh=np.zeros((m, 3)),
                          lag_body=np.full(m, -1, np.int64), lag_split=np.zeros(m), lag_point_body=np.zeros((m, 3)),
                          lag_end_node=np.full(m, -1, np.int64), lag_end_impulse_lvlh=np.zeros((m, 3)),
                          node_force_lvlh=np.zeros((3, n)), lag_velocity_lvlh=np.zeros((3, n)),
                          centre_distance=np.zeros((ns, n)), node_speed=np.zeros(n), shape_work=np.zeros((2, ns)),
                          breakpoints=np.zeros(MAX_BREAKPOINTS), contact_scalar=np.zeros((5, 1)),
                          contact_vector=np.zeros((6, 1, 3)), external_force=np.zeros(3))


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
    """Apply every thread's impulse carried from the previous step (its contact's end minus mean velocity
    change) as a force over this step at its stored point, and note the velocity change it gives each node
    (``seg.lag_velocity_lvlh``) for this step's contact start velocities; clears the carried impulses."""
    lag_velocity = seg.lag_velocity_lvlh
    lag_velocity[:] = 0.0
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    inverse_step = 1.0 / step
    for j in range(threads.shape[0]):
        b = seg.lag_body[j]
        if b < 0:
            continue
        a, c = threads[j, 0], threads[j, 1]
        s = seg.lag_split[j]
        jx, jy, jz = seg.lag_impulse_lvlh[j, 0], seg.lag_impulse_lvlh[j, 1], seg.lag_impulse_lvlh[j, 2]
        for d in range(3):
            lag_velocity[d, a] += (1.0 - s) * seg.lag_impulse_lvlh[j, d] / net_mass[a]
            lag_velocity[d, c] += s * seg.lag_impulse_lvlh[j, d] / net_mass[c]
        px, py, pz = seg.lag_point_body[j, 0], seg.lag_point_body[j, 1], seg.lag_point_body[j, 2]
        arm_x = body_to_lvlh[b, 0, 0] * px + body_to_lvlh[b, 0, 1] * py + body_to_lvlh[b, 0, 2] * pz
        arm_y = body_to_lvlh[b, 1, 0] * px + body_to_lvlh[b, 1, 1] * py + body_to_lvlh[b, 1, 2] * pz
        arm_z = body_to_lvlh[b, 2, 0] * px + body_to_lvlh[b, 2, 1] * py + body_to_lvlh[b, 2, 2] * pz
        _apply_at_point(a, c, s, b, jx * inverse_step, jy * inverse_step, jz * inverse_step, arm_x, arm_y, arm_z,
                        step * stage_weight, seg.node_force_lvlh, body_force_lvlh, torque_lvlh, out_body_impulse,
                        out_node_impulse)
        e = seg.lag_end_node[j]
        if e >= 0:
            for d in range(3):
                lag_velocity[d, e] += seg.lag_end_impulse_lvlh[j, d] / net_mass[e]
            end_impulse = seg.lag_end_impulse_lvlh
            _apply_at_point(e, e, 0.0, b, end_impulse[j, 0] * inverse_step, end_impulse[j, 1] * inverse_step,
                            end_impulse[j, 2] * inverse_step,
                            x[0, e] - com_lvlh[b, 0], x[1, e] - com_lvlh[b, 1], x[2, e] - com_lvlh[b, 2],
                            step * stage_weight, seg.node_force_lvlh, body_force_lvlh, torque_lvlh, out_body_impulse,
                            out_node_impulse)
        seg.lag_body[j] = -1
        seg.lag_end_node[j] = -1


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


@njit(cache=True)
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
    centre_distance, node_speed = seg.centre_distance, seg.node_speed
    sphere_radius, surface_speed = seg.shape_work[0], seg.shape_work[1]
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    box_min, box_max, shape_body, is_box = shapes.box_min_body, shapes.box_max_body, shapes.body, shapes.is_box
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
            e, k, w = _thread_on_box(j, a, c, s, b, pa, pc, reach, x, v, net_force_lvlh, net, states, bodies, shapes,
                                     law, step, n_substeps, stage_weight, buffers, body_force_lvlh, torque_lvlh)
            energy += e
            count += k
            dissipated += w
    net_force_lvlh += node_force
    return energy, count, dissipated


@njit(cache=True, inline="always")
def _to_body(x, i, body_to_lvlh, com_lvlh, b):
    """Node ``i`` of the coordinate-major LVLH positions ``x`` in body ``b``'s frame (m), as a tuple."""
    ax, ay, az = x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2]
    return (body_to_lvlh[b, 0, 0] * ax + body_to_lvlh[b, 1, 0] * ay + body_to_lvlh[b, 2, 0] * az,
            body_to_lvlh[b, 0, 1] * ax + body_to_lvlh[b, 1, 1] * ay + body_to_lvlh[b, 2, 1] * az,
            body_to_lvlh[b, 0, 2] * ax + body_to_lvlh[b, 1, 2] * ay + body_to_lvlh[b, 2, 2] * az)


@njit(cache=True)
def _thread_on_box(j, a, c, s, b, pa, pc, reach, x, v, net_force_lvlh, net, states, bodies, shapes, law, step,
                   n_substeps, stage_weight, buffers, body_force_lvlh, torque_lvlh):
    """Thread ``j`` (nodes a, c; body-frame ends ``pa``, ``pc``) against box shape ``s`` of body ``b`` over the
    step (module doc); returns the contact's elastic energy (J), 1 if it penetrates (else 0), and the energy
    it dissipated (J, weighted).

    The contact's coordinate is the excess q = delta(t*) - delta_e of the deepest point over the deeper node
    e when that node's own sphere penetrates (else q = delta(t*)), and the forces are its energy's gradient:
    F (1 - s) n and F s n on the nodes at the point, and -F n_e on node e, which hands the load its own
    contact carried up to q to the point (module doc); the body takes every reaction on the same lines."""
    seg = buffers.segments
    net_mass, radius = net.mass, net.radius
    lo = (shapes.box_min_body[s, 0], shapes.box_min_body[s, 1], shapes.box_min_body[s, 2])
    hi = (shapes.box_max_body[s, 0], shapes.box_max_body[s, 1], shapes.box_max_body[s, 2])
    d = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    t_deepest, distance = segment_box_deepest(pa, d, lo, hi, seg.breakpoints)
    gap_a, eax, eay, eaz = box_signed_distance(pa[0], pa[1], pa[2], shapes.box_min_body, shapes.box_max_body, s)
    gap_c, ecx, ecy, ecz = box_signed_distance(pc[0], pc[1], pc[2], shapes.box_min_body, shapes.box_max_body, s)
    depth_a, depth_c = radius[a] - gap_a, radius[c] - gap_c
    thread_radius = min(radius[a], radius[c])
    depth = thread_radius - distance
    # only an interior point deeper than both nodes' own spheres (no double count of a thread on a face)
    if depth <= max(depth_a, depth_c) + TIE_DISTANCE:
        return 0.0, 0, 0.0
    end = -1
    if max(depth_a, depth_c) > 0.0:
        end = a if depth_a >= depth_c else c
    penetration = depth - max(0.0, depth_a, depth_c)
    if penetration + reach - thread_radius <= 0.0:
        return 0.0, 0, 0.0
    # where the force acts: the deepest point (the middle of the tied part when several points are as deep); there
    # the force is the gradient of the contact energy (module doc)
    t_low, t_high = segment_box_sublevel(pa, d, lo, hi, distance + TIE_DISTANCE,
                                         seg.breakpoints)
    split = 0.5 * (t_low + t_high) if t_low <= t_high else t_deepest
    rot, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    lag, node_lag = seg.lag_velocity_lvlh, buffers.velocity_lag
    wa, wc = 1.0 - split, split
    # start velocities (as the node contact's) and non-contact accelerations: the point's and node e's
    u = np.empty((3, 3))     # rows: point, node e (LVLH, m/s); then the point's arm from the CoM (m)
    acc = np.zeros((2, 3))   # point, node e (m/s^2)
    for k in range(3):
        ua = v[k, a] + node_lag[k, a] + lag[k, a] + half_kick * net_force_lvlh[k, a] / net_mass[a]
        uc = v[k, c] + node_lag[k, c] + lag[k, c] + half_kick * net_force_lvlh[k, c] / net_mass[c]
        u[0, k] = wa * ua + wc * uc
        acc[0, k] = wa * net_force_lvlh[k, a] / net_mass[a] + wc * net_force_lvlh[k, c] / net_mass[c]
        u[2, k] = wa * x[k, a] + wc * x[k, c] - com_lvlh[b, k]
        if end >= 0:
            u[1, k] = ua if end == a else uc
            acc[1, k] = net_force_lvlh[k, end] / net_mass[end]
    arm_x, arm_y, arm_z = u[2, 0], u[2, 1], u[2, 2]
    wx = u[0, 0] - velocity_lvlh[b, 0] - (omega_lvlh[b, 1] * arm_z - omega_lvlh[b, 2] * arm_y)
    wy = u[0, 1] - velocity_lvlh[b, 1] - (omega_lvlh[b, 2] * arm_x - omega_lvlh[b, 0] * arm_z)
    wz = u[0, 2] - velocity_lvlh[b, 2] - (omega_lvlh[b, 0] * arm_y - omega_lvlh[b, 1] * arm_x)
    nbx, nby, nbz = segment_box_normal(pa[0] + t_deepest * d[0], pa[1] + t_deepest * d[1], pa[2] + t_deepest * d[2],
                                       d[0], d[1], d[2], lo, hi,
                                       rot[b, 0, 0] * wx + rot[b, 1, 0] * wy + rot[b, 2, 0] * wz,
                                       rot[b, 0, 1] * wx + rot[b, 1, 1] * wy + rot[b, 2, 1] * wz,
                                       rot[b, 0, 2] * wx + rot[b, 1, 2] * wy + rot[b, 2, 2] * wz)
    nx = rot[b, 0, 0] * nbx + rot[b, 0, 1] * nby + rot[b, 0, 2] * nbz
    ny = rot[b, 1, 0] * nbx + rot[b, 1, 1] * nby + rot[b, 1, 2] * nbz
    nz = rot[b, 2, 0] * nbx + rot[b, 2, 1] * nby + rot[b, 2, 2] * nbz
    # node e's normal (LVLH), its normal speed relative to the surface and its normal acceleration
    mx_e = my_e = mz_e = 0.0
    rate_e = accel_e = 0.0
    ex_arm = ey_arm = ez_arm = 0.0
    inverse_mass_a = (wa * wa) / net_mass[a]
    inverse_mass_c = (wc * wc) / net_mass[c]
    if end >= 0:
        ebx, eby, ebz = (eax, eay, eaz) if end == a else (ecx, ecy, ecz)
        mx_e = rot[b, 0, 0] * ebx + rot[b, 0, 1] * eby + rot[b, 0, 2] * ebz
        my_e = rot[b, 1, 0] * ebx + rot[b, 1, 1] * eby + rot[b, 1, 2] * ebz
        mz_e = rot[b, 2, 0] * ebx + rot[b, 2, 1] * eby + rot[b, 2, 2] * ebz
        ex_arm, ey_arm, ez_arm = x[0, end] - com_lvlh[b, 0], x[1, end] - com_lvlh[b, 1], x[2, end] - com_lvlh[b, 2]
        sx = u[1, 0] - velocity_lvlh[b, 0] - (omega_lvlh[b, 1] * ez_arm - omega_lvlh[b, 2] * ey_arm)
        sy = u[1, 1] - velocity_lvlh[b, 1] - (omega_lvlh[b, 2] * ex_arm - omega_lvlh[b, 0] * ez_arm)
        sz = u[1, 2] - velocity_lvlh[b, 2] - (omega_lvlh[b, 0] * ey_arm - omega_lvlh[b, 1] * ex_arm)
        rate_e = sx * mx_e + sy * my_e + sz * mz_e
        accel_e = acc[1, 0] * mx_e + acc[1, 1] * my_e + acc[1, 2] * mz_e
        # the coordinate's inverse mass: node e moves along (its share of n) - n_e
        share = wa if end == a else wc
        along = share * (nx * mx_e + ny * my_e + nz * mz_e)
        change = (share * share - 2.0 * along + 1.0) / net_mass[end]
        if end == a:
            inverse_mass_a = change
        else:
            inverse_mass_c = change
    # the coordinate as a particle: its normal rate and acceleration less node e's; the slip is the point's
    wx, wy, wz = wx - rate_e * nx, wy - rate_e * ny, wz - rate_e * nz
    ax_p, ay_p, az_p = acc[0, 0] - accel_e * nx, acc[0, 1] - accel_e * ny, acc[0, 2] - accel_e * nz
    # touches within the step under its velocity and non-contact acceleration (as the node contact)
    pull = ax_p * nx + ay_p * ny + az_p * nz
    closing = (wx * nx + wy * ny + wz * nz) * step
    if penetration - closing - 0.5 * pull * step * step <= 0.0 and penetration <= 0.0:
        return 0.0, 0, 0.0
    point_mass = 1.0 / (inverse_mass_a + inverse_mass_c)
    body_mass = _effective_mass_of_body(rot, bodies.inverse_inertia_body, b, bodies.mass[b], arm_x, arm_y, arm_z,
                                        nx, ny, nz)
    mx, my, mz, ex, ey, ez, lost = _point_contact_over_step(penetration, wx, wy, wz, nx, ny, nz, point_mass * ax_p,
                                                             point_mass * ay_p, point_mass * az_p, point_mass,
                                                             body_mass, law, step, n_substeps, seg)
    scale = point_mass / step
    weight = step * stage_weight
    _apply_pair(a, c, split, b, end, scale * mx, scale * my, scale * mz, nx, ny, nz, mx_e, my_e, mz_e, arm_x, arm_y,
                arm_z, ex_arm, ey_arm, ez_arm, weight, seg, body_force_lvlh, torque_lvlh, buffers)
    # the rest of the step's velocity change, carried to the next evaluation; a thread already carrying one
    # from another shape this step takes this one now (momentum stays exact)
    if seg.lag_body[j] >= 0:
        _apply_pair(a, c, split, b, end, scale * (ex - mx), scale * (ey - my), scale * (ez - mz), nx, ny, nz, mx_e,
                    my_e, mz_e, arm_x, arm_y, arm_z, ex_arm, ey_arm, ez_arm, weight, seg, body_force_lvlh, torque_lvlh,
                    buffers)
    elif ex != mx or ey != my or ez != mz:
        jx, jy, jz = point_mass * (ex - mx), point_mass * (ey - my), point_mass * (ez - mz)
        seg.lag_body[j] = b
        seg.lag_split[j] = split
        seg.lag_impulse_lvlh[j, 0], seg.lag_impulse_lvlh[j, 1], seg.lag_impulse_lvlh[j, 2] = jx, jy, jz
        seg.lag_point_body[j, 0] = rot[b, 0, 0] * arm_x + rot[b, 1, 0] * arm_y + rot[b, 2, 0] * arm_z
        seg.lag_point_body[j, 1] = rot[b, 0, 1] * arm_x + rot[b, 1, 1] * arm_y + rot[b, 2, 1] * arm_z
        seg.lag_point_body[j, 2] = rot[b, 0, 2] * arm_x + rot[b, 1, 2] * arm_y + rot[b, 2, 2] * arm_z
        normal_impulse = jx * nx + jy * ny + jz * nz
        seg.lag_end_node[j] = end
        seg.lag_end_impulse_lvlh[j, 0] = -normal_impulse * mx_e
        seg.lag_end_impulse_lvlh[j, 1] = -normal_impulse * my_e
        seg.lag_end_impulse_lvlh[j, 2] = -normal_impulse * mz_e
    if penetration > 0.0:
        return hertz_elastic_energy(penetration, law.stiffness, law.exponent), 1, lost * stage_weight
    return 0.0, 0, lost * stage_weight


@njit(cache=True, inline="always")
def _apply_pair(a, c, split, b, end, fx, fy, fz, nx, ny, nz, ex, ey, ez, arm_x, arm_y, arm_z, end_arm_x, end_arm_y,
                end_arm_z, weight, seg, body_force_lvlh, torque_lvlh, buffers):
    """The contact force f at the thread's point (split over a and c, reaction on body b) and, with a node
    ``end`` >= 0, -(f . n) n_e on that node with its reaction at the node (``e``: its unit normal, LVLH)."""
    _apply_at_point(a, c, split, b, fx, fy, fz, arm_x, arm_y, arm_z, weight, seg.node_force_lvlh, body_force_lvlh,
                    torque_lvlh, buffers.body_impulse_lvlh, buffers.node_impulse_lvlh)
    if end >= 0:
        normal = fx * nx + fy * ny + fz * nz
        _apply_at_point(end, end, 0.0, b, -normal * ex, -normal * ey, -normal * ez, end_arm_x, end_arm_y, end_arm_z,
                        weight, seg.node_force_lvlh, body_force_lvlh, torque_lvlh, buffers.body_impulse_lvlh,
                        buffers.node_impulse_lvlh)


@njit(cache=True)
def _point_contact_over_step(penetration, wx, wy, wz, nx, ny, nz, fx, fy, fz, point_mass, body_mass, law, step,
                             n_substeps, seg):
    """The point's contact over the step by the node contact's own integration: the implicit step for a slow
    contact, the sub-cycle otherwise (:mod:`multibody.contact_kernel`); returns the point's mean and end
    velocity change by contact (m/s, LVLH) and the energy dissipated (J)."""
    k_contact, exponent, d_contact = law.stiffness, law.exponent, law.damping
    mu_s, mu_k, v_transition = law.mu_static, law.mu_kinetic, law.transition_speed
    if n_substeps > 1 and abs(wx * nx + wy * ny + wz * nz) < law.implicit_speed:
        mx, my, mz, ex, ey, ez, lost, jx, jy, jz = contact_implicit_step_xyz(
            penetration, wx, wy, wz, nx, ny, nz, fx, fy, fz, point_mass, body_mass, step, k_contact, exponent,
            d_contact, mu_s, mu_k, v_transition)
        return mx, my, mz, ex, ey, ez, lost
    scalar, vector, external = seg.contact_scalar, seg.contact_vector, seg.external_force
    scalar[0, 0], scalar[1, 0] = penetration, body_mass
    vector[0, 0, 0], vector[0, 0, 1], vector[0, 0, 2] = wx, wy, wz
    vector[1, 0, 0], vector[1, 0, 1], vector[1, 0, 2] = nx, ny, nz
    external[0], external[1], external[2] = fx, fy, fz
    n_point = n_substeps
    if n_substeps > 1:
        n_point = min(n_substeps, _substeps_to_resolve_contact(scalar[0], vector[0], vector[1], scalar[1], 1, external,
                                                               point_mass, step, k_contact, exponent, d_contact))
    return contact_over_step(scalar[0], vector[0], vector[1], external, point_mass, scalar[1], step, n_point,
                             k_contact, exponent, d_contact, mu_s, mu_k, v_transition, vector[2], scalar[2],
                             vector[3], vector[4])
