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
from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.experimental import structref

from multibody.control.attitude import desired_attitude, sliding_mode_torque
from multibody.control.thrust import THRUST_LAW
from multibody.connection_point import implicit_point_step
from multibody.contact import contact_over_step
from multibody.contact_kernel import _effective_mass_along_normal, _substeps_to_resolve_contact
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.net import add_thread_forces, tension_only_kelvin_voigt
from multibody.orbit import two_body_acceleration_xyz

#: Layout of the per-step accumulator ``acc`` (all inertial): debris force (3), debris torque about
#: its CoM (3), chaser force (3), chaser torque about its CoM (3), then scalars.
ACC_DEBRIS_F, ACC_DEBRIS_T, ACC_CHASER_F, ACC_CHASER_T = 0, 3, 6, 9
ACC_TENSION, ACC_CONTACTS, ACC_CONTACT_F, ACC_CLOSING, ACC_EXTERNAL, ACC_DISSIPATED, ACC_SIZE = 12, 13, 14, 15, 16, 19, 20
#: Diagnostics of one step (``diag``): MT mean tension, elongation, elongation rate, thrust, control
#: torque (3, chaser body), sliding variable (3), mean contacts, mean contact force, largest closing tension,
#: lateral station-keeping force (3, N, inertial; :mod:`multibody.control.lateral`).
D_TENSION, D_ELONGATION, D_RATE, D_THRUST, D_TORQUE, D_SLIDING, D_CONTACTS, D_CONTACT_F, D_CLOSING, D_LATERAL, D_SIZE = (
    0, 1, 2, 3, 4, 7, 10, 11, 12, 13, 16)
#: Cylinder geometry: radius (m), half length (m), axial centre z (m) in the debris frame.
CYL_RADIUS, CYL_HALF, CYL_Z = 0, 1, 2
#: Contact law: k_n (N/m^n), n, d_n, mu_s, mu_k, V_t0 (see multibody.assembly.ContactLaw).
C_K, C_EXP, C_D, C_MUS, C_MUK, C_VT = range(6)


class NetThreads(NamedTuple):
    """The net's nodes and threads as the towing kernels take them (n nodes, m threads; SI)."""

    node_mass: np.ndarray     # (n,) node masses (kg)
    node_radius: np.ndarray   # (n,) node contact radii (m)
    threads: np.ndarray       # (m, 2) int64 node pairs; the closing loop is the last 12
    rest: np.ndarray          # (m,) natural lengths (m); the closing loop's change in place while it is reeled in
    stiffness: np.ndarray     # (m,) EA/l0 (N/m), likewise
    damping: np.ndarray       # (m,) (N s/m)
    rest_rate: np.ndarray     # (m,) rate of each natural length (m/s): the closing loop's while it is reeled in, else
                              # 0; the dampers read the stretch's rate l' - l0' (multibody.net.tension_only_kelvin_voigt)


class DebrisBody(NamedTuple):
    """The debris as the net's contact meets it: a rigid closed cylinder (SI)."""

    mass: float                         # (kg)
    inverse_inertia_body: np.ndarray    # (3, 3) inverse inertia about the CoM, debris frame (1/(kg m^2))
    geometry: np.ndarray                # (3,) radius (m), half length (m), axial centre z_body (m): CYL_*
    contact_law: np.ndarray             # (6,) k_n, n, d_n, mu_s, mu_k, V_t0: C_*


class DebrisMotion(NamedTuple):
    """The debris' motion at one net sub-step (inertial frame)."""

    com: np.ndarray              # (3,) CoM relative to the nodes' reference point (m)
    to_inertial: np.ndarray      # (3, 3) rotation debris frame -> inertial
    velocity: np.ndarray         # (3,) CoM velocity (m/s)
    omega_inertial: np.ndarray   # (3,) angular velocity, inertial components (rad/s)


