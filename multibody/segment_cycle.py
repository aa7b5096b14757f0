"""A thread's contact with one box over one step, sub-cycled with its deepest point followed inside the step.

Until 2026-11-27 (helper thread12) the thread contact (:mod:`multibody.contact_segment`) picked the segment's
deepest point once a step and integrated a particle at that point along a normal held over the step. A thread
rocking on a plate's two edges, or turning round an edge, changes its deepest point inside the step: the point
held was then shallower than the deepest one, the other edge sank unresisted for the rest of the step, and the
next step's contact started deeper than any force had paid for. The stored energy only jumped up (first order
in the step: +12 % of a 20 m/s strike's launch energy at 1e-4 s, docs/model.md "Contact").

Here the two nodes themselves are the sub-cycle's state (positions and velocities relative to the body, body
frame, the body's attitude held over the step as in the node contact), and at every sub-step the contact is
evaluated again from them: the deepest point t* (:func:`multibody.segment_box.segment_box_deepest`, the middle
of the tied part when points tie), its normal perpendicular to the thread, the excess q over the deeper node's
own penetration (the no-double-count coordinate of :mod:`multibody.contact_segment`) and the split (1 - s, s)
over the nodes. So the contact's potential k q^(n+1)/(n+1), a maximum over the segment's points, is followed as
the maximum moves, and a switch of the deepest point costs at most one sub-step's error instead of one step's.

The nodes' non-contact accelerations are held over the step (as every contact of the kernel holds them); each
node's own contact against the same box is included in the nodes' motion here, as a prediction only (its
impulse is applied by the node contact, :mod:`multibody.contact_kernel`), so that the excess q over a node in
its own 0.15 ms impact follows that node's rebound instead of a free flight into the face. The body recoils
with its mass and inertia (velocity and spin changes, body frame) at the nodes, where its reactions act.

Returns each node's mean and end velocity change by the thread's contact over the step (the kick and the
remainder carried to the next step, as the node contact), the energy the contact dissipated (Hunt-Crossley
damping, friction, and stored energy lost when a fast separation clips the force), and the contact's elastic
energy at the end of the sub-cycle (its work is then booked per contact: docs/model.md, "Contact").
Frames: the box's body frame (origin at the body's CoM); SI units.
"""
from __future__ import annotations

import math

from numba import njit

from multibody.broad_phase import box_signed_distance
from multibody.contact import _power, hollar_friction_coefficient_inverse
from multibody.segment_box import TIE_DISTANCE, segment_box_deepest, segment_box_normal, segment_box_sublevel


@njit(cache=True)
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
    t_deepest, distance = segment_box_deepest(pa, d, lo, hi, work)
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
            t_low, t_high = segment_box_sublevel(pa, d, lo, hi, distance + TIE_DISTANCE, work)
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


