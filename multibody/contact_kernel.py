"""Contact of every net node with the bodies' shapes over one step, for the compiled kernel.

For each node: the shapes it can touch within the step (:mod:`multibody.broad_phase`), the signed
distance to each (closed form for boxes, closest triangle otherwise), then the node's contacts over
the step: one implicit step for a slow single contact (:mod:`multibody.contact_implicit`), the
sub-cycled impulse otherwise (:func:`multibody.contact.contact_over_step`). Reactions go to the bodies
on the same line of action, so momentum exchange is exact. Frames: LVLH unless named; SI units.
"""
from __future__ import annotations

import math

from typing import NamedTuple

import numpy as np
from numba import njit

from multibody.broad_phase import box_signed_distance, flag_candidates
from multibody.contact import (
    contact_over_step,
    hertz_elastic_energy,
    signed_distance_to_mesh,
)
from multibody.contact_implicit import contact_implicit_step


@njit(cache=True)
def _effective_mass_along_normal(rot, inverse_inertia_body, mass, ax, ay, az, nx, ny, nz):
    """Mass (kg) a body shows to a push along n at arm a from its CoM: 1 / (1/m + (a x n)^T J^-1 (a x n))."""
    lx = ay * nz - az * ny
    ly = az * nx - ax * nz
    lz = ax * ny - ay * nx
    # lever in the body frame
    bx = rot[0, 0] * lx + rot[1, 0] * ly + rot[2, 0] * lz
    by = rot[0, 1] * lx + rot[1, 1] * ly + rot[2, 1] * lz
    bz = rot[0, 2] * lx + rot[1, 2] * ly + rot[2, 2] * lz
    j = inverse_inertia_body
    quad = (bx * (j[0, 0] * bx + j[0, 1] * by + j[0, 2] * bz) + by * (j[1, 0] * bx + j[1, 1] * by + j[1, 2] * bz)
            + bz * (j[2, 0] * bx + j[2, 1] * by + j[2, 2] * bz))
    return 1.0 / (1.0 / mass + quad)


@njit(cache=True)
def _apply_contact_pair(i, b, fx, fy, fz, com_lvlh, weight, x, net_force_lvlh, body_force_lvlh, torque_lvlh,
                        out_body_impulse,
                        out_node_impulse):
    """Force (fx, fy, fz) on node ``i`` and its reaction on body ``b`` on the same line of action; the
    impulses (times ``weight``) accumulate per body and per node."""
    net_force_lvlh[i, 0] += fx
    net_force_lvlh[i, 1] += fy
    net_force_lvlh[i, 2] += fz
    body_force_lvlh[b, 0] -= fx
    body_force_lvlh[b, 1] -= fy
    body_force_lvlh[b, 2] -= fz
    ax = x[i, 0] - com_lvlh[b, 0]
    ay = x[i, 1] - com_lvlh[b, 1]
    az = x[i, 2] - com_lvlh[b, 2]
    # moment of the reaction -f about the body CoM: a x (-f)
    mx = -(ay * fz - az * fy)
    my = -(az * fx - ax * fz)
    mz = -(ax * fy - ay * fx)
    torque_lvlh[b, 0] += mx
    torque_lvlh[b, 1] += my
    torque_lvlh[b, 2] += mz
    out_body_impulse[b, 0] -= fx * weight
    out_body_impulse[b, 1] -= fy * weight
    out_body_impulse[b, 2] -= fz * weight
    out_body_impulse[b, 3] += mx * weight
    out_body_impulse[b, 4] += my * weight
    out_body_impulse[b, 5] += mz * weight
    out_node_impulse[i, 0] += fx * weight
    out_node_impulse[i, 1] += fy * weight
    out_node_impulse[i, 2] += fz * weight


#: Phase of a contact's linearized oscillation (rad) per contact sub-step. 0.06 is the
#: 2 us sub-step of the seed paper's 7.7 g node striking at 20 m/s, which reproduces the
#: analytic Hunt-Crossley rebound within 0.5 % (tests/multibody/test_contact.py).
CONTACT_PHASE_PER_SUBSTEP = 0.02


@njit(cache=True)
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


