"""Compiled core of the full-net towing model (Boonrath, Singh & Botta 2024, Sec. 2.1): the wrapped
net's nodes, sub-cycled inside one step of the chaser and the debris.

The net is light (2.7 kg on 229 nodes) and stiff (Kevlar threads, Hertz contact on the debris), the
bodies are heavy (1600 kg, 9000 kg) and slow. The bodies are Exudyn nodes stepped by VelocityVerlet
at the step H; inside the force evaluation of each step the net is advanced over the same interval
[t_n, t_n+1] by ``m`` symplectic-Euler sub-steps h = H/m, with the bodies moving as Verlet moves them
over that interval (CoM linear from q_n to q_n+1 at the half-step velocity, attitude along the
Lie-group geodesic R_n+1 exp(-(t_n+1 - s) omega_n+1/2)). Every impulse a node exchanges with a body
(contact, main tether) is summed with the opposite sign on that body; the step's mean force and
torque are the generalized force Verlet applies. Momentum exchange is therefore exact; the coupling
lags by H/2 (a first-order error in H measured by the step study, docs/towing.md).

Forces on a node: tension-only Kelvin-Voigt threads (:func:`multibody.net.add_thread_forces`, eq. 1
of the impact paper; the closing mechanism's threads are threads of the same list), two-body gravity
(eq. 1), Hertz / Hunt-Crossley contact with Hollar friction against the debris cylinder
(:func:`multibody.contact.contact_over_step`, one sub-step: the plain force evaluation of the impact
model's law) and, on the central node, the main tether (eq. 5a). Frame: Earth-centred inertial;
node positions are displacements from one reference point (m), ``_body`` vectors are in the debris
frame.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from control.attitude import desired_attitude, sliding_mode_torque
from control.thrust import thrust_command
from multibody.contact import contact_over_step
from multibody.kernel import _effective_mass_along_normal, rotation_matrix_from_rotation_vector
from multibody.net import add_thread_forces, tension_only_kelvin_voigt
from multibody.orbit import two_body_acceleration_xyz

#: Layout of the per-step accumulator ``acc`` (all inertial): debris force (3), debris torque about
#: its CoM (3), chaser force (3), chaser torque about its CoM (3), then scalars.
ACC_DEBRIS_F, ACC_DEBRIS_T, ACC_CHASER_F, ACC_CHASER_T = 0, 3, 6, 9
ACC_TENSION, ACC_CONTACTS, ACC_CONTACT_F, ACC_CLOSING, ACC_EXTERNAL, ACC_DISSIPATED, ACC_SIZE = 12, 13, 14, 15, 16, 19, 20
#: Diagnostics of one step (``diag``): MT mean tension, elongation, elongation rate, thrust, control
#: torque (3, chaser body), sliding variable (3), mean contacts, mean contact force, largest closing tension.
D_TENSION, D_ELONGATION, D_RATE, D_THRUST, D_TORQUE, D_SLIDING, D_CONTACTS, D_CONTACT_F, D_CLOSING, D_SIZE = (
    0, 1, 2, 3, 4, 7, 10, 11, 12, 13)
#: Cylinder geometry: radius (m), half length (m), axial centre z (m) in the debris frame.
CYL_RADIUS, CYL_HALF, CYL_Z = 0, 1, 2
#: Contact law: k_n (N/m^n), n, d_n, mu_s, mu_k, V_t0 (see multibody.assembly.ContactLaw).
C_K, C_EXP, C_D, C_MUS, C_MUK, C_VT = range(6)


@njit(cache=True, inline="always")
def cylinder_distance(px, py, pz, geometry):
    """Signed distance (m) from a point (debris frame, m) to a closed circular cylinder with axis
    z_body (``geometry``: radius, half length, axial centre) and the outward unit normal at the
    nearest surface point (debris frame); negative inside."""
    radius, half, zc = geometry[CYL_RADIUS], geometry[CYL_HALF], geometry[CYL_Z]
    rho = math.sqrt(px * px + py * py)
    ex, ey = (px / rho, py / rho) if rho > 1e-12 else (1.0, 0.0)
    dz = pz - zc
    sz = 1.0 if dz >= 0.0 else -1.0
    radial, axial = rho - radius, abs(dz) - half
    if radial > 0.0 and axial > 0.0:  # beyond the rim: nearest point on the edge circle
        d = math.sqrt(radial * radial + axial * axial)
        return d, radial * ex / d, radial * ey / d, axial * sz / d
    if radial >= axial:
        return radial, ex, ey, 0.0
    return axial, 0.0, 0.0, sz


@njit(cache=True, inline="always")
def _near(i, x, v, node_radius, com, rot, vel, omega, geometry, h):
    """Broad phase in scalars: node ``i``'s penetration into the debris cylinder (m, negative for a
    gap), its normal (debris frame), and whether it can touch within two sub-steps."""
    ax, ay, az = x[i, 0] - com[0], x[i, 1] - com[1], x[i, 2] - com[2]
    px = rot[0, 0] * ax + rot[1, 0] * ay + rot[2, 0] * az
    py = rot[0, 1] * ax + rot[1, 1] * ay + rot[2, 1] * az
    pz = rot[0, 2] * ax + rot[1, 2] * ay + rot[2, 2] * az
    distance, nbx, nby, nbz = cylinder_distance(px, py, pz, geometry)
    penetration = node_radius - distance
    speed = math.sqrt((v[i, 0] - vel[0]) ** 2 + (v[i, 1] - vel[1]) ** 2 + (v[i, 2] - vel[2]) ** 2)
    reach = speed + math.sqrt(omega[0] ** 2 + omega[1] ** 2 + omega[2] ** 2) * (abs(distance) + 10.0)
    return penetration, nbx, nby, nbz, penetration + 2.0 * h * reach >= 0.0


@njit(cache=True, inline="always")
def _node_contact(i, x, v, f, node_mass, penetration, nbx, nby, nbz, com, rot, vel, omega, mass, inverse_inertia, law,
                  h, work):
    """Contact of node ``i`` (``penetration`` (m) along the debris-frame normal ``nb``) with the debris
    over one sub-step (the impact model's law and friction, :func:`multibody.contact.contact_over_step`
    with one sub-step). Adds the contact force to ``f[i]`` and returns it (N, inertial) with the
    dissipated energy (J)."""
    ax, ay, az = x[i, 0] - com[0], x[i, 1] - com[1], x[i, 2] - com[2]
    pen, rel, normal, ext, masses = work[0:1], work[1:4].reshape(1, 3), work[4:7].reshape(1, 3), work[7:10], work[10:11]
    pen[0] = penetration
    normal[0, 0] = rot[0, 0] * nbx + rot[0, 1] * nby + rot[0, 2] * nbz
    normal[0, 1] = rot[1, 0] * nbx + rot[1, 1] * nby + rot[1, 2] * nbz
    normal[0, 2] = rot[2, 0] * nbx + rot[2, 1] * nby + rot[2, 2] * nbz
    rel[0, 0] = v[i, 0] - vel[0] - (omega[1] * az - omega[2] * ay)
    rel[0, 1] = v[i, 1] - vel[1] - (omega[2] * ax - omega[0] * az)
    rel[0, 2] = v[i, 2] - vel[2] - (omega[0] * ay - omega[1] * ax)
    ext[0], ext[1], ext[2] = f[i, 0], f[i, 1], f[i, 2]
    masses[0] = _effective_mass_along_normal(rot, inverse_inertia, mass, ax, ay, az,
                                             normal[0, 0], normal[0, 1], normal[0, 2])
    _, _, _, ux, uy, uz, dissipated = contact_over_step(
        work[0:1], rel, normal, ext, node_mass, masses, h, 1, law[C_K], law[C_EXP], law[C_D], law[C_MUS], law[C_MUK],
        law[C_VT], work[11:14].reshape(1, 3), work[14:15], work[15:18].reshape(1, 3), work[18:21].reshape(1, 3))
    fx, fy, fz = node_mass * ux / h, node_mass * uy / h, node_mass * uz / h
    f[i, 0] += fx
    f[i, 1] += fy
    f[i, 2] += fz
    return fx, fy, fz, dissipated


@njit(cache=True)
def net_forces(x, v, node_mass, node_radius, threads, rest, stiffness, damping, reference, mu, central, main_tether,
               a_point, a_velocity, com_c, com_d, rot_d, vel_d, omega_d, mass_d, inverse_inertia_d, geometry, law, h,
               f, acc, work):
    """Forces on every node (``f`` (n, 3), N) at positions ``x`` (displacements from ``reference``, m)
    and velocities ``v`` (m/s); the reactions on the bodies (force, torque about the CoM, inertial)
    are added to ``acc`` times ``h`` (impulses), with the main tether's tension, contact count, total
    contact force, largest closing-thread tension and the node gravity's impulse.

    ``main_tether`` = [k_MT, c_MT, l_MT0] joins node ``central`` to the chaser's attachment
    ``a_point`` (absolute, m) moving with ``a_velocity`` (m/s); chaser CoM ``com_c`` (absolute, m);
    the debris (CoM ``com_d``, relative to ``reference`` like the nodes, attitude
    ``rot_d``, velocity ``vel_d``, angular velocity ``omega_d`` inertial) is the cylinder ``geometry``.
    Returns the main tether's (tension, elongation, elongation rate).
    """
    f[:] = 0.0
    add_thread_forces(x, v, threads, rest, stiffness, damping, f)
    n = x.shape[0]
    for i in range(n):
        if mu == 0.0:
            break
        gx, gy, gz = two_body_acceleration_xyz(reference[0] + x[i, 0], reference[1] + x[i, 1], reference[2] + x[i, 2], mu)
        f[i, 0] += node_mass[i] * gx
        f[i, 1] += node_mass[i] * gy
        f[i, 2] += node_mass[i] * gz
        acc[ACC_EXTERNAL] += h * node_mass[i] * gx
        acc[ACC_EXTERNAL + 1] += h * node_mass[i] * gy
        acc[ACC_EXTERNAL + 2] += h * node_mass[i] * gz
    # main tether: node -> chaser attachment A
    dx = reference[0] + x[central, 0] - a_point[0]
    dy = reference[1] + x[central, 1] - a_point[1]
    dz = reference[2] + x[central, 2] - a_point[2]
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    ux, uy, uz = dx / length, dy / length, dz / length
    rate = ((v[central, 0] - a_velocity[0]) * ux + (v[central, 1] - a_velocity[1]) * uy
            + (v[central, 2] - a_velocity[2]) * uz)
    tension = tension_only_kelvin_voigt(length - main_tether[2], rate, main_tether[0], main_tether[1])
    f[central, 0] -= tension * ux
    f[central, 1] -= tension * uy
    f[central, 2] -= tension * uz
    rx, ry, rz = a_point[0] - com_c[0], a_point[1] - com_c[1], a_point[2] - com_c[2]
    _add_impulse(acc, ACC_CHASER_F, tension * ux * h, tension * uy * h, tension * uz * h, rx, ry, rz)
    acc[ACC_TENSION] += tension * h
    for t in range(threads.shape[0] - 12, threads.shape[0]):  # the closing loop is the last 12 threads
        a, b = threads[t, 0], threads[t, 1]
        stretch = math.sqrt((x[b, 0] - x[a, 0]) ** 2 + (x[b, 1] - x[a, 1]) ** 2 + (x[b, 2] - x[a, 2]) ** 2) - rest[t]
        acc[ACC_CLOSING] = max(acc[ACC_CLOSING], stiffness[t] * stretch)
    for i in range(n):
        penetration, nbx, nby, nbz, near = _near(i, x, v, node_radius[i], com_d, rot_d, vel_d, omega_d, geometry, h)
        if not near:
            continue
        fx, fy, fz, dissipated = _node_contact(i, x, v, f, node_mass[i], penetration, nbx, nby, nbz, com_d, rot_d, vel_d,
                                               omega_d, mass_d, inverse_inertia_d, law, h, work)
        if fx != 0.0 or fy != 0.0 or fz != 0.0:
            rx, ry, rz = x[i, 0] - com_d[0], x[i, 1] - com_d[1], x[i, 2] - com_d[2]
            _add_impulse(acc, ACC_DEBRIS_F, -fx * h, -fy * h, -fz * h, rx, ry, rz)
            acc[ACC_CONTACT_F] += math.sqrt(fx * fx + fy * fy + fz * fz) * h
        if penetration > 0.0:
            acc[ACC_CONTACTS] += h
        acc[ACC_DISSIPATED] += dissipated
    return tension, length - main_tether[2], rate


@njit(cache=True, inline="always")
def _add_impulse(acc, base, jx, jy, jz, rx, ry, rz):
    """Impulse (jx, jy, jz) (N s) at arm r (m) from a body's CoM: into ``acc[base:base+6]``."""
    acc[base] += jx
    acc[base + 1] += jy
    acc[base + 2] += jz
    acc[base + 3] += ry * jz - rz * jy
    acc[base + 4] += rz * jx - rx * jz
    acc[base + 5] += rx * jy - ry * jx