@njit(cache=True)
def thread_contact_over_step(pa, pc, va, vc, aa, ac, mass_a, mass_c, radius_a, radius_c, box_min, box_max, s,
                             body_mass, inverse_inertia_body, b, law, step, n_substeps, own_a, own_c, work, out):
    """Thread (nodes a, c) against box ``s`` of body ``b`` over one step, the contact re-evaluated at every
    sub-step from the nodes' state (module doc).

    Parameters
    ----------
    pa, pc : tuple of 3 float
        The nodes at the evaluation, body frame (m).
    va, vc : tuple of 3 float
        Their velocities relative to the body's material point at each (m/s), body frame, at the evaluation.
    aa, ac : tuple of 3 float
        Their non-contact accelerations (m/s^2), body frame, held over the step.
    mass_a, mass_c, radius_a, radius_c : float
        The nodes' masses (kg) and contact radii (m).
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
    own_a, own_c : bool
        The node's own contact with this box is integrated here and its impulse returned with the thread's (the
        node contact skips it this step); otherwise it only moves the node here (a prediction).
    work : (MAX_BREAKPOINTS,) float
        Work space.
    out : (4, 3) float
        Output, body frame (m/s): node a's mean and end velocity change by the thread's contact (and its own when
        owned), node c's.

    Returns
    -------
    dissipated : float
        Energy the thread's contact (and the owned node contacts) dissipated over the step (J).
    end_energy : float
        Its elastic energy at the end of the sub-cycle (J).
    touched : int
        1 if the thread's contact acted in any sub-step.
    """
    k_contact, exponent, damping = law.stiffness, law.exponent, law.damping
    mu_s, mu_k = law.mu_static, law.mu_kinetic
    inverse_transition_speed = 1.0 / law.transition_speed
    dt = step / n_substeps
    inv_a, inv_c, inv_body = 1.0 / mass_a, 1.0 / mass_c, 1.0 / body_mass
    j_inv = inverse_inertia_body
    xa0, xa1, xa2 = pa
    xc0, xc1, xc2 = pc
    ua0 = ua1 = ua2 = uc0 = uc1 = uc2 = 0.0     # the thread contact's velocity change of each node
    sa0 = sa1 = sa2 = sc0 = sc1 = sc2 = 0.0     # its time integral
    pa0 = pa1 = pa2 = pc0 = pc1 = pc2 = 0.0     # the nodes' own contacts' velocity change (prediction only)
    bv0 = bv1 = bv2 = bw0 = bw1 = bw2 = 0.0     # the body's velocity and spin change (body frame)
    dissipated = 0.0
    touched = 0
    excess = -math.inf
    for j in range(n_substeps):
        t = j * dt
        # relative velocities at the sub-step: start + non-contact + contact changes - the body's recoil there
        wa = (va[0] + aa[0] * t + ua0 + pa0 - (bv0 + bw1 * xa2 - bw2 * xa1),
              va[1] + aa[1] * t + ua1 + pa1 - (bv1 + bw2 * xa0 - bw0 * xa2),
              va[2] + aa[2] * t + ua2 + pa2 - (bv2 + bw0 * xa1 - bw1 * xa0))
        wc = (vc[0] + ac[0] * t + uc0 + pc0 - (bv0 + bw1 * xc2 - bw2 * xc1),
              vc[1] + ac[1] * t + uc1 + pc1 - (bv1 + bw2 * xc0 - bw0 * xc2),
              vc[2] + ac[2] * t + uc2 + pc2 - (bv2 + bw0 * xc1 - bw1 * xc0))
        geometry = thread_contact_geometry((xa0, xa1, xa2), (xc0, xc1, xc2), box_min, box_max, s, radius_a,
                                           radius_c, work)
        excess, depth, split, t_deepest, end, depth_a, depth_c, n_a, n_c = geometry
        fa0 = fa1 = fa2 = fc0 = fc1 = fc2 = 0.0      # the thread contact's forces on the nodes
        if excess > 0.0:
            touched = 1
            wp, wq = 1.0 - split, split
            w = (wp * wa[0] + wq * wc[0], wp * wa[1] + wq * wc[1], wp * wa[2] + wq * wc[2])
            d = (xc0 - xa0, xc1 - xa1, xc2 - xa2)
            lo = (box_min[s, 0], box_min[s, 1], box_min[s, 2])
            hi = (box_max[s, 0], box_max[s, 1], box_max[s, 2])
            nx, ny, nz = segment_box_normal(xa0 + t_deepest * d[0], xa1 + t_deepest * d[1], xa2 + t_deepest * d[2],
                                            d[0], d[1], d[2], lo, hi, w[0], w[1], w[2])
            rate = -(w[0] * nx + w[1] * ny + w[2] * nz)          # q's rate: the point's closing speed ...
            inverse_point_mass = wp * wp * inv_a + wq * wq * inv_c
            me = (0.0, 0.0, 0.0)
            if end == 0:
                me = n_a
                rate += wa[0] * me[0] + wa[1] * me[1] + wa[2] * me[2]   # ... less node e's own
            elif end == 1:
                me = n_c
                rate += wc[0] * me[0] + wc[1] * me[1] + wc[2] * me[2]
            dn = _power(excess, exponent)
            elastic = k_contact * dn
            fn = max(elastic + damping * dn * rate, 0.0)
            dissipated += (fn - elastic) * rate * dt
            normal_speed = w[0] * nx + w[1] * ny + w[2] * nz
            gx, gy, gz = w[0] - normal_speed * nx, w[1] - normal_speed * ny, w[2] - normal_speed * nz
            fx, fy, fz = fn * nx, fn * ny, fn * nz
            slip = math.sqrt(gx * gx + gy * gy + gz * gz)
            if fn > 0.0 and slip > 0.0:
                mu = hollar_friction_coefficient_inverse(slip, mu_s, mu_k, inverse_transition_speed)
                reduced = 1.0 / (inverse_point_mass + inv_body)
                magnitude = min(mu * fn, reduced * slip / dt)   # may stop the slip within a sub-step, not reverse it
                along = magnitude / slip
                fx -= along * gx
                fy -= along * gy
                fz -= along * gz
                dissipated += magnitude * slip * dt
            fa0, fa1, fa2 = wp * fx, wp * fy, wp * fz
            fc0, fc1, fc2 = wq * fx, wq * fy, wq * fz
            # node e hands its load up to q to the point: -(F . n) n_e on it (the gradient of k q^(n+1)/(n+1))
            if end == 0:
                fa0, fa1, fa2 = fa0 - fn * me[0], fa1 - fn * me[1], fa2 - fn * me[2]
            elif end == 1:
                fc0, fc1, fc2 = fc0 - fn * me[0], fc1 - fn * me[1], fc2 - fn * me[2]
        # the nodes' own contacts with this box, for their motion only (module doc): Hunt-Crossley, no friction
        ga0, ga1, ga2, lost_a = _node_contact_force(depth_a, wa, n_a, mass_a, inv_body, k_contact, exponent, damping,
                                                    mu_s, mu_k, inverse_transition_speed, dt, own_a)
        gc0, gc1, gc2, lost_c = _node_contact_force(depth_c, wc, n_c, mass_c, inv_body, k_contact, exponent, damping,
                                                    mu_s, mu_k, inverse_transition_speed, dt, own_c)
        dissipated += lost_a + lost_c
        # velocity updates (symplectic Euler, as the node contact's sub-cycle)
        ua0 += dt * fa0 * inv_a
        ua1 += dt * fa1 * inv_a
        ua2 += dt * fa2 * inv_a
        uc0 += dt * fc0 * inv_c
        uc1 += dt * fc1 * inv_c
        uc2 += dt * fc2 * inv_c
        ua0, ua1, ua2, pa0, pa1, pa2 = _own_contact_kick(ua0, ua1, ua2, pa0, pa1, pa2, ga0, ga1, ga2, inv_a, dt, own_a)
        uc0, uc1, uc2, pc0, pc1, pc2 = _own_contact_kick(uc0, uc1, uc2, pc0, pc1, pc2, gc0, gc1, gc2, inv_c, dt, own_c)
        # the body's recoil: every reaction acts at the node it came from
        ta0, ta1, ta2 = fa0 + ga0, fa1 + ga1, fa2 + ga2
        tc0, tc1, tc2 = fc0 + gc0, fc1 + gc1, fc2 + gc2
        bv0 -= dt * (ta0 + tc0) * inv_body
        bv1 -= dt * (ta1 + tc1) * inv_body
        bv2 -= dt * (ta2 + tc2) * inv_body
        ma = _cross((xa0, xa1, xa2), (ta0, ta1, ta2))
        mc = _cross((xc0, xc1, xc2), (tc0, tc1, tc2))
        l0, l1, l2 = ma[0] + mc[0], ma[1] + mc[1], ma[2] + mc[2]
        bw0 -= dt * (j_inv[b, 0, 0] * l0 + j_inv[b, 0, 1] * l1 + j_inv[b, 0, 2] * l2)
        bw1 -= dt * (j_inv[b, 1, 0] * l0 + j_inv[b, 1, 1] * l1 + j_inv[b, 1, 2] * l2)
        bw2 -= dt * (j_inv[b, 2, 0] * l0 + j_inv[b, 2, 1] * l1 + j_inv[b, 2, 2] * l2)
        # positions: the non-contact acceleration at mid-sub-step, the changes after the kick
        tm = t + 0.5 * dt
        xa0 += dt * (va[0] + aa[0] * tm + ua0 + pa0 - (bv0 + bw1 * xa2 - bw2 * xa1))
        xa1 += dt * (va[1] + aa[1] * tm + ua1 + pa1 - (bv1 + bw2 * xa0 - bw0 * xa2))
        xa2 += dt * (va[2] + aa[2] * tm + ua2 + pa2 - (bv2 + bw0 * xa1 - bw1 * xa0))
        xc0 += dt * (vc[0] + ac[0] * tm + uc0 + pc0 - (bv0 + bw1 * xc2 - bw2 * xc1))
        xc1 += dt * (vc[1] + ac[1] * tm + uc1 + pc1 - (bv1 + bw2 * xc0 - bw0 * xc2))
        xc2 += dt * (vc[2] + ac[2] * tm + uc2 + pc2 - (bv2 + bw0 * xc1 - bw1 * xc0))
        sa0 += dt * ua0
        sa1 += dt * ua1
        sa2 += dt * ua2
        sc0 += dt * uc0
        sc1 += dt * uc1
        sc2 += dt * uc2
    out[0, 0], out[0, 1], out[0, 2] = sa0 / step, sa1 / step, sa2 / step
    out[1, 0], out[1, 1], out[1, 2] = ua0, ua1, ua2
    out[2, 0], out[2, 1], out[2, 2] = sc0 / step, sc1 / step, sc2 / step
    out[3, 0], out[3, 1], out[3, 2] = uc0, uc1, uc2
    end_geometry = thread_contact_geometry((xa0, xa1, xa2), (xc0, xc1, xc2), box_min, box_max, s, radius_a,
                                           radius_c, work)
    end_excess = end_geometry[0]
    end_energy = k_contact * _power(end_excess, exponent) * end_excess / (exponent + 1.0) if end_excess > 0.0 else 0.0
    return dissipated, end_energy, touched