@njit(cache=True)
def add_contact_forces(x, v, net, states, bodies, shapes, law, step, n_substeps, stage_weight, buffers, net_force_lvlh,
                       body_force_lvlh,
                       torque_lvlh):
    """Add node-body contact kicks to ``net_force_lvlh`` and their reactions to ``body_force_lvlh``/``torque_lvlh``.

    Parameters
    ----------
    x, v : (n, 3) float
        Node positions (m) and velocities (m/s) at the evaluation state, LVLH.
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
    net_force_lvlh : (n, 3) float
        Enters holding every non-contact force on the nodes (N, LVLH); the contact forces are added.
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
    n = net.mass.shape[0]
    half_kick = 0.5 * step if n_substeps > 1 else 0.0
    _bound_reach(x, v, net, buffers, net_force_lvlh, step, half_kick)
    shape_speed = _shape_speeds(states, shapes)
    # bounding-box pass over all nodes (multibody.broad_phase); the exact margin test follows per node
    flag_candidates(x, buffers.work_node[2], states.body_to_lvlh, states.com_lvlh, shapes.body, shapes.box_min_body,
                    shapes.box_max_body, step * shape_speed, buffers.candidates)
    contacts = node_contact_lists(shapes.body.shape[0])
    lag_body, velocity_lag, candidates = buffers.lag_body, buffers.velocity_lag, buffers.candidates
    n_shapes = shapes.body.shape[0]
    contact_energy = 0.0
    n_contacts = 0
    dissipated_total = 0.0
    for i in range(n):
        if lag_body[i] < 0 and not candidates[n_shapes, i]:
            continue  # far from every shape and nothing carried: no contact work for this node
        k, energy, touching = _gather_node_contacts(i, x, v, net, states, bodies, shapes, law, step, half_kick,
                                                    shape_speed, buffers, net_force_lvlh, contacts)
        contact_energy += energy
        n_contacts += touching
        lag_x = lag_y = lag_z = 0.0
        strongest = -1
        if k > 0:
            # All of this node's contacts in one sub-cycle (a node pinched between two bodies
            # must feel both). The contact force is the kick that makes the integrator's next
            # drift follow the sub-cycled path; the true end velocity minus the mean velocity
            # is carried as a lag and released at the next evaluation.
            mx, my, mz, ex, ey, ez, dissipated = _resolve_node_contacts(i, k, contacts, net, law, step, n_substeps,
                                                                        buffers)
            strongest = _react_on_bodies(i, k, contacts, mx, my, mz, net.mass[i] / step, states.com_lvlh,
                                         step * stage_weight, x, buffers, net_force_lvlh, body_force_lvlh, torque_lvlh)
            lag_x, lag_y, lag_z = ex - mx, ey - my, ez - mz
            dissipated_total += dissipated * stage_weight
        # Release the lag carried from the previous step (zero without sub-cycling).
        b = lag_body[i]
        if b >= 0:
            scale = net.mass[i] / step
            _apply_contact_pair(i, b, scale * velocity_lag[i, 0], scale * velocity_lag[i, 1],
                                scale * velocity_lag[i, 2], states.com_lvlh, step * stage_weight, x,
                                net_force_lvlh, body_force_lvlh, torque_lvlh, buffers.body_impulse_lvlh,
                                buffers.node_impulse_lvlh)
        lag_body[i] = contacts.body[strongest] if k > 0 else -1
        velocity_lag[i, 0] = lag_x
        velocity_lag[i, 1] = lag_y
        velocity_lag[i, 2] = lag_z
    return contact_energy, n_contacts, dissipated_total


class NodeContacts(NamedTuple):
    """One node's contacts within a step (at most one per shape, ns shapes), and the sub-cycle's work
    space: allocated once per force evaluation and reused node by node."""

    body: np.ndarray                    # (ns,) int64 body of each contact
    penetration: np.ndarray             # (ns,) at the evaluation time (m), negative for a gap
    normal_lvlh: np.ndarray             # (ns, 3) unit normal from the body to the node
    relative_velocity_lvlh: np.ndarray  # (ns, 3) node velocity minus the body's surface velocity (m/s)
    effective_mass: np.ndarray          # (ns,) the body's mass at the contact along the normal (kg)
    impulse_lvlh: np.ndarray            # (ns, 3) contact impulse on the node over the step (N s)
    impulse_norm: np.ndarray            # (ns,) its magnitude (N s)
    delta: np.ndarray                   # (ns,) work space of the sub-cycle
    recoil: np.ndarray                  # (ns, 3) work space
    forces: np.ndarray                  # (ns, 3) work space


@njit(cache=True)
def node_contact_lists(n_shapes):
    """Empty :class:`NodeContacts` for ``n_shapes`` shapes.

    Parameters
    ----------
    n_shapes : int
    """
    return NodeContacts(np.empty(n_shapes, np.int64), np.empty(n_shapes), np.empty((n_shapes, 3)),
                        np.empty((n_shapes, 3)), np.empty(n_shapes), np.empty((n_shapes, 3)), np.empty(n_shapes),
                        np.empty(n_shapes), np.empty((n_shapes, 3)), np.empty((n_shapes, 3)))


@njit(cache=True)
def _bound_reach(x, v, net, buffers, net_force_lvlh, step, half_kick):
    """``buffers.work_node[2]``: how far (m) each node can reach within the step, an upper bound of the
    exact margin of :func:`_gather_node_contacts` (L1 norms, no square roots): it only feeds the
    bounding-box pass, which must never miss a node the exact tests would keep."""
    velocity_lag, work_node, net_radius = buffers.velocity_lag, buffers.work_node, net.radius
    reach, inverse_masses = work_node[2], work_node[3]
    for i in range(net.mass.shape[0]):
        inverse_mass = inverse_masses[i]
        speed_bound = 0.0
        push_bound = 0.0
        for d in range(3):
            speed_bound += abs(v[i, d] + velocity_lag[i, d] + half_kick * net_force_lvlh[i, d] * inverse_mass)
            push_bound += abs(net_force_lvlh[i, d])
        reach[i] = 1.001 * (net_radius[i] + step * speed_bound + 0.5 * step * step * push_bound * inverse_mass)


@njit(cache=True)
def _shape_speeds(states, shapes):
    """(ns,) the fastest any point of each shape's bounding box moves (m/s): CoM speed plus |omega| times
    the box's farthest corner from the CoM."""
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    n_shapes = shapes.body.shape[0]
    shape_speed = np.empty(n_shapes)
    for s in range(n_shapes):
        b = shapes.body[s]
        lo, hi = shapes.box_min_body[s], shapes.box_max_body[s]
        extent = math.sqrt(max(lo[0] * lo[0] + lo[1] * lo[1] + lo[2] * lo[2],
                               hi[0] * hi[0] + hi[1] * hi[1] + hi[2] * hi[2]))
        shape_speed[s] = (math.sqrt(velocity_lvlh[b, 0] ** 2 + velocity_lvlh[b, 1] ** 2 + velocity_lvlh[b, 2] ** 2)
                          + math.sqrt(omega_lvlh[b, 0] ** 2 + omega_lvlh[b, 1] ** 2 + omega_lvlh[b, 2] ** 2) * extent)
    return shape_speed