class TetherEnd(NamedTuple):
    """The main tether (eq. 5a) and its end A on the chaser at one net sub-step (inertial frame)."""

    params: np.ndarray        # (3,) k_MT (N/m), c_MT (N s/m), l_MT0 (m)
    point: np.ndarray         # (3,) attachment point A, absolute (m)
    velocity: np.ndarray      # (3,) A's velocity (m/s)
    chaser_com: np.ndarray    # (3,) chaser CoM, absolute (m)


@njit(cache=True, inline="always")
def cylinder_distance(px, py, pz, geometry):
    """Signed distance (m) from a point (debris frame, m) to a closed circular cylinder with axis
    z_body (``geometry``: radius, half length, axial centre) and the outward unit normal at the
    nearest surface point (debris frame); negative inside.

    Parameters
    ----------
    px, py, pz : float
        The point, debris body frame relative to its CoM (m).
    geometry : (3,) float
        Radius (m), half length (m), axial centre z_body (m): ``CYL_*``.

    Returns
    -------
    distance, nx, ny, nz : float
        Signed distance (m) and unit normal (-, debris body frame).
    """
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


#: Most contact sub-steps per net sub-step (the impact model sizes them at 0.02 rad of the contact's
#: linearized oscillation, multibody.contact_kernel.CONTACT_PHASE_PER_SUBSTEP).
MAX_CONTACT_SUBSTEPS = 64


@njit(cache=True, inline="always")
def _node_contact(i, x, v, lag, f, node_mass, penetration, nbx, nby, nbz, com, rot, vel, omega, mass, inverse_inertia,
                  law, h, work):
    """Contact of node ``i`` (``penetration`` (m) along the debris-frame normal ``nb``) with the debris
    over one net sub-step, sub-cycled in time exactly as the impact model does
    (:func:`multibody.contact.contact_over_step`, sub-steps sized by
    :func:`multibody.contact_kernel._substeps_to_resolve_contact`; starting from the node's velocity plus the
    ``lag`` carried from the last sub-step). Returns the mean and end velocity changes (m/s) and the
    dissipated energy (J); the caller kicks with the mean and carries end - mean as the next lag."""
    ax, ay, az = x[i, 0] - com[0], x[i, 1] - com[1], x[i, 2] - com[2]
    pen, rel, normal, ext, masses = work[0:1], work[1:4].reshape(1, 3), work[4:7].reshape(1, 3), work[7:10], work[10:11]
    pen[0] = penetration
    normal[0, 0] = rot[0, 0] * nbx + rot[0, 1] * nby + rot[0, 2] * nbz
    normal[0, 1] = rot[1, 0] * nbx + rot[1, 1] * nby + rot[1, 2] * nbz
    normal[0, 2] = rot[2, 0] * nbx + rot[2, 1] * nby + rot[2, 2] * nbz
    rel[0, 0] = v[i, 0] + lag[i, 0] - vel[0] - (omega[1] * az - omega[2] * ay)
    rel[0, 1] = v[i, 1] + lag[i, 1] - vel[1] - (omega[2] * ax - omega[0] * az)
    rel[0, 2] = v[i, 2] + lag[i, 2] - vel[2] - (omega[0] * ay - omega[1] * ax)
    ext[0], ext[1], ext[2] = f[i, 0], f[i, 1], f[i, 2]
    masses[0] = _effective_mass_along_normal(rot, inverse_inertia, mass, ax, ay, az,
                                             normal[0, 0], normal[0, 1], normal[0, 2])
    n_sub = min(MAX_CONTACT_SUBSTEPS, _substeps_to_resolve_contact(pen, rel, normal, masses, 1, ext, node_mass, h,
                                                                    law[C_K], law[C_EXP], law[C_D]))
    return contact_over_step(
        pen, rel, normal, ext, node_mass, masses, h, n_sub, law[C_K], law[C_EXP], law[C_D], law[C_MUS], law[C_MUK],
        law[C_VT], work[11:14].reshape(1, 3), work[14:15], work[15:18].reshape(1, 3), work[18:21].reshape(1, 3))