@njit(cache=True)
def _geodesic(rot_end, omega_body, back):
    """Attitude ``back`` seconds before the step's end on the Lie-group path of Verlet's drift."""
    inc = np.empty(3)
    inc[0], inc[1], inc[2] = -back * omega_body[0], -back * omega_body[1], -back * omega_body[2]
    return rot_end @ rotation_matrix_from_rotation_vector(inc)


@njit(cache=True)
def advance_net(x, v, t_start, t_end, n_sub, node_mass, node_radius, threads, rest, stiffness, damping, reference, mu,
                central, main_tether, attach_chaser_body, bodies, mass_d, inverse_inertia_d, geometry, law, f, acc,
                work):
    """Advance the net from ``t_start`` to ``t_end`` (s) by ``n_sub`` symplectic-Euler sub-steps while
    chaser and debris move as Verlet moves them over the step. ``bodies`` (2, 12): per body (chaser,
    debris) the CoM at ``t_end`` (absolute, m), rotation vector body->inertial at ``t_end`` (rad),
    half-step CoM velocity (m/s) and angular velocity (rad/s, body frame). ``acc`` (ACC_SIZE) is
    zeroed and receives the impulses over the step (:func:`net_forces`). Returns the main tether's
    (tension, elongation, rate) at the last sub-step."""
    acc[:] = 0.0
    h = (t_end - t_start) / n_sub
    rot_c_end = rotation_matrix_from_rotation_vector(bodies[0, 3:6])
    rot_d_end = rotation_matrix_from_rotation_vector(bodies[1, 3:6])
    out = (0.0, 0.0, 0.0)
    com_c, com_d, a_point, a_velocity = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for k in range(n_sub):
        back = t_end - (t_start + k * h)
        rot_c = _geodesic(rot_c_end, bodies[0, 9:12], back)
        rot_d = _geodesic(rot_d_end, bodies[1, 9:12], back)
        arm = rot_c @ attach_chaser_body
        spin = rot_c @ np.cross(bodies[0, 9:12], attach_chaser_body)
        for a in range(3):
            com_c[a] = bodies[0, a] - back * bodies[0, 6 + a]
            com_d[a] = bodies[1, a] - back * bodies[1, 6 + a]
            a_point[a] = com_c[a] + arm[a]
            a_velocity[a] = bodies[0, 6 + a] + spin[a]
        omega_d = rot_d @ bodies[1, 9:12]
        out = net_forces(x, v, node_mass, node_radius, threads, rest, stiffness, damping, reference, mu, central,
                         main_tether, a_point, a_velocity, com_c, com_d - reference, rot_d, bodies[1, 6:9], omega_d,
                         mass_d, inverse_inertia_d, geometry, law, h, f, acc, work)
        for i in range(x.shape[0]):
            for a in range(3):
                v[i, a] += h * f[i, a] / node_mass[i]
                x[i, a] += h * v[i, a]
    return out