@njit(cache=True)
def _gather_node_contacts(i, x, v, net, states, bodies, shapes, law, step, half_kick, shape_speed, buffers,
                          net_force_lvlh, contacts):
    """Node ``i``'s contacts within the step, into ``contacts``; returns their number, the elastic energy
    of the penetrating ones (J) and how many penetrate now.

    Sets the node's non-contact force and its velocity at the evaluation time (``buffers.work[2]``,
    ``[3]``; see :func:`add_contact_forces`), then, per flagged shape: the exact margin test in the body
    frame, the signed distance (closed form for boxes, closest triangle otherwise) and the contact's
    normal, relative velocity and effective mass.
    """
    net_mass, net_radius = net.mass, net.radius
    body_to_lvlh, com_lvlh = states.body_to_lvlh, states.com_lvlh
    velocity_lvlh, omega_lvlh = states.velocity_lvlh, states.omega_lvlh
    shape_body, shape_box_min, shape_box_max = shapes.body, shapes.box_min_body, shapes.box_max_body
    non_contact_force_lvlh, start_velocity_lvlh = buffers.work[2], buffers.work[3]
    velocity_lag, candidates = buffers.velocity_lag, buffers.candidates
    speed, push = buffers.work_node[0], buffers.work_node[1]  # push: acceleration bound (m/s^2)
    # the node's non-contact force and its velocity at the evaluation time (see add_contact_forces)
    for d in range(3):
        non_contact_force_lvlh[i, d] = net_force_lvlh[i, d]
        start_velocity_lvlh[i, d] = v[i, d] + velocity_lag[i, d] + half_kick * net_force_lvlh[i, d] / net_mass[i]
    speed[i] = math.sqrt(start_velocity_lvlh[i, 0] ** 2 + start_velocity_lvlh[i, 1] ** 2
                         + start_velocity_lvlh[i, 2] ** 2)
    push[i] = math.sqrt(net_force_lvlh[i, 0] ** 2 + net_force_lvlh[i, 1] ** 2
                        + net_force_lvlh[i, 2] ** 2) / net_mass[i]
    energy = 0.0
    touching = 0
    k = 0
    for s in range(shape_body.shape[0]):
        if not candidates[s, i]:
            continue
        b = shape_body[s]
        # Broad phase in scalars: node in the body frame against the shape's box, grown by
        # the node radius and the distance the pair can close within one step.
        ax = x[i, 0] - com_lvlh[b, 0]
        ay = x[i, 1] - com_lvlh[b, 1]
        az = x[i, 2] - com_lvlh[b, 2]
        px = body_to_lvlh[b, 0, 0] * ax + body_to_lvlh[b, 1, 0] * ay + body_to_lvlh[b, 2, 0] * az
        py = body_to_lvlh[b, 0, 1] * ax + body_to_lvlh[b, 1, 1] * ay + body_to_lvlh[b, 2, 1] * az
        pz = body_to_lvlh[b, 0, 2] * ax + body_to_lvlh[b, 1, 2] * ay + body_to_lvlh[b, 2, 2] * az
        margin = net_radius[i] + step * (speed[i] + shape_speed[s]) + 0.5 * step * step * push[i]
        if (px < shape_box_min[s, 0] - margin or px > shape_box_max[s, 0] + margin
                or py < shape_box_min[s, 1] - margin or py > shape_box_max[s, 1] + margin
                or pz < shape_box_min[s, 2] - margin or pz > shape_box_max[s, 2] + margin):
            continue
        if shapes.is_box[s]:
            distance, nbx, nby, nbz = box_signed_distance(px, py, pz, shape_box_min[s], shape_box_max[s])
        else:
            distance, nbx, nby, nbz = signed_distance_to_mesh(
                px, py, pz, shapes.triangles_body, shapes.normals_body, shapes.triangle_range[s, 0],
                shapes.triangle_range[s, 1])
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
        contacts.body[k] = b
        contacts.penetration[k] = penetration
        normal, relative = contacts.normal_lvlh, contacts.relative_velocity_lvlh
        normal[k, 0], normal[k, 1], normal[k, 2] = nx, ny, nz
        relative[k, 0], relative[k, 1], relative[k, 2] = rx, ry, rz
        contacts.effective_mass[k] = _effective_mass_along_normal(
            body_to_lvlh[b], bodies.inverse_inertia_body[b], bodies.mass[b], ax, ay, az, nx, ny, nz)
        k += 1
        if penetration > 0.0:
            energy += hertz_elastic_energy(penetration, law.stiffness, law.exponent)
            touching += 1
    return k, energy, touching