@njit(cache=True)
def net_forces(x, v, lag, net, reference, mu, central, end, motion, debris, h, f, acc, work, explicit_tether=True):
    """Forces on every node (``f`` (n, 3), N) at positions ``x`` (displacements from ``reference``, m)
    and velocities ``v`` (m/s); the reactions on the bodies (force, torque about the CoM, inertial)
    are added to ``acc`` times ``h`` (impulses), with the main tether's tension, contact count, total
    contact force, largest closing-thread tension and the node gravity's impulse.

    ``net`` (:class:`NetThreads`) the nodes and threads; ``end`` (:class:`TetherEnd`) the main tether from
    node ``central`` to the chaser's attachment; ``motion`` (:class:`DebrisMotion`, CoM relative to
    ``reference`` like the nodes) and ``debris`` (:class:`DebrisBody`) the debris cylinder; ``mu``
    (m^3/s^2), ``h`` the sub-step (s); ``f``, ``acc``, ``work`` buffers.
    Returns the main tether's (tension, elongation, elongation rate). With ``explicit_tether`` False
    the main tether is left out (the sub-cycle steps it implicitly, :func:`_implicit_tether_step`).

    Parameters
    ----------
    x, v : (n, 3) float
        Node positions relative to ``reference`` (m) and velocities (m/s), inertial.
    lag : (n, 3) float
        Contact velocity lags (m/s), released and set in place.
    net : NetThreads
        Nodes and threads.
    reference : (3,) float
        Origin of the node positions, absolute (m).
    mu : float
        Gravitational parameter (m^3/s^2); 0: no gravity.
    central : int
        Node the main tether holds.
    end : TetherEnd
        Main tether and its chaser end A.
    motion : DebrisMotion
        The debris' motion at this sub-step.
    debris : DebrisBody
        The debris cylinder, its mass properties and the contact law.
    h : float
        Sub-step (s).
    f : (n, 3) float
        Node forces (N, inertial), overwritten.
    acc : (ACC_SIZE,) float
        Impulses and scalars (``ACC_*``), added to.
    work : (21,) float
        Scratch of the contact solver.
    explicit_tether : bool
        Include the main tether's force.
    """
    node_mass, node_radius, threads, rest, stiffness, damping, rest_rate = net
    main_tether, a_point, a_velocity, com_c = end
    com_d, rot_d, vel_d, omega_d = motion
    mass_d, inverse_inertia_d, geometry, law = debris
    f[:] = 0.0
    add_thread_forces(x, v, threads, rest, stiffness, damping, f, rest_rate)
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
    tension, stretch, rate = 0.0, 0.0, 0.0
    if explicit_tether:
        tension, stretch, rate = _main_tether(x, v, reference, central, main_tether, a_point, a_velocity, com_c, h, f,
                                              acc)
    for t in range(threads.shape[0] - 12, threads.shape[0]):  # the closing loop is the last 12 threads
        a, b = threads[t, 0], threads[t, 1]
        length = math.sqrt((x[b, 0] - x[a, 0]) ** 2 + (x[b, 1] - x[a, 1]) ** 2 + (x[b, 2] - x[a, 2]) ** 2)
        acc[ACC_CLOSING] = max(acc[ACC_CLOSING], stiffness[t] * (length - rest[t]))
    for i in range(n):
        kx, ky, kz = lag[i, 0], lag[i, 1], lag[i, 2]  # release the lag of the last sub-step
        lag[i, 0] = lag[i, 1] = lag[i, 2] = 0.0
        penetration, nbx, nby, nbz, near = _near(i, x, v, node_radius[i], com_d, rot_d, vel_d, omega_d, geometry, h)
        if near:
            mx, my, mz, ex, ey, ez, dissipated = _node_contact(
                i, x, v, lag, f, node_mass[i], penetration, nbx, nby, nbz, com_d, rot_d, vel_d, omega_d, mass_d,
                inverse_inertia_d, law, h, work)
            kx, ky, kz = kx + mx, ky + my, kz + mz
            lag[i, 0], lag[i, 1], lag[i, 2] = ex - mx, ey - my, ez - mz
            acc[ACC_DISSIPATED] += dissipated
        if kx != 0.0 or ky != 0.0 or kz != 0.0:
            fx, fy, fz = node_mass[i] * kx / h, node_mass[i] * ky / h, node_mass[i] * kz / h
            f[i, 0] += fx
            f[i, 1] += fy
            f[i, 2] += fz
            rx, ry, rz = x[i, 0] - com_d[0], x[i, 1] - com_d[1], x[i, 2] - com_d[2]
            _add_impulse(acc, ACC_DEBRIS_F, -fx * h, -fy * h, -fz * h, rx, ry, rz)
            acc[ACC_CONTACT_F] += math.sqrt(fx * fx + fy * fy + fz * fz) * h
        if penetration > 0.0:
            acc[ACC_CONTACTS] += h
    return tension, stretch, rate


