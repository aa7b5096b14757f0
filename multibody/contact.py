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


@njit(cache=True)
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
    dn = penetration ** exponent
    force = stiffness * dn + damping * dn * penetration_rate
    return force if force > 0.0 else 0.0


@njit(cache=True)
def hollar_friction_coefficient(slip_speed, mu_static, mu_kinetic, transition_speed):
    """Friction coefficient (-) at tangential slip speed (m/s); eq. (7) of the seed paper.

    Rises linearly from 0 to :math:`\\mu_s` below the transition speed :math:`V_{t,0}`
    (the regularization that replaces stiction) and decays to :math:`\\mu_k` above it.
    """
    ratio = slip_speed / transition_speed
    mu = mu_kinetic + 2.0 * (mu_static - mu_kinetic) / (1.0 + ratio * ratio)
    if ratio < 1.0:
        return ratio * mu
    return mu


@njit(cache=True)
def closest_point_on_triangle(p, a, b, c):
    """Closest point to ``p`` on triangle ``(a, b, c)``; all (3,) arrays in one frame (m).

    Region tests of Ericson, *Real-Time Collision Detection* (2005), section 5.1.5.
    """
    ab = b - a
    ac = c - a
    ap = p - a
    d1 = ab @ ap
    d2 = ac @ ap
    if d1 <= 0.0 and d2 <= 0.0:
        return a.copy()
    bp = p - b
    d3 = ab @ bp
    d4 = ac @ bp
    if d3 >= 0.0 and d4 <= d3:
        return b.copy()
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return a + (d1 / (d1 - d3)) * ab
    cp = p - c
    d5 = ab @ cp
    d6 = ac @ cp
    if d6 >= 0.0 and d5 <= d6:
        return c.copy()
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return a + (d2 / (d2 - d6)) * ac
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return b + w * (c - b)
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    return a + ab * v + ac * w


@njit(cache=True)
def signed_distance_to_mesh(p_body, vertices, normals, first, last):
    """Signed distance (m) and outward normal of point ``p_body`` to a closed triangle mesh.

    Parameters
    ----------
    p_body : (3,) float
        Query point, body frame (m).
    vertices : (T, 3, 3) float
        Triangle corners, body frame (m).
    normals : (T, 3) float
        Outward unit normals, body frame.
    first, last : int
        Triangle index range of this body.

    Returns
    -------
    distance : float
        Distance to the closest surface point, negative inside the mesh (m).
    normal : (3,) float
        Unit vector from the surface to the point (outward where the point is inside).
    """
    best = 1e300
    best_k = first
    best_cp = np.zeros(3)
    for k in range(first, last):
        cp = closest_point_on_triangle(p_body, vertices[k, 0], vertices[k, 1], vertices[k, 2])
        d = p_body - cp
        d2 = d @ d
        if d2 < best:
            best = d2
            best_k = k
            best_cp = cp
    distance = math.sqrt(best)
    offset = p_body - best_cp
    if offset @ normals[best_k] < 0.0:
        # Inside: push out along the face normal of the nearest face.
        return -distance, normals[best_k].copy()
    if distance > 1e-12:
        return distance, offset / distance
    return 0.0, normals[best_k].copy()


@njit(cache=True)
def contact_over_step(penetration, relative_velocity, normal, external_force, node_mass, step, n_substeps,
                      stiffness, exponent, damping, mu_static, mu_kinetic, transition_speed):
    """Node motion relative to a body surface over one integrator step, sub-cycled in time.

    The node's velocity relative to the surface is integrated over ``step`` with
    ``n_substeps`` symplectic-Euler sub-steps, holding the body velocity, the contact
    normal and the node's non-contact force (threads, relative-motion terms) constant.
    This resolves node impacts whose Hertz contact is shorter than the step (about
    0.1 ms for a 7.7 g node at 20 m/s against the seed paper's contact law).

    Parameters
    ----------
    penetration : float
        :math:`\\delta` (m) at the start of the step; negative for a gap.
    relative_velocity : (3,) float
        Node velocity minus surface velocity at the node (m/s), global frame.
    normal : (3,) float
        Unit normal from the body to the node, global frame.
    external_force : (3,) float
        Non-contact force on the node (N), global frame.
    node_mass : float
        (kg).
    step : float
        Integrator step (s).
    n_substeps : int
        Number of sub-steps; 1 is the plain force evaluation.

    Returns
    -------
    impulse : (3,) float
        Contact impulse on the node over the step (N s), global frame.
    mean_velocity : (3,) float
        Relative velocity averaged over the step, i.e. relative displacement / step (m/s).
    end_velocity : (3,) float
        Relative velocity at the end of the step (m/s).
    dissipated : float
        Energy removed by contact damping and friction over the step (J).
    """
    dt = step / n_substeps
    delta = penetration
    w = relative_velocity.copy()
    impulse = np.zeros(3)
    displacement = np.zeros(3)
    dissipated = 0.0
    for _ in range(n_substeps):
        rate = -(w @ normal)
        fn = hertz_hunt_crossley_normal_force(delta, rate, stiffness, exponent, damping)
        slip = w + rate * normal
        speed = math.sqrt(slip @ slip)
        ft = np.zeros(3)
        if fn > 0.0 and speed > 0.0:
            mu = hollar_friction_coefficient(speed, mu_static, mu_kinetic, transition_speed)
            # Friction may stop the slip within a sub-step but never reverse it.
            magnitude = min(mu * fn, node_mass * speed / dt)
            ft = -magnitude / speed * slip
            dissipated += magnitude * speed * dt
        if delta > 0.0:
            # Work of the non-elastic part: damping, or the stored energy lost when a
            # fast separation clips the force to zero (no adhesion).
            dissipated += (fn - stiffness * delta ** exponent) * rate * dt
        contact = fn * normal + ft
        w += dt * (contact + external_force) / node_mass
        delta -= dt * (w @ normal)
        displacement += dt * w
        impulse += dt * contact
    return impulse, displacement / step, w, dissipated


def hertz_elastic_energy(penetration, stiffness, exponent):
    """Elastic energy stored in a Hertz contact (J): :math:`k\\delta^{n+1}/(n+1)`."""
    penetration = np.maximum(penetration, 0.0)
    return stiffness * penetration ** (exponent + 1.0) / (exponent + 1.0)
