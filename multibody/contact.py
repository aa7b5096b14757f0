"""Node-to-surface contact: Hertz normal force with Hunt-Crossley damping, regularized friction.

Pure functions on floats and arrays (SI units), compiled with numba so the coupled
force kernel (:mod:`multibody.kernel`) can call them per node and per sub-step.

The normal law is Cuadrat-Grzybowski & Gill 2024, eq. (6):

.. math:: F_n = k_n \\delta^n + d_n \\delta^n \\dot\\delta ,\\qquad d_n = \\tfrac{3}{2} \\alpha k_n

with the Hunt-Crossley damping written through the factor :math:`\\alpha` (s/m)
(Hunt & Crossley 1975; Gilardi & Sharf 2002, eq. 23), so that the restitution
coefficient at impact speed :math:`v_0` is about :math:`1 - \\tfrac{2}{3}\\alpha v_0`.
The friction law is Hollar's regularized Coulomb model, eq. (7) of the same paper.

Exudyn's own ``GeneralContact`` is a linear penalty; this module is how the Hertz
exponent enters the model: the compiled kernel evaluates these functions for every
node inside a body's bounding box and returns the forces through an Exudyn
``ObjectGenericODE2`` (see ``docs/model.md``).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from multibody.jit_cache import WITH_REFCOUNTS


@njit(cache=True, inline="always")
def hertz_hunt_crossley_normal_force(penetration, penetration_rate, stiffness, exponent, damping):
    """Normal contact force magnitude (N), never adhesive.

    Parameters
    ----------
    penetration : float
        Penetration depth :math:`\\delta` (m); no force when <= 0.
    penetration_rate : float
        :math:`\\dot\\delta` (m/s), positive while approaching.
    stiffness : float
        :math:`k_n` (N/m^n).
    exponent : float
        :math:`n` (-), 1.5 for Hertz sphere-plane contact.
    damping : float
        :math:`d_n = 1.5\\,\\alpha\\,k_n` (N s/m^(n+1)).
    """
    if penetration <= 0.0:
        return 0.0
    dn = _power(penetration, exponent)
    force = stiffness * dn + damping * dn * penetration_rate
    return force if force > 0.0 else 0.0


@njit(cache=True, inline="always")
def _power(base, exponent):
    """base ** exponent, with the Hertz exponent 1.5 as a square root (pow is the hot spot)."""
    if exponent == 1.5:
        return base * math.sqrt(base)
    return base ** exponent


@njit(cache=True, inline="always")
def hollar_friction_coefficient(slip_speed, mu_static, mu_kinetic, transition_speed):
    """Friction coefficient (-) at tangential slip speed (m/s); eq. (7) of the seed paper.

    Rises linearly from 0 to :math:`\\mu_s` below the transition speed :math:`V_{t,0}`
    (the regularization that replaces stiction) and decays to :math:`\\mu_k` above it.

    Parameters
    ----------
    slip_speed : float
        Tangential slip speed (m/s), >= 0.
    mu_static, mu_kinetic : float
        Static and kinetic coefficients (-).
    transition_speed : float
        :math:`V_{t,0}` (m/s), > 0.
    """
    return hollar_friction_of_ratio(slip_speed / transition_speed, mu_static, mu_kinetic)


@njit(cache=True, inline="always")
def hollar_friction_of_ratio(ratio, mu_static, mu_kinetic):
    """Friction coefficient (-) of :func:`hollar_friction_coefficient` at the slip speed's ratio to the
    transition speed (-), the one place the law's shape is written.

    Parameters
    ----------
    ratio : float
        Slip speed / :math:`V_{t,0}` (-), >= 0.
    mu_static, mu_kinetic : float
        Static and kinetic coefficients (-).
    """
    mu = mu_kinetic + 2.0 * (mu_static - mu_kinetic) / (1.0 + ratio * ratio)
    if ratio < 1.0:
        return ratio * mu
    return mu


@njit(cache=True, inline="always")
def hollar_friction_coefficient_inverse(slip_speed, mu_static, mu_kinetic, inverse_transition_speed):
    """:func:`hollar_friction_coefficient` with 1 / transition speed (s/m) given: a product instead of a
    division, for the loops that evaluate the law many times per contact (the sub-cycle, the implicit
    friction solve); equal to it to round-off.

    Parameters
    ----------
    slip_speed : float
        Tangential slip speed (m/s), >= 0.
    mu_static, mu_kinetic : float
        Static and kinetic coefficients (-).
    inverse_transition_speed : float
        :math:`1 / V_{t,0}` (s/m).
    """
    return hollar_friction_of_ratio(slip_speed * inverse_transition_speed, mu_static, mu_kinetic)


@njit(cache=True, inline="always")
def hollar_friction_coefficient_and_slope(slip_speed, mu_static, mu_kinetic, transition_speed):
    """:func:`hollar_friction_coefficient` (-) and its derivative with respect to the slip speed (s/m),
    for Newton iterations on friction laws; the slope is one-sided (from above) at the transition.

    Parameters
    ----------
    slip_speed : float
        Tangential slip speed (m/s), >= 0.
    mu_static, mu_kinetic : float
        Static and kinetic coefficients (-).
    transition_speed : float
        Hollar's transition speed (m/s), > 0.
    """
    ratio = slip_speed / transition_speed
    denominator = 1.0 + ratio * ratio
    mu = mu_kinetic + 2.0 * (mu_static - mu_kinetic) / denominator
    mu_slope = -4.0 * (mu_static - mu_kinetic) * ratio / (denominator * denominator)  # d mu / d ratio
    if ratio < 1.0:
        return ratio * mu, (mu + ratio * mu_slope) / transition_speed
    return mu, mu_slope / transition_speed


@njit(cache=True, inline="always")
def _dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@njit(cache=True)
def closest_point_on_triangle(px, py, pz, tri):
    """Closest point to ``p`` on triangle ``tri`` ((3, 3) corners), same frame (m); returns a tuple.

    Region tests of Ericson, *Real-Time Collision Detection* (2005), section 5.1.5, in scalar
    arithmetic (numba would send small-array products to BLAS).

    Parameters
    ----------
    px, py, pz : float
        The point (m), in the triangle's frame (a body frame in the kernel).
    tri : (3, 3) float
        The triangle's corners (m), one per row, same frame.
    """
    ax, ay, az = tri[0, 0], tri[0, 1], tri[0, 2]
    abx, aby, abz = tri[1, 0] - ax, tri[1, 1] - ay, tri[1, 2] - az
    acx, acy, acz = tri[2, 0] - ax, tri[2, 1] - ay, tri[2, 2] - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = _dot(abx, aby, abz, apx, apy, apz)
    d2 = _dot(acx, acy, acz, apx, apy, apz)
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az
    bpx, bpy, bpz = px - tri[1, 0], py - tri[1, 1], pz - tri[1, 2]
    d3 = _dot(abx, aby, abz, bpx, bpy, bpz)
    d4 = _dot(acx, acy, acz, bpx, bpy, bpz)
    if d3 >= 0.0 and d4 <= d3:
        return tri[1, 0], tri[1, 1], tri[1, 2]
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        t = d1 / (d1 - d3)
        return ax + t * abx, ay + t * aby, az + t * abz
    cpx, cpy, cpz = px - tri[2, 0], py - tri[2, 1], pz - tri[2, 2]
    d5 = _dot(abx, aby, abz, cpx, cpy, cpz)
    d6 = _dot(acx, acy, acz, cpx, cpy, cpz)
    if d6 >= 0.0 and d5 <= d6:
        return tri[2, 0], tri[2, 1], tri[2, 2]
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        t = d2 / (d2 - d6)
        return ax + t * acx, ay + t * acy, az + t * acz
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return (tri[1, 0] + t * (tri[2, 0] - tri[1, 0]), tri[1, 1] + t * (tri[2, 1] - tri[1, 1]),
                tri[1, 2] + t * (tri[2, 2] - tri[1, 2]))
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    return ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w


@njit(cache=True)
def signed_distance_to_mesh(px, py, pz, vertices, normals, first, last):
    """Signed distance (m) and outward normal of point ``p`` to a closed convex triangle shape.

    Parameters
    ----------
    px, py, pz : float
        Query point, body frame (m).
    vertices : (T, 3, 3) float
        Triangle corners, body frame (m).
    normals : (T, 3) float
        Outward unit normals, body frame.
    first, last : int
        Triangle index range of this shape.

    Returns
    -------
    distance : float
        Distance to the closest surface point, negative inside (m).
    nx, ny, nz : float
        Unit vector from the surface to the point (the face normal where the point is inside).
    """
    best = 1e300
    best_k = first
    cx = cy = cz = 0.0
    for k in range(first, last):
        qx, qy, qz = closest_point_on_triangle(px, py, pz, vertices[k])
        d2 = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
        if d2 < best:
            best = d2
            best_k = k
            cx, cy, cz = qx, qy, qz
    distance = math.sqrt(best)
    ox, oy, oz = px - cx, py - cy, pz - cz
    fx, fy, fz = normals[best_k, 0], normals[best_k, 1], normals[best_k, 2]
    if _dot(ox, oy, oz, fx, fy, fz) < 0.0:
        return -distance, fx, fy, fz
    if distance > 1e-12:
        return distance, ox / distance, oy / distance, oz / distance
    return 0.0, fx, fy, fz


@njit(cache=True, inline="always")
def _free_flight_substeps(delta, relative_velocities, normals, recoil, n_contacts, ux, uy, uz, ax, ay, az, t, dt,
                          remaining):
    """Whole sub-steps (at most ``remaining``) before any of the node's contacts can touch.

    Each gap evolves as delta(tau) = delta + rate tau + a tau^2 / 2 while no force acts
    (rate and a: penetration rate and acceleration under the constant non-contact force).
    Zero when a contact is touching now.
    """
    earliest = remaining * dt
    for c in range(n_contacts):
        if delta[c] >= 0.0:
            return 0
        nx, ny, nz = normals[c, 0], normals[c, 1], normals[c, 2]
        rate = -((relative_velocities[c, 0] + ux + ax * t - recoil[c, 0]) * nx
                 + (relative_velocities[c, 1] + uy + ay * t - recoil[c, 1]) * ny
                 + (relative_velocities[c, 2] + uz + az * t - recoil[c, 2]) * nz)
        accel = -(ax * nx + ay * ny + az * nz)
        # earliest tau > 0 with delta + rate tau + accel tau^2 / 2 = 0; the roots in the
        # cancellation-free form (q / (accel/2) and delta / q), as accel is often tiny
        disc = rate * rate - 2.0 * accel * delta[c]
        if disc < 0.0:
            continue
        q = -0.5 * (rate + math.copysign(math.sqrt(disc), rate))
        touch = np.inf
        if q != 0.0:
            root = delta[c] / q
            if root > 0.0:
                touch = root
            if accel != 0.0:
                root = q / (0.5 * accel)
                if 0.0 < root < touch:
                    touch = root
        earliest = min(earliest, touch)
    return min(remaining, int(earliest / dt))


@njit(cache=True, **WITH_REFCOUNTS)  # allocates; called from a NO_REFCOUNTS kernel (jit_cache)
def contact_over_step(penetrations, relative_velocities, normals, external_force, node_mass, body_masses, step,
                      n_substeps, stiffness, exponent, damping, mu_static, mu_kinetic, transition_speed,
                      impulses, delta, recoil, forces):
    """A node's contacts with one or more body surfaces over one integrator step, sub-cycled in time.

    The node's motion is integrated over ``step`` with ``n_substeps`` symplectic-Euler
    sub-steps under all its contacts at once, holding each contact normal and the node's
    non-contact force (threads, relative-motion terms) constant; the motion that constant
    force causes is added in closed form, so only the contact part carries the sub-step
    error and, with one sub-step, the result is the plain force evaluation. Each body
    recoils with its effective mass at the contact point, so a bullet striking a light dish
    exchanges the momentum of the two-body collision, and a node pinched between two bodies
    feels both. This resolves node impacts whose Hertz contact is shorter than the step
    (about 0.15 ms for a 7.7 g node at 20 m/s against the seed paper's contact law).

    Parameters
    ----------
    penetrations : (K,) float
        :math:`\\delta` of each contact at the start of the step (m); negative for a gap.
    relative_velocities : (K, 3) float
        Node velocity minus the body's surface velocity at the node (m/s), global frame,
        at the start of the step.
    normals : (K, 3) float
        Unit normals from each body to the node, global frame.
    external_force : (3,) float
        Non-contact force on the node (N), global frame.
    node_mass : float
        (kg).
    body_masses : (K,) float
        Effective mass of each body at its contact point along its normal (kg),
        :math:`(1/m + (r\\times n)^T J^{-1} (r\\times n))^{-1}`.
    step : float
        Integrator step (s).
    n_substeps : int
        Number of sub-steps; 1 is the plain force evaluation.
    impulses : (>=K, 3) float
        Output: contact impulse of each contact on the node over the step (N s), global frame.
    delta, recoil, forces : (>=K,), (>=K, 3), (>=K, 3) float
        Work space.

    Returns
    -------
    mean_x, mean_y, mean_z : float
        Node velocity change caused by contact, averaged over the step (m/s).
    end_x, end_y, end_z : float
        Node velocity change caused by contact at the end of the step (m/s).
    dissipated : float
        Energy removed by contact damping and friction over the step (J).
    """
    n_contacts = penetrations.shape[0]
    dt = step / n_substeps
    # divisions by the masses, the sub-step and the transition speed as products with reciprocals formed
    # once per call (the sub-step's chain is long; a division is 4-5 times a product's latency)
    inverse_dt = 1.0 / dt
    inverse_node_mass = 1.0 / node_mass
    inverse_transition_speed = 1.0 / transition_speed
    inverse_body_mass = np.empty(n_contacts)
    reduced_mass = np.empty(n_contacts)
    for c in range(n_contacts):
        delta[c] = penetrations[c]
        inverse_body_mass[c] = 1.0 / body_masses[c]
        reduced_mass[c] = node_mass * body_masses[c] / (node_mass + body_masses[c])
        for k in range(3):
            recoil[c, k] = 0.0  # body surface velocity change at the contact
            impulses[c, k] = 0.0
    ax = external_force[0] * inverse_node_mass
    ay = external_force[1] * inverse_node_mass
    az = external_force[2] * inverse_node_mass
    ux = uy = uz = 0.0  # node velocity change by contact
    sx = sy = sz = 0.0  # its time integral (displacement change)
    dissipated = 0.0
    j = 0
    while j < n_substeps:
        t = j * dt
        free = _free_flight_substeps(delta, relative_velocities, normals, recoil, n_contacts, ux, uy, uz,
                                     ax, ay, az, t, dt, n_substeps - j)
        if free > 0:
            # No contact can touch within the next ``free`` sub-steps: advance them in closed
            # form (exactly what the sub-steps would compute, as all contact forces are zero).
            t1 = t + free * dt
            for c in range(n_contacts):
                delta[c] -= (free * dt * ((relative_velocities[c, 0] + ux - recoil[c, 0]) * normals[c, 0]
                                          + (relative_velocities[c, 1] + uy - recoil[c, 1]) * normals[c, 1]
                                          + (relative_velocities[c, 2] + uz - recoil[c, 2]) * normals[c, 2])
                             + 0.5 * (t1 * t1 - t * t) * (ax * normals[c, 0] + ay * normals[c, 1] + az * normals[c, 2]))
            sx += free * dt * ux
            sy += free * dt * uy
            sz += free * dt * uz
            j += free
            continue
        j += 1
        for c in range(n_contacts):
            nx, ny, nz = normals[c, 0], normals[c, 1], normals[c, 2]
            wx = relative_velocities[c, 0] + ux + ax * t - recoil[c, 0]
            wy = relative_velocities[c, 1] + uy + ay * t - recoil[c, 1]
            wz = relative_velocities[c, 2] + uz + az * t - recoil[c, 2]
            rate = -_dot(wx, wy, wz, nx, ny, nz)
            # hertz_hunt_crossley_normal_force, with the power kept for the dissipation below
            fn = 0.0
            elastic = 0.0
            if delta[c] > 0.0:
                dn = _power(delta[c], exponent)
                elastic = stiffness * dn
                fn = max(elastic + damping * dn * rate, 0.0)
            gx, gy, gz = wx + rate * nx, wy + rate * ny, wz + rate * nz  # slip velocity
            speed = math.sqrt(gx * gx + gy * gy + gz * gz)
            fx, fy, fz = fn * nx, fn * ny, fn * nz
            if fn > 0.0 and speed > 0.0:
                mu = hollar_friction_coefficient_inverse(speed, mu_static, mu_kinetic, inverse_transition_speed)
                # Friction may stop the slip within a sub-step but never reverse it.
                magnitude = min(mu * fn, reduced_mass[c] * speed * inverse_dt)
                along = magnitude / speed
                fx -= along * gx
                fy -= along * gy
                fz -= along * gz
                dissipated += magnitude * speed * dt
            if delta[c] > 0.0:
                # Work of the non-elastic part: damping, or the stored energy lost when a
                # fast separation clips the force to zero (no adhesion).
                dissipated += (fn - elastic) * rate * dt
            forces[c, 0] = fx
            forces[c, 1] = fy
            forces[c, 2] = fz
        for c in range(n_contacts):
            ux += dt * forces[c, 0] * inverse_node_mass
            uy += dt * forces[c, 1] * inverse_node_mass
            uz += dt * forces[c, 2] * inverse_node_mass
            for k in range(3):
                recoil[c, k] -= dt * forces[c, k] * inverse_body_mass[c]
                impulses[c, k] += dt * forces[c, k]
        # The constant external force moves the node by a (t1^2 - t0^2) / 2 over the sub-step.
        tm = t + 0.5 * dt
        for c in range(n_contacts):
            wn = ((relative_velocities[c, 0] + ux + ax * tm - recoil[c, 0]) * normals[c, 0]
                  + (relative_velocities[c, 1] + uy + ay * tm - recoil[c, 1]) * normals[c, 1]
                  + (relative_velocities[c, 2] + uz + az * tm - recoil[c, 2]) * normals[c, 2])
            delta[c] -= dt * wn
        sx += dt * ux
        sy += dt * uy
        sz += dt * uz
    return sx / step, sy / step, sz / step, ux, uy, uz, dissipated


@njit(cache=True)
def hertz_elastic_energy(penetration, stiffness, exponent):
    """Elastic energy stored in a Hertz contact (J): :math:`k\\delta^{n+1}/(n+1)`, zero without contact.

    Parameters
    ----------
    penetration : float
        :math:`\\delta` (m); <= 0 for a gap.
    stiffness : float
        :math:`k` (N/m^n).
    exponent : float
        :math:`n` (-), 1.5 for Hertz.
    """
    if penetration <= 0.0:
        return 0.0
    return stiffness * _power(penetration, exponent) * penetration / (exponent + 1.0)