@njit(cache=True)
def _main_tether(x, v, reference, central, main_tether, a_point, a_velocity, com_c, h, f, acc):
    """Main tether (eq. 5a) from node ``central`` to the chaser's attachment ``a_point`` (absolute, m)
    at the current state: its pull into ``f``, the reaction's impulse over ``h`` on the chaser into
    ``acc``. Returns (tension (N), elongation (m), elongation rate (m/s))."""
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
def advance_net(x, v, lag, t_start, t_end, n_sub, net, reference, mu, central, main_tether, attach_chaser_body, bodies,
                debris, f, acc, work):
    """Advance the net from ``t_start`` to ``t_end`` (s) by ``n_sub`` symplectic-Euler sub-steps while
    chaser and debris move as Verlet moves them over the step. ``bodies`` (2, 12): per body (chaser,
    debris) the CoM at ``t_end`` (absolute, m), rotation vector body->inertial at ``t_end`` (rad),
    half-step CoM velocity (m/s) and angular velocity (rad/s, body frame). ``net``
    (:class:`NetThreads`), ``debris`` (:class:`DebrisBody`), ``main_tether`` = [k_MT (N/m), c_MT (N s/m),
    l_MT0 (m)], ``attach_chaser_body`` (3,) A in the chaser frame (m). ``acc`` (ACC_SIZE) is
    zeroed and receives the impulses over the step (:func:`net_forces`). Returns the main tether's
    (tension, elongation, rate) at the last sub-step.

    Parameters
    ----------
    x, v, lag : (n, 3) float
        Net state (:func:`net_forces`), advanced in place.
    t_start, t_end : float
        The step's interval (s).
    n_sub : int
        Sub-steps.
    net, reference, mu, central
        As :func:`net_forces` takes them.
    main_tether : (3,) float
        k_MT (N/m), c_MT (N s/m), l_MT0 (m).
    attach_chaser_body : (3,) float
        A in the chaser frame (m).
    bodies : (2, 12) float
        See above.
    debris : DebrisBody
        The debris cylinder, its mass properties and the contact law.
    f, acc, work
        Buffers (:func:`net_forces`); ``acc`` zeroed first.
    """
    node_mass = net.node_mass
    acc[:] = 0.0
    h = (t_end - t_start) / n_sub
    rot_c_end = rotation_matrix_from_rotation_vector(bodies[0, 3:6])
    rot_d_end = rotation_matrix_from_rotation_vector(bodies[1, 3:6])
    out = (0.0, 0.0, 0.0)
    com_c, com_d, a_point, a_velocity = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for k in range(n_sub):
        back = t_end - (t_start + k * h)
        rot_d = _geodesic(rot_d_end, bodies[1, 9:12], back)
        for a in range(3):
            com_d[a] = bodies[1, a] - back * bodies[1, 6 + a] - reference[a]
        _attachment(bodies[0], rot_c_end, attach_chaser_body, back, com_c, a_point, a_velocity)
        omega_d = rot_d @ bodies[1, 9:12]
        net_forces(x, v, lag, net, reference, mu, central, TetherEnd(main_tether, a_point, a_velocity, com_c),
                   DebrisMotion(com_d, rot_d, bodies[1, 6:9], omega_d), debris, h, f, acc, work, False)
        for i in range(x.shape[0]):
            if i == central:
                continue
            for a in range(3):
                v[i, a] += h * f[i, a] / node_mass[i]
                x[i, a] += h * v[i, a]
        _attachment(bodies[0], rot_c_end, attach_chaser_body, back - h, com_c, a_point, a_velocity)
        out = _implicit_tether_step(x, v, f, node_mass[central], reference, central, main_tether, a_point, a_velocity,
                                    com_c, h, acc)
    return out