@njit(cache=True)
def _resolve_node_contacts(i, k, contacts, net, law, step, n_substeps, buffers):
    """Node ``i``'s ``k`` contacts over the step: one implicit step for a slow single contact
    (:mod:`multibody.contact_implicit`), the sub-cycled impulse otherwise; returns the node's mean and end
    velocity change by contact (m/s, LVLH) and the energy dissipated (J), as
    :func:`multibody.contact.contact_over_step`; the impulses go to ``contacts.impulse_lvlh``."""
    penetration, normal, relative = contacts.penetration, contacts.normal_lvlh, contacts.relative_velocity_lvlh
    effective_mass, impulses = contacts.effective_mass, contacts.impulse_lvlh
    non_contact_force = buffers.work[2][i]
    node_mass = net.mass[i]
    normal_speed = abs(relative[0, 0] * normal[0, 0] + relative[0, 1] * normal[0, 1] + relative[0, 2] * normal[0, 2])
    if n_substeps > 1 and k == 1 and normal_speed < law.implicit_speed:
        # a resting or slow single contact: one implicit step (multibody.contact_implicit)
        return contact_implicit_step(
            penetration[0], relative[0], normal[0], non_contact_force, node_mass, effective_mass[0], step,
            law.stiffness, law.exponent, law.damping, law.mu_static, law.mu_kinetic, law.transition_speed,
            impulses[0])
    n_node = n_substeps
    if n_substeps > 1:
        n_node = min(n_substeps, _substeps_to_resolve_contact(
            penetration, relative, normal, effective_mass, k, non_contact_force, node_mass, step,
            law.stiffness, law.exponent, law.damping))
    return contact_over_step(
        penetration[:k], relative[:k], normal[:k], non_contact_force, node_mass, effective_mass[:k], step, n_node,
        law.stiffness, law.exponent, law.damping, law.mu_static, law.mu_kinetic, law.transition_speed,
        impulses, contacts.delta, contacts.recoil, contacts.forces)


@njit(cache=True)
def _react_on_bodies(i, k, contacts, mx, my, mz, scale, com_lvlh, weight, x, buffers, net_force_lvlh,
                     body_force_lvlh, torque_lvlh):
    """Apply node ``i``'s contact force ``scale`` (mx, my, mz) (N) and its reactions: each body takes the
    share of its impulse (weights sum to 1, so momentum exchange stays exact). Returns the contact with
    the strongest impulse (the lag's body)."""
    impulses, impulse_norm = contacts.impulse_lvlh, contacts.impulse_norm
    for c in range(k):
        impulse_norm[c] = math.sqrt(impulses[c, 0] ** 2 + impulses[c, 1] ** 2 + impulses[c, 2] ** 2)
    total = impulse_norm[:k].sum()
    strongest = int(np.argmax(impulse_norm[:k]))
    for c in range(k):
        share = impulse_norm[c] / total if total > 0.0 else 1.0 / k
        _apply_contact_pair(i, contacts.body[c], share * scale * mx, share * scale * my, share * scale * mz,
                            com_lvlh, weight, x, net_force_lvlh, body_force_lvlh, torque_lvlh,
                            buffers.body_impulse_lvlh, buffers.node_impulse_lvlh)
    return strongest
