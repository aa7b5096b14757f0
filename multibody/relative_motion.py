"""The net's motion relative to a multi-body debris, taken apart: which body each node moves with, what an
appendage's own swing carries, and how much of the rest is the net moving as a whole.

The capture window (:mod:`structures.capture_window`) measures the net's kinetic energy relative to the debris'
main body. On a debris whose appendages (a hinged solar array, a clamped antenna) move relative to the main body, a
net riding on a swinging appendage would read as relative energy although nothing moves relative to what it touches.
These functions split that energy so a run can say which it is:

- :func:`velocity_field` -- a rigid body's velocity at given points;
- :func:`convex_distance` -- each point's signed distance to a convex body (the nearest-body test);
- :func:`nearest_body_relative_energy` -- each node's kinetic energy relative to the main body, relative to its
  nearest body, and the part its nearest body's motion relative to the main body carries;
- :func:`appendage_energy_relative_to_body` -- an appendage's own kinetic energy relative to the main body;
- :func:`rigid_split` -- the net's relative energy as its centre of mass's, a rigid rotation's and the rest (the
  net's own deformation: threads and bullets swinging).

Pure functions on SI floats and arrays; one frame for every vector (LVLH in the impact model), angular velocities
relative to that frame's axes and expressed in it.
"""
from __future__ import annotations

import numpy as np


def velocity_field(points, body_com, body_velocity, omega):
    """A rigid body's velocity (m/s) at points moving with it.

    .. math:: v(x) = v_c + \\omega \\times (x - x_c)

    Parameters
    ----------
    points : (..., n, 3) float
        Points (m).
    body_com, body_velocity, omega : (..., 3) float
        The body's centre of mass (m), its velocity (m/s) and angular velocity (rad/s), same frame.

    Returns
    -------
    (..., n, 3) float
    """
    x = np.asarray(points, float)
    c, vc, w = (np.asarray(a, float)[..., None, :] for a in (body_com, body_velocity, omega))
    return vc + np.cross(w, x - c)


def face_planes(vertices, faces):
    """Outward unit normals (f, 3) and offsets (f,) (m) of a convex mesh's faces, in the mesh's frame; the frame's
    origin must lie inside the mesh (a body's mesh about its centre of mass)."""
    v, f = np.asarray(vertices, float), np.asarray(faces, int)
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    offset = np.einsum("fi,fi->f", normal, v[f[:, 0]])
    sign = np.where(offset < 0, -1.0, 1.0)
    return normal * sign[:, None], offset * sign


def convex_distance(points_body, normals, offsets):
    """Signed distance (m) of points to a convex body: max over its faces of n . p - d.

    Exact inside (negative) and for a point whose nearest feature is a face; a lower bound near an edge or a corner
    (at most a factor sqrt(3) short at a box's corner), which is enough to rank bodies by nearness.

    Parameters
    ----------
    points_body : (..., 3) float
        Points (m) in the body's frame (origin inside the body).
    normals, offsets : (f, 3), (f,) float
        :func:`face_planes`.

    Returns
    -------
    (...) float
    """
    return (np.asarray(points_body, float) @ np.asarray(normals, float).T - np.asarray(offsets, float)).max(axis=-1)


def nearest_body_relative_energy(masses, velocities, fields, nearest, main: int = 0):
    """Each node's kinetic energy relative to the main body, relative to its nearest body, and carried.

    .. math::

        u_i^{main} = v_i - v_{main}(x_i), \\quad u_i^{near} = v_i - v_{b(i)}(x_i), \\quad
        c_i = v_{b(i)}(x_i) - v_{main}(x_i) = u_i^{main} - u_i^{near}

    and the energies :math:`\\tfrac12 m_i |\\cdot|^2` of each. A node riding rigidly on a swinging appendage has
    :math:`u^{near} = 0` and :math:`u^{main} = c`: its whole relative energy is carried. A node swinging freely near
    the main body has :math:`c = 0`.

    Parameters
    ----------
    masses : (n,) float
        Node masses (kg).
    velocities : (k, n, 3) float
        Node velocities (m/s).
    fields : (k, n, b, 3) float
        Every body's velocity field at every node (m/s, :func:`velocity_field`).
    nearest : (k, n) int
        Each node's nearest body (index into ``fields``' body axis).
    main : int
        The main body's index.

    Returns
    -------
    dict of (k, n) float
        ``main``, ``near``, ``carried`` (J).
    """
    m = np.asarray(masses, float)
    v = np.asarray(velocities, float)
    fields = np.asarray(fields, float)
    near_field = np.take_along_axis(fields, np.asarray(nearest)[..., None, None], axis=-2)[..., 0, :]
    parts = {"main": v - fields[..., main, :], "near": v - near_field, "carried": near_field - fields[..., main, :]}
    return {name: 0.5 * m * np.einsum("...i,...i->...", u, u) for name, u in parts.items()}