@njit(cache=True)
def _attachment(chaser, rot_end, attach_body, back, com, point, velocity):
    """Chaser CoM, attachment point A (absolute, m) and A's velocity (m/s) ``back`` seconds before
    the step's end, on Verlet's path (``chaser``: a row of ``bodies``, see :func:`advance_net`)."""
    rot = _geodesic(rot_end, chaser[9:12], back)
    arm = rot @ attach_body
    spin = rot @ np.cross(chaser[9:12], attach_body)
    for a in range(3):
        com[a] = chaser[a] - back * chaser[6 + a]
        point[a] = com[a] + arm[a]
        velocity[a] = chaser[6 + a] + spin[a]


@njit(cache=True)
def _implicit_tether_step(x, v, f, mass, reference, central, main_tether, a_point, a_velocity, com_c, h, acc):
    """Backward-Euler sub-step of the central node under the main tether, the node's other forces
    ``f[central]`` held: :math:`m(v_{k+1} - v_k) = h(F_{MT}(x_k + h v_{k+1}, v_{k+1}) + f)`, Newton on the
    tether Jacobians (:func:`multibody.connection_point.implicit_point_step`, the lower-order model's
    P solver), A at the sub-step's end. The tether's damping on a 10 g node (c_MT/m ~ 3e4 1/s) would
    need an explicit sub-step below ~60 us; backward Euler is L-stable. The chaser gets the reaction
    of the tension at the new state, so the momentum exchange stays exact. Returns (tension,
    elongation, rate) at the new state."""
    points = np.empty((1, 3))
    for a in range(3):
        points[0, a] = a_point[a] - reference[a]
    k, c, rest = np.full(1, main_tether[0]), np.full(1, main_tether[1]), np.full(1, main_tether[2])
    x_new, v_new = implicit_point_step(x[central], v[central], h, mass, reference, 0.0, points,
                                       a_velocity.reshape(1, 3), k, c, rest, v[central], f[central])
    x[central], v[central] = x_new, v_new
    return _main_tether(x, v, reference, central, main_tether, a_point, a_velocity, com_c, h, f, acc)


_VECTOR = types.float64[::1]


@structref.register
class ChaserControlType(types.StructRef):
    """numba type of :class:`ChaserControl`."""


class ChaserControl(structref.StructRefProxy):
    """The chaser's controllers as the compiled full-net kernel takes them (make it with
    :func:`chaser_control`).

    Fields
    ------
    attitude : (8,) float       Sliding-mode attitude control: on (1/0), K (1/s), G (3,) (rad/s^2),
                                boundary layer epsilon (3,) (rad/s) (eqs. 7-10).
    thrust : first-class function   The thrust law's compiled ``command``
                                (:data:`multibody.control.thrust.THRUST_LAW`).
    along_body_z : bool         Thrust along the chaser's body z (True) or against its inertial velocity.
    thrust_params : (k,) float  The law's constants; ``thrust_state`` (j,) float its states, advanced
                                in place (shared with the array given, not copied).
    lateral : (L_SIZE,) float   Lateral station-keeping law's constants (:func:`multibody.control.lateral.lateral_params`;
                                all zero: off).
    """


