"""Relative orbital motion about a circular reference orbit (Clohessy-Wiltshire).

Frame: LVLH centred on the chaser, x radial (outward), y along-track (flight
direction), z cross-track (orbit normal); Cuadrat-Grzybowski & Gill 2024, Sec. 2.2.1.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Earth's gravitational parameter (m^3/s^2), IERS 2010 / EGM2008 value.
MU_EARTH = 3.986004418e14
#: Earth's equatorial radius (m), WGS-84.
R_EARTH = 6378137.0


def mean_motion(altitude):
    """Mean motion of a circular orbit (rad/s) at ``altitude`` above the equatorial radius.

    Parameters
    ----------
    altitude : float
        Orbit altitude above :data:`R_EARTH` (m).
    """
    return math.sqrt(MU_EARTH / (R_EARTH + altitude) ** 3)


@njit(cache=True, inline="always")
def clohessy_wiltshire_acceleration_xyz(x, z, vx, vy, n):
    """Components (m/s^2) of :func:`clohessy_wiltshire_acceleration`, in scalars (no allocation).

    Parameters
    ----------
    x, z : float
        Radial and cross-track position relative to the chaser (m), LVLH.
    vx, vy : float
        Radial and along-track velocity (m/s), LVLH.
    n : float
        Mean motion (rad/s).

    Returns
    -------
    tuple of 3 float
        Acceleration (m/s^2), LVLH x, y, z.
    """
    return n * n * 3.0 * x + 2.0 * n * vy, -2.0 * n * vx, -n * n * z


@njit(cache=True)
def clohessy_wiltshire_acceleration(r_lvlh, v_lvlh, n):
    """Apparent acceleration in LVLH (m/s^2) of a free body; seed paper eq. (9) without contact.

    .. math:: \\ddot{\\mathbf r} = n^2 (3x, 0, -z) + 2n(\\dot y, -\\dot x, 0)

    Parameters
    ----------
    r_lvlh, v_lvlh : (3,) float
        Position (m) and velocity (m/s) relative to the chaser, LVLH.
    n : float
        Mean motion (rad/s); 0 turns the orbit off.
    """
    ax, ay, az = clohessy_wiltshire_acceleration_xyz(r_lvlh[0], r_lvlh[2], v_lvlh[0], v_lvlh[1], n)
    return np.array([ax, ay, az])


def clohessy_wiltshire_potential(r_lvlh, n):
    """Potential energy per unit mass of the CW field (J/kg); with the Jacobi integral it is conserved.

    The Coriolis term does no work, so :math:`\\tfrac12|v|^2 + \\tfrac12 n^2 (z^2 - 3x^2)` is constant.

    Parameters
    ----------
    r_lvlh : (3,) or (k, 3) float
        Positions relative to the chaser (m), LVLH.
    n : float
        Mean motion (rad/s).

    Returns
    -------
    (k,) float
        Potential per unit mass (J/kg), one per position.
    """
    r_lvlh = np.atleast_2d(r_lvlh)
    return 0.5 * n * n * (r_lvlh[:, 2] ** 2 - 3.0 * r_lvlh[:, 0] ** 2)


@njit(cache=True, inline="always")
def two_body_acceleration_xyz(x, y, z, mu):
    """Components (m/s^2) of :func:`two_body_acceleration`, in scalars (no allocation).

    Parameters
    ----------
    x, y, z : float
        Position from the Earth's centre (m), inertial frame.
    mu : float
        Gravitational parameter (m^3/s^2).

    Returns
    -------
    tuple of 3 float
        Acceleration (m/s^2), inertial frame.
    """
    r2 = x * x + y * y + z * z
    scale = -mu / (r2 * math.sqrt(r2))
    return scale * x, scale * y, scale * z


@njit(cache=True)
def two_body_acceleration(r_inertial, mu):
    """Gravitational acceleration of a point at ``r_inertial`` (m/s^2), Earth-centred inertial frame.

    Boonrath, Singh & Botta 2024, eq. (1) divided by the body's mass:

    .. math:: \\mathbf a = -\\mu \\frac{\\mathbf r}{\\|\\mathbf r\\|^3}

    Parameters
    ----------
    r_inertial : (3,) float
        Position of the body's CoM from the Earth's centre (m), inertial frame.
    mu : float
        Gravitational parameter (m^3/s^2).
    """
    ax, ay, az = two_body_acceleration_xyz(r_inertial[0], r_inertial[1], r_inertial[2], mu)
    return np.array([ax, ay, az])


def two_body_specific_energy(r_inertial, v_inertial, mu):
    """Specific orbital energy :math:`\\tfrac12 v^2 - \\mu/r` (J/kg) of states (..., 3) in the
    inertial frame; constant on a Keplerian orbit.

    Parameters
    ----------
    r_inertial : (..., 3) float
        Positions from the Earth's centre (m), inertial frame.
    v_inertial : (..., 3) float
        Velocities (m/s), inertial frame.
    mu : float
        Gravitational parameter (m^3/s^2).

    Returns
    -------
    (...,) float
        Specific energy (J/kg).
    """
    distance = np.linalg.norm(r_inertial, axis=-1)
    return 0.5 * np.sum(np.asarray(v_inertial) ** 2, axis=-1) - mu / distance


def lvlh_to_eci(r_eci, v_eci) -> np.ndarray:
    """Rotation LVLH -> ECI of a spacecraft's orbit frame.

    Parameters
    ----------
    r_eci : (3,) or (k, 3) float array
        Position (m, ECI).
    v_eci : (3,) or (k, 3) float array
        Velocity (m/s, ECI).

    Returns
    -------
    (3, 3) or (k, 3, 3) float array
        Matrices whose columns are the LVLH axes in ECI: radial, along-track, orbit normal.
    """
    r_eci, v_eci = np.asarray(r_eci, float), np.asarray(v_eci, float)
    x_lvlh_eci = r_eci / np.linalg.norm(r_eci, axis=-1, keepdims=True)
    z_lvlh_eci = np.cross(r_eci, v_eci)
    z_lvlh_eci /= np.linalg.norm(z_lvlh_eci, axis=-1, keepdims=True)
    return np.stack([x_lvlh_eci, np.cross(z_lvlh_eci, x_lvlh_eci), z_lvlh_eci], axis=-1)


@njit(cache=True, inline="always")
def add_body_gravity(out_force_inertial, base, x, y, z, mass, mu):
    """Two-body gravity (Boonrath et al. 2024, eq. 1) on a body, added to a force vector.

    Parameters
    ----------
    out_force_inertial : (n,) float array
        Generalized forces (N, inertial); the body's three force components start at ``base``.
    base : int
        Index of the body's x force component in ``out_force_inertial``.
    x, y, z : float
        The body's CoM (m, inertial, from the Earth's centre).
    mass : float
        The body's mass (kg).
    mu : float
        Gravitational parameter (m^3/s^2); 0 turns gravity off (tests away from any orbit).
    """
    if mu == 0.0:
        return
    gx, gy, gz = two_body_acceleration_xyz(x, y, z, mu)
    out_force_inertial[base] += mass * gx
    out_force_inertial[base + 1] += mass * gy
    out_force_inertial[base + 2] += mass * gz