def appendage_energy_relative_to_body(mass, inertia_body, com, velocity, omega, body_to_frame,
                                      main_com, main_velocity, main_omega):
    """An appendage's kinetic energy relative to the main body (J): its centre of mass's velocity less the main
    body's field there, and its angular velocity less the main body's.

    .. math::

        T = \\tfrac12 m |v_a - v_m - \\omega_m \\times (x_a - x_m)|^2
            + \\tfrac12 (\\omega_a - \\omega_m)^T R I_a R^T (\\omega_a - \\omega_m)

    Parameters
    ----------
    mass : float
        The appendage's mass (kg).
    inertia_body : (3, 3) float
        Its inertia about its centre of mass (kg m^2), its body frame.
    com, velocity, omega : (k, 3) float
        Its centre of mass (m), velocity (m/s), angular velocity (rad/s), frame of the call.
    body_to_frame : (k, 3, 3) float
        Its attitude, body -> that frame.
    main_com, main_velocity, main_omega : (k, 3) float
        The main body's, same frame.

    Returns
    -------
    (k,) float
    """
    dv = np.asarray(velocity, float) - velocity_field(np.asarray(com, float)[..., None, :], main_com, main_velocity,
                                                      main_omega)[..., 0, :]
    dw = np.asarray(omega, float) - np.asarray(main_omega, float)
    rotation = np.asarray(body_to_frame, float)
    inertia = rotation @ np.asarray(inertia_body, float) @ np.swapaxes(rotation, -1, -2)
    return 0.5 * mass * np.einsum("...i,...i->...", dv, dv) + 0.5 * np.einsum("...i,...ij,...j->...", dw, inertia, dw)


def rigid_split(masses, positions, relative_velocities):
    """The net's relative kinetic energy (J) as its centre of mass's, a rigid rotation's about it, and the rest.

    With :math:`u_i` each node's velocity relative to a body, :math:`M`, :math:`x_G`, :math:`u_G` the net's mass,
    centre and mean relative velocity, :math:`L = \\sum m_i r_i \\times (u_i - u_G)` and :math:`J` the net's inertia
    about :math:`x_G`: :math:`T = \\tfrac12 M |u_G|^2 + \\tfrac12 L^T J^{-1} L + T_{def}` (König's theorem; the
    rotation is the best-fitting rigid one, so :math:`T_{def} \\ge 0` is what no rigid motion of the whole net
    accounts for: threads and bullets moving relative to each other).

    Parameters
    ----------
    masses : (n,) float
        Node masses (kg).
    positions, relative_velocities : (k, n, 3) float
        Node positions (m) and velocities relative to the body (m/s).

    Returns
    -------
    dict of (k,) float
        ``centre``, ``rotation``, ``deformation`` (J).
    """
    m = np.asarray(masses, float)
    x, u = np.asarray(positions, float), np.asarray(relative_velocities, float)
    total_mass = m.sum()
    x_g = np.einsum("n,...ni->...i", m, x) / total_mass
    u_g = np.einsum("n,...ni->...i", m, u) / total_mass
    r, du = x - x_g[..., None, :], u - u_g[..., None, :]
    momentum = np.einsum("n,...ni->...i", m, np.cross(r, du))
    r2 = np.einsum("...ni,...ni->...n", r, r)
    inertia = (np.einsum("n,...n->...", m, r2)[..., None, None] * np.eye(3) - np.einsum("n,...ni,...nj->...ij", m, r, r))
    centre = 0.5 * total_mass * np.einsum("...i,...i->...", u_g, u_g)
    rotation = 0.5 * np.einsum("...i,...i->...", momentum, np.linalg.solve(inertia, momentum[..., None])[..., 0])
    total = 0.5 * np.einsum("n,...ni,...ni->...", m, u, u)
    return {"centre": centre, "rotation": rotation, "deformation": total - centre - rotation}