structref.define_proxy(ChaserControl, ChaserControlType, ["attitude", "thrust", "along_body_z", "thrust_params",
                                                          "thrust_state", "lateral"])
#: numba type of the kernels' chaser-control argument.
CHASER_CONTROL = ChaserControlType([("attitude", _VECTOR), ("thrust", THRUST_LAW), ("along_body_z", types.boolean),
                                    ("thrust_params", _VECTOR), ("thrust_state", _VECTOR), ("lateral", _VECTOR)])


@njit(CHASER_CONTROL(_VECTOR, THRUST_LAW, types.boolean, _VECTOR, _VECTOR, _VECTOR), cache=True)
def chaser_control(attitude, thrust, along_body_z, thrust_params, thrust_state, lateral):
    """The :class:`ChaserControl` of these fields (arrays shared, not copied).

    Parameters
    ----------
    attitude : (8,) float
        On (1/0), K (1/s), G (3,) (rad/s^2), epsilon (3,) (rad/s).
    thrust : first-class function
        The thrust law's compiled command (:data:`multibody.control.thrust.THRUST_LAW`).
    along_body_z : bool
        Thrust along the chaser's body z (True) or against its inertial velocity.
    thrust_params, thrust_state : (k,), (j,) float
        The law's constants and states (states advanced in place).
    lateral : (L_SIZE,) float
        Lateral station-keeping constants (:func:`multibody.control.lateral.lateral_params`; zeros: off).
    """
    control = structref.new(CHASER_CONTROL)
    control.attitude = attitude
    control.thrust = thrust
    control.along_body_z = along_body_z
    control.thrust_params = thrust_params
    control.thrust_state = thrust_state
    control.lateral = lateral
    return control


@njit(cache=True)
def chaser_actuation(t, elongation, rate, range_rate, u_inertial, rot_c, com_c, vel_c, omega_c, inertia_c, control, step,
                     advance, force, diag):
    """Thrust (the case's law ``control.thrust``, along the chaser's body z or against its velocity as in the
    lower-order model) and the sliding-mode torque (eqs. 7-10, :mod:`multibody.control.attitude`) from the main
    tether's elongation (m), its rate (m/s) and direction ``u_inertial`` (A -> net node); ``control`` a
    :class:`ChaserControl`. Adds them to ``force`` (6,: chaser force inertial, torque body) and fills ``diag``.

    Parameters
    ----------
    t : float
        Time (s).
    elongation, rate : float
        Main-tether elongation (m) and rate (m/s).
    range_rate : float
        Chaser-debris range rate (m/s, > 0 separating), :func:`multibody.control.thrust.range_rate`.
    u_inertial : (3,) float
        Unit vector A -> net node (inertial).
    rot_c : (3, 3) float
        Chaser body -> inertial.
    com_c, vel_c : (3,) float
        Chaser CoM (m, absolute) and velocity (m/s), inertial.
    omega_c : (3,) float
        Chaser angular velocity, body frame (rad/s).
    inertia_c : (3, 3) float
        Chaser inertia, body frame (kg m^2).
    control : ChaserControl
        Thrust law and attitude controller.
    step : float
        Sampling step (s).
    advance : bool
        Advance the thrust law's state.
    force : (6,) float
        Added to: chaser force (N, inertial), torque (N m, body).
    diag : (D_SIZE,) float
        ``D_THRUST``, ``D_TORQUE``, ``D_SLIDING`` written.
    """
    attitude = control.attitude
    magnitude = control.thrust(t, elongation, rate, range_rate, control.thrust_params, control.thrust_state, step,
                               advance)
    diag[D_THRUST] = magnitude
    if magnitude != 0.0:
        if control.along_body_z:
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
