"""Contact of every net node with the bodies' shapes over one step, for the compiled kernel.

For each node: the shapes it can touch within the step (:mod:`multibody.broad_phase`), the signed
distance to each (closed form for boxes, closest triangle otherwise), then the node's contacts over
the step: one implicit step for a slow single contact (:mod:`multibody.contact_implicit`), the
sub-cycled impulse otherwise (:func:`multibody.contact.contact_over_step`). Reactions go to the bodies
on the same line of action, so momentum exchange is exact. Frames: LVLH unless named; SI units.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from multibody.broad_phase import box_signed_distance, flag_candidates
from multibody.contact import (
    contact_over_step,
    hertz_elastic_energy,
    signed_distance_to_mesh,
)
from multibody.contact_implicit import contact_implicit_step_xyz
from multibody.jit_cache import NO_REFCOUNTS


@njit(cache=True, inline="always")
def _effective_mass_of_body(body_to_lvlh, inverse_inertia_body, b, mass, ax, ay, az, nx, ny, nz):
    """Mass (kg) body ``b`` shows to a push along n at arm a from its CoM: 1 / (1/m + (a x n)^T J^-1 (a x n)).

    ``body_to_lvlh``, ``inverse_inertia_body`` (nb, 3, 3) are read at ``b`` (whole arrays and an index: row
    views cost a reference count taken and dropped per contact and step)."""
    lx = ay * nz - az * ny
    ly = az * nx - ax * nz
    lz = ax * ny - ay * nx
    # lever in the body frame
    rot = body_to_lvlh
    bx = rot[b, 0, 0] * lx + rot[b, 1, 0] * ly + rot[b, 2, 0] * lz
    by = rot[b, 0, 1] * lx + rot[b, 1, 1] * ly + rot[b, 2, 1] * lz
    bz = rot[b, 0, 2] * lx + rot[b, 1, 2] * ly + rot[b, 2, 2] * lz
    j = inverse_inertia_body
    quad = (bx * (j[b, 0, 0] * bx + j[b, 0, 1] * by + j[b, 0, 2] * bz)
            + by * (j[b, 1, 0] * bx + j[b, 1, 1] * by + j[b, 1, 2] * bz)
            + bz * (j[b, 2, 0] * bx + j[b, 2, 1] * by + j[b, 2, 2] * bz))
    return 1.0 / (1.0 / mass + quad)


@njit(cache=True, inline="always")
def _effective_mass_along_normal(rot, inverse_inertia_body, mass, ax, ay, az, nx, ny, nz):
    """:func:`_effective_mass_of_body` of one body given by its (3, 3) attitude ``rot`` and inverse inertia."""
    return _effective_mass_of_body(rot[np.newaxis], inverse_inertia_body[np.newaxis], 0, mass, ax, ay, az, nx, ny, nz)


@njit(cache=True, inline="always")
def add_body_reaction(b, fx, fy, fz, arm_x, arm_y, arm_z, weight, body_force_lvlh, torque_lvlh, out_body_impulse):
    """The reaction -f of a contact force f = (fx, fy, fz) (N, LVLH) on body ``b``, acting at ``arm`` from its CoM
    (m, LVLH): its force, its moment arm x (-f) about the CoM, and both times ``weight`` into the body's impulse
    (N s, N m s). One place for a node's contact and a thread's (:mod:`multibody.contact_segment`)."""
    body_force_lvlh[b, 0] -= fx
    body_force_lvlh[b, 1] -= fy
    body_force_lvlh[b, 2] -= fz
    mx = -(arm_y * fz - arm_z * fy)
    my = -(arm_z * fx - arm_x * fz)
    mz = -(arm_x * fy - arm_y * fx)
    torque_lvlh[b, 0] += mx
    torque_lvlh[b, 1] += my
    torque_lvlh[b, 2] += mz
    out_body_impulse[b, 0] -= fx * weight
    out_body_impulse[b, 1] -= fy * weight
    out_body_impulse[b, 2] -= fz * weight
    out_body_impulse[b, 3] += mx * weight
    out_body_impulse[b, 4] += my * weight
    out_body_impulse[b, 5] += mz * weight


# inlined (numba IR): as a call, each of its seven array arguments was reference-counted per contact
# and step; with the other per-contact inlines this took NRT_incref/decref from 7 % to 4 % of a run
@njit(cache=True, inline="always")
def _apply_contact_pair(i, b, fx, fy, fz, com_lvlh, weight, x, net_force_lvlh, body_force_lvlh, torque_lvlh,
                        out_body_impulse,
                        out_node_impulse):
    """Force (fx, fy, fz) on node ``i`` and its reaction on body ``b`` on the same line of action; the
    impulses (times ``weight``) accumulate per body and per node."""
    net_force_lvlh[0, i] += fx
    net_force_lvlh[1, i] += fy
    net_force_lvlh[2, i] += fz
    add_body_reaction(b, fx, fy, fz, x[0, i] - com_lvlh[b, 0], x[1, i] - com_lvlh[b, 1], x[2, i] - com_lvlh[b, 2],
                      weight, body_force_lvlh, torque_lvlh, out_body_impulse)
    out_node_impulse[i, 0] += fx * weight
    out_node_impulse[i, 1] += fy * weight
    out_node_impulse[i, 2] += fz * weight


@njit(cache=True, inline="always")
def _apply_each_contact(i, k, strongest, fx, fy, fz, impulses, c_body, step, stage_weight, com_lvlh, x, net_force_lvlh,
                        body_force_lvlh, torque_lvlh, out_body_impulse, out_node_impulse):
    """Node ``i``'s ``k`` >= 2 contacts of one sub-cycle: the node takes its mean kick f = (fx, fy, fz) (N, LVLH) and
    each body the reaction of its own contact's impulse over the step (``impulses`` (>= k, 3), N s, on the node).

    Contact c other than the ``strongest`` acts as the mean force J_c / h on the pair; the strongest takes the rest
    of f, f - sum_(c != s) J_c / h, and the node's carried remainder m (v_end - v_mean) at the next evaluation
    (``lag_body``), so over the two evaluations every body gets -J_c, to round-off, and the node sum J_c. Until
    2026-11-28 every body got a share of the node's net kick in proportion to |J_c|: a node squeezed between two
    bodies (J_1 = -J_2, net kick 0) pushed on neither, the bodies closed on it unresisted and its contact's
    energy grew without bound (the pinch scene of ``tests/multibody/test_contact_pinch.py``: +740 J on 2.5 J)."""
    weight = step * stage_weight
    inverse_step = 1.0 / step
    rest_x, rest_y, rest_z = fx, fy, fz
    for c in range(k):
        if c == strongest:
            continue
        gx, gy, gz = impulses[c, 0] * inverse_step, impulses[c, 1] * inverse_step, impulses[c, 2] * inverse_step
        rest_x, rest_y, rest_z = rest_x - gx, rest_y - gy, rest_z - gz
        _apply_contact_pair(i, c_body[c], gx, gy, gz, com_lvlh, weight, x, net_force_lvlh, body_force_lvlh,
                            torque_lvlh, out_body_impulse, out_node_impulse)
    _apply_contact_pair(i, c_body[strongest], rest_x, rest_y, rest_z, com_lvlh, weight, x, net_force_lvlh,
                        body_force_lvlh, torque_lvlh, out_body_impulse, out_node_impulse)


#: Phase of a contact's linearized oscillation (rad) per contact sub-step. 0.06 is the
#: 2 us sub-step of the seed paper's 7.7 g node striking at 20 m/s, which reproduces the
#: analytic Hunt-Crossley rebound within 0.5 % (tests/multibody/test_contact.py).
CONTACT_PHASE_PER_SUBSTEP = 0.02


@njit(cache=True, **NO_REFCOUNTS)
def _substeps_to_resolve_contact(penetrations, relative_velocities, normals, body_masses, n_contacts,
                                 external_force, node_mass, step, stiffness, exponent, damping):
    """Sub-steps that resolve a node's contacts over one step at CONTACT_PHASE_PER_SUBSTEP.

    The deepest penetration the step can reach is bounded by the energy of the approach
    (reduced mass, closing speed grown by the non-contact force over the step) plus what
    is stored now, and by twice the static penetration under the non-contact force (a
    suddenly applied load). The contact's tangent stiffness n k delta^(n-1) and its
    damping rate d delta^n / m there set the fastest time scale; parallel contacts add.
    """
    omega_squared = 0.0
    fastest_damping = 0.0
    for c in range(n_contacts):
        nx, ny, nz = normals[c, 0], normals[c, 1], normals[c, 2]
        reduced_mass = node_mass * body_masses[c] / (node_mass + body_masses[c])
        push = abs(external_force[0] * nx + external_force[1] * ny + external_force[2] * nz)
        closing = max(0.0, -(relative_velocities[c, 0] * nx + relative_velocities[c, 1] * ny
                             + relative_velocities[c, 2] * nz)) + push / node_mass * step
        stored = hertz_elastic_energy(penetrations[c], stiffness, exponent)
        energy = 0.5 * reduced_mass * closing * closing + stored
        deepest = max(((exponent + 1.0) * energy / stiffness) ** (1.0 / (exponent + 1.0)),
                      2.0 * (push / stiffness) ** (1.0 / exponent))
        if deepest <= 0.0:
            continue
        omega_squared += exponent * stiffness * deepest ** (exponent - 1.0) / reduced_mass
        fastest_damping = max(fastest_damping, damping * deepest ** exponent / reduced_mass)
    rate = max(math.sqrt(omega_squared), fastest_damping)
    return max(1, int(math.ceil(step * rate / CONTACT_PHASE_PER_SUBSTEP)))


# no reference counts (jit_cache.NO_REFCOUNTS): its entry and exits counted 70 arrays each a step
@njit(cache=True, inline="always")
def _thread_lag_in_start_velocity(i, thread_lag, node_mass, step, non_contact_force_lvlh, start_velocity_lvlh):
    """Node ``i``'s start velocity and non-contact force with the threads' carried remainders as the clusters see
    them (:func:`multibody.segment_pairs._node_motion`): the remainder r (m/s, LVLH, ``thread_lag``) is velocity the
    node already has at the step's start (the end of the last step's sub-cycle), so all of it is in the start
    velocity and none in the force held over the step. Released as the force m r / step
    (:func:`multibody.contact_segment._release_carried`), it entered the start velocity half (the half kick) and the
    held force whole: a node whose own contact moved from a cluster to the node contact saw r / 2 at the start and
    r more by the end (helper thread13's "known inconsistency"; helper thread14 removed it)."""
    for d in range(3):
        non_contact_force_lvlh[i, d] -= node_mass * thread_lag[d, i] / step
        start_velocity_lvlh[i, d] += 0.5 * thread_lag[d, i]


@njit(cache=True, **NO_REFCOUNTS)
def add_contact_forces(x, v, net, states, bodies, shapes, law, step, n_substeps, stage_weight, buffers, net_force_lvlh,
                       body_force_lvlh,
                       torque_lvlh):
    """Add node-body contact kicks to ``net_force_lvlh`` and their reactions to ``body_force_lvlh``/``torque_lvlh``.

    Parameters
    ----------
    x, v : (3, n) float
        Node positions (m) and velocities (m/s) at the evaluation state, LVLH, coordinate-major (the
        kernel's layout: the thread pass and the box test vectorize over nodes).
    net, states, bodies, shapes, law : NetArrays, BodyStates, BodyArrays, ShapeArrays, ContactLaw
        (:mod:`multibody.kernel`).
    step : float
        Integrator step (s).
    n_substeps : int
        Contact sub-steps per step (1: plain force evaluation).
    stage_weight : float
        Weight of the accumulated impulses and energies (1 / force evaluations per step).
    buffers : KernelBuffers
        Impulse accumulators, the carried velocity lag and work space (:mod:`multibody.kernel`).
    net_force_lvlh : (3, n) float
        Enters holding every non-contact force on the nodes (N, LVLH), coordinate-major; the contact
        forces are added.
    body_force_lvlh, torque_lvlh : (nb, 3) float
        The reactions are added: force (N) and torque about the CoM (N m), LVLH.

    Returns
    -------
    contact_energy : float
        Elastic contact energy (J) at this evaluation.
    n_contacts : int
        Penetrating contacts at this evaluation.
    dissipated : float
        Energy dissipated by contact over the step (J, weighted by ``stage_weight``).

    Notes
    -----
    With sub-cycling (Verlet only), the node's state at the evaluation time is the
    solver's position and its mid-step velocity ``v`` (Verlet evaluates the force before
    its second half kick) plus the half kick of the non-contact force and the lag carried
    from the previous step. Starting the sub-cycle from ``v`` alone would apply half of
    every thread force one step late inside contact: a delayed restoring force, which
    acts as a negative damping of about ``k step / 2`` per thread (3 N s/m at 1e-4 s
    against the threads' own 1.6 N s/m) and pumped energy into nodes held on a surface.
    """
    net_mass, net_radius = net.mass, net.radius
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    body_mass_all, inverse_inertia = bodies.mass, bodies.inverse_inertia_body
    triangles, triangle_normals, shape_body = shapes.triangles_body, shapes.normals_body, shapes.body
    shape_triangle_range, shape_box_min, shape_box_max = shapes.triangle_range, shapes.box_min_body, shapes.box_max_body
    shape_is_box = shapes.is_box
    k_contact, exponent, d_contact = law.stiffness, law.exponent, law.damping
    mu_s, mu_k, v_transition, implicit_speed = law.mu_static, law.mu_kinetic, law.transition_speed, law.implicit_speed
    velocity_lag, lag_body, work_node, candidates = (buffers.velocity_lag, buffers.lag_body, buffers.work_node,
                                                     buffers.candidates)
    out_body_impulse, out_node_impulse = buffers.body_impulse_lvlh, buffers.node_impulse_lvlh
    non_contact_force_lvlh, start_velocity_lvlh = buffers.work[2], buffers.work[3]
    n = net_mass.shape[0]
    # pairs a thread's sub-cycle integrated this step (multibody.contact_segment; none when thread contact is off)
    segments_on, owned_shape = buffers.segments.enabled != 0, buffers.segments.owned_shape
    thread_lag = buffers.segments.lag_velocity_lvlh
    contact_energy = 0.0
    n_contacts = 0
    dissipated_total = 0.0
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    speed, push, reach = work_node[0], work_node[1], work_node[2]  # push: acceleration bound (m/s^2)
    inverse_masses = work_node[3]
    # coordinate rows (the lag coordinate-major too: its node-major reads kept this loop scalar, 5.3 against
    # 2.3 us a pass for the reference net, offline); each sum in the order it had from 0.0 (0.0 + x is x)
    v0, v1, v2 = v[0], v[1], v[2]
    lag0, lag1, lag2 = velocity_lag[0], velocity_lag[1], velocity_lag[2]
    f0, f1, f2 = net_force_lvlh[0], net_force_lvlh[1], net_force_lvlh[2]
    for i in range(n):
        # An upper bound of the exact reach below (L1 norms, no square roots): it only feeds the
        # bounding-sphere pass, which must never miss a node the exact tests would keep.
        inverse_mass = inverse_masses[i]
        speed_bound = abs(v0[i] + lag0[i] + half_kick * f0[i] * inverse_mass)
        speed_bound += abs(v1[i] + lag1[i] + half_kick * f1[i] * inverse_mass)
        speed_bound += abs(v2[i] + lag2[i] + half_kick * f2[i] * inverse_mass)
        push_bound = abs(f0[i]) + abs(f1[i]) + abs(f2[i])
        reach[i] = 1.001 * (net_radius[i] + step * speed_bound + 0.5 * step * step * push_bound * inverse_mass)
    n_shapes = shape_body.shape[0]
    # per-shape work space from the buffers (allocating it was 11 arrays a step)
    work_shape, work_shape_scalar = buffers.work_shape, buffers.work_shape_scalar
    shape_speed = work_shape_scalar[4]
    for s in range(n_shapes):
        b = shape_body[s]
        lo, hi = shape_box_min[s], shape_box_max[s]
        extent = math.sqrt(max(lo[0] * lo[0] + lo[1] * lo[1] + lo[2] * lo[2],
                               hi[0] * hi[0] + hi[1] * hi[1] + hi[2] * hi[2]))
        shape_speed[s] = (math.sqrt(velocity_lvlh[b, 0] ** 2 + velocity_lvlh[b, 1] ** 2 + velocity_lvlh[b, 2] ** 2)
                          + math.sqrt(omega_lvlh[b, 0] ** 2 + omega_lvlh[b, 1] ** 2 + omega_lvlh[b, 2] ** 2) * extent)
    # bounding-sphere pass (multibody.broad_phase); the box test below stays the exact filter
    shape_reach = work_shape_scalar[5]
    for s in range(n_shapes):
        shape_reach[s] = step * shape_speed[s]
    flag_candidates(x, reach, body_to_lvlh, com_lvlh, shape_body, shape_box_min, shape_box_max, shape_reach,
                    candidates)
    # per-node contact lists and sub-cycle work space, reused
    c_body = buffers.contact_body
    c_pen, c_mass, impulse_norm, work_delta = (work_shape_scalar[0], work_shape_scalar[1], work_shape_scalar[2],
                                               work_shape_scalar[3])
    c_normal, c_rel, impulses, work_recoil, work_forces = (work_shape[0], work_shape[1], work_shape[2], work_shape[3],
                                                           work_shape[4])
    for i in range(n):
        if lag_body[i] < 0 and not candidates[n_shapes, i]:
            continue  # far from every shape and nothing carried: no contact work for this node
        # the node's non-contact force and its velocity at the evaluation time (see the doc above)
        for d in range(3):
            non_contact_force_lvlh[i, d] = net_force_lvlh[d, i]
            start_velocity_lvlh[i, d] = v[d, i] + velocity_lag[d, i] + half_kick * net_force_lvlh[d, i] / net_mass[i]
        if segments_on and half_kick > 0.0:
            _thread_lag_in_start_velocity(i, thread_lag, net_mass[i], step, non_contact_force_lvlh,
                                          start_velocity_lvlh)
        speed[i] = math.sqrt(start_velocity_lvlh[i, 0] ** 2 + start_velocity_lvlh[i, 1] ** 2
                             + start_velocity_lvlh[i, 2] ** 2)
        push[i] = math.sqrt(net_force_lvlh[0, i] ** 2 + net_force_lvlh[1, i] ** 2
                            + net_force_lvlh[2, i] ** 2) / net_mass[i]
        k = 0
        for s in range(n_shapes):
            if not candidates[s, i]:
                continue
            if segments_on and owned_shape[i] == s:
                continue
            b = shape_body[s]
            # Broad phase in scalars: node in the body frame against the shape's box, grown by
            # the node radius and the distance the pair can close within one step.
            ax = x[0, i] - com_lvlh[b, 0]
            ay = x[1, i] - com_lvlh[b, 1]
            az = x[2, i] - com_lvlh[b, 2]
            px = body_to_lvlh[b, 0, 0] * ax + body_to_lvlh[b, 1, 0] * ay + body_to_lvlh[b, 2, 0] * az
            py = body_to_lvlh[b, 0, 1] * ax + body_to_lvlh[b, 1, 1] * ay + body_to_lvlh[b, 2, 1] * az
            pz = body_to_lvlh[b, 0, 2] * ax + body_to_lvlh[b, 1, 2] * ay + body_to_lvlh[b, 2, 2] * az
            margin = net_radius[i] + step * (speed[i] + shape_speed[s]) + 0.5 * step * step * push[i]
            if (px < shape_box_min[s, 0] - margin or px > shape_box_max[s, 0] + margin
                    or py < shape_box_min[s, 1] - margin or py > shape_box_max[s, 1] + margin
                    or pz < shape_box_min[s, 2] - margin or pz > shape_box_max[s, 2] + margin):
                continue
            if shape_is_box[s]:
                distance, nbx, nby, nbz = box_signed_distance(px, py, pz, shape_box_min, shape_box_max, s)
            else:
                distance, nbx, nby, nbz = signed_distance_to_mesh(
                    px, py, pz, triangles, triangle_normals, shape_triangle_range[s, 0], shape_triangle_range[s, 1])
            penetration = net_radius[i] - distance
            nx = body_to_lvlh[b, 0, 0] * nbx + body_to_lvlh[b, 0, 1] * nby + body_to_lvlh[b, 0, 2] * nbz
            ny = body_to_lvlh[b, 1, 0] * nbx + body_to_lvlh[b, 1, 1] * nby + body_to_lvlh[b, 1, 2] * nbz
            nz = body_to_lvlh[b, 2, 0] * nbx + body_to_lvlh[b, 2, 1] * nby + body_to_lvlh[b, 2, 2] * nbz
            wx, wy, wz = omega_lvlh[b, 0], omega_lvlh[b, 1], omega_lvlh[b, 2]
            rx = start_velocity_lvlh[i, 0] - velocity_lvlh[b, 0] - (wy * az - wz * ay)
            ry = start_velocity_lvlh[i, 1] - velocity_lvlh[b, 1] - (wz * ax - wx * az)
            rz = start_velocity_lvlh[i, 2] - velocity_lvlh[b, 2] - (wx * ay - wy * ax)
            # Touches within the step if the gap closes under the current velocity and the
            # non-contact force (a taut thread can pull a node 0.6 mm in 1e-4 s; missing that
            # lets it sink unresisted for a step and come back out with the Hertz energy).
            pull = (non_contact_force_lvlh[i, 0] * nx + non_contact_force_lvlh[i, 1] * ny
                    + non_contact_force_lvlh[i, 2] * nz) / net_mass[i]
            closing = (rx * nx + ry * ny + rz * nz) * step
            if penetration - closing - 0.5 * pull * step * step <= 0.0 and penetration <= 0.0:
                continue
            c_body[k] = b
            c_pen[k] = penetration
            c_normal[k, 0], c_normal[k, 1], c_normal[k, 2] = nx, ny, nz
            c_rel[k, 0], c_rel[k, 1], c_rel[k, 2] = rx, ry, rz
            c_mass[k] = _effective_mass_of_body(body_to_lvlh, inverse_inertia, b, body_mass_all[b], ax, ay, az,
                                                nx, ny, nz)
            k += 1
            if penetration > 0.0:
                contact_energy += hertz_elastic_energy(penetration, k_contact, exponent)
                n_contacts += 1
        lag_x = lag_y = lag_z = 0.0
        strongest = -1
        if k > 0:
            # All of this node's contacts in one sub-cycle (a node pinched between two bodies
            # must feel both). The contact force is the kick that makes the integrator's next
            # drift follow the sub-cycled path; the true end velocity minus the mean velocity
            # is carried as a lag and released at the next evaluation.
            normal_speed = abs(c_rel[0, 0] * c_normal[0, 0] + c_rel[0, 1] * c_normal[0, 1]
                               + c_rel[0, 2] * c_normal[0, 2])
            if n_substeps > 1 and k == 1 and normal_speed < implicit_speed:
                # a resting or slow single contact: one implicit step (multibody.contact_implicit)
                # in scalars: array views would cost a reference count each per contact and step
                mx, my, mz, ex, ey, ez, dissipated, jx, jy, jz = contact_implicit_step_xyz(
                    c_pen[0], c_rel[0, 0], c_rel[0, 1], c_rel[0, 2], c_normal[0, 0], c_normal[0, 1], c_normal[0, 2],
                    non_contact_force_lvlh[i, 0], non_contact_force_lvlh[i, 1], non_contact_force_lvlh[i, 2],
                    net_mass[i], c_mass[0], step, k_contact, exponent, d_contact, mu_s, mu_k, v_transition)
                impulses[0, 0], impulses[0, 1], impulses[0, 2] = jx, jy, jz
            else:
                n_node = n_substeps
                if n_substeps > 1:
                    n_node = min(n_substeps, _substeps_to_resolve_contact(
                        c_pen, c_rel, c_normal, c_mass, k, non_contact_force_lvlh[i], net_mass[i], step,
                        k_contact, exponent, d_contact))
                mx, my, mz, ex, ey, ez, dissipated = contact_over_step(
                    c_pen[:k], c_rel[:k], c_normal[:k], non_contact_force_lvlh[i], net_mass[i], c_mass[:k], step,
                    n_node,
                    k_contact, exponent, d_contact, mu_s, mu_k, v_transition,
                    impulses, work_delta, work_recoil, work_forces)
            scale = net_mass[i] / step
            # in scalars: a slice here (a view) costs a reference count per contact node and step
            strongest = 0
            for c in range(k):
                impulse_norm[c] = math.sqrt(impulses[c, 0] ** 2 + impulses[c, 1] ** 2 + impulses[c, 2] ** 2)
                if impulse_norm[c] > impulse_norm[strongest]:
                    strongest = c
            if k == 1:
                _apply_contact_pair(i, c_body[0], scale * mx, scale * my, scale * mz, com_lvlh, step * stage_weight,
                                    x, net_force_lvlh, body_force_lvlh, torque_lvlh, out_body_impulse,
                                    out_node_impulse)
            else:
                _apply_each_contact(i, k, strongest, scale * mx, scale * my, scale * mz, impulses, c_body, step,
                                    stage_weight, com_lvlh, x, net_force_lvlh, body_force_lvlh, torque_lvlh,
                                    out_body_impulse, out_node_impulse)
            lag_x, lag_y, lag_z = ex - mx, ey - my, ez - mz
            dissipated_total += dissipated * stage_weight
        # Release the lag carried from the previous step (zero without sub-cycling).
        b = lag_body[i]
        if b >= 0:
            scale = net_mass[i] / step
            _apply_contact_pair(i, b, scale * velocity_lag[0, i], scale * velocity_lag[1, i],
                                scale * velocity_lag[2, i], com_lvlh, step * stage_weight, x,
                                net_force_lvlh, body_force_lvlh, torque_lvlh, out_body_impulse, out_node_impulse)
        lag_body[i] = c_body[strongest] if k > 0 else -1
        velocity_lag[0, i] = lag_x
        velocity_lag[1, i] = lag_y
        velocity_lag[2, i] = lag_z
    return contact_energy, n_contacts, dissipated_total