@njit(cache=True)
def chaser_actuation(t, elongation, rate, u_inertial, rot_c, com_c, vel_c, omega_c, inertia_c, attitude, thrust_kind,
                     along_body_z, thrust_params, thrust_state, step, advance, force, diag):
    """Thrust (the case's law, :func:`control.thrust.thrust_command`, along the chaser's body z or
    against its velocity as in the lower-order model) and the sliding-mode torque (eqs. 7-10,
    :mod:`control.attitude`) from the main tether's elongation and direction ``u_inertial`` (A -> net
    node). Adds them to ``force`` (6,: chaser force inertial, torque body) and fills ``diag``."""
    magnitude = thrust_command(thrust_kind, t, elongation, rate, thrust_params, thrust_state, step, advance)
    diag[D_THRUST] = magnitude
    if magnitude != 0.0:
        if along_body_z:
            direction = rot_c[:, 2].copy()
        else:
            direction = -vel_c / math.sqrt(vel_c[0] ** 2 + vel_c[1] ** 2 + vel_c[2] ** 2)
        force[0:3] += magnitude * direction
    if attitude[0] > 0.0:
        desired = desired_attitude(u_inertial, com_c)
        torque, s = sliding_mode_torque(rot_c, omega_c, desired, inertia_c, attitude[1], attitude[2:5], attitude[5:8])
        force[3:6] += torque
        diag[D_TORQUE:D_TORQUE + 3] = torque
        diag[D_SLIDING:D_SLIDING + 3] = s


@njit(cache=True)
def body_gravity(com, mass, mu, force):
    """Eq. (1) on a body at ``com`` (absolute, m) into ``force[0:3]`` (N); ``mu`` = 0: none."""
    if mu == 0.0:
        return
    gx, gy, gz = two_body_acceleration_xyz(com[0], com[1], com[2], mu)
    force[0] += mass * gx
    force[1] += mass * gy
    force[2] += mass * gz
