"""Lateral station keeping of the towing chaser: a thrust component across the main tether that holds the
chaser on a line through the debris CoM (issue 27; docs/towing.md, "A lateral station-keeping law").

Why. The Zenit-2's CoM is 0.217 m off the middle of its cylinder, so the bag's tow point P (the net's central
node) sits off the debris' spin axis and turns about it once per turn; at 29.01 deg/s that drive sits on the
chaser-bag mode and the elongation laws (thrust along the tether only) run out of headroom (docs/towing.md, "What
grows the swing at 29.01 deg/s"). The thrust-magnitude interface (:mod:`multibody.control.thrust`) acts along the
tether only; this law adds a force across it, from side thrusters in the chaser's body x-y plane (the attitude
controller keeps body z along the tether, :func:`multibody.control.attitude.desired_attitude`).

Law (a PD on the chaser's distance from a target line, a digital controller evaluated at each step like the thrust
laws). The target line passes through the debris CoM G along a unit vector n (inertial), picked by ``target``:

* ``"tow_point"``: n along G -> P. The chaser on this line puts the main tether's line (P -> chaser) through G, so
  the tension has no moment about G and the offset drives nothing once per turn. P turns about the spin axis, so
  the line turns at the spin rate, and at the chaser's distance the target point moves on a circle of radius
  delta |C - G| / |P - G| (~2 m for delta = 0.22 m, |P - G| = 1.97 m, |C - G| = 17.4 m in the shipped case).
* ``"momentum_axis"``: n along the debris' angular momentum H (towards the chaser). The chaser on the spin axis
  makes P's once-per-turn circle perpendicular to the tether, so it does not change the tether's length to first
  order; n is steady (H changes only by the tether's moment, |tau| / |H| ~ 5e-4 rad/s at 120 N x 0.2 m on
  48 000 N m s at 29.01 deg/s), so its rate is taken as zero.

With d = r_C - r_G and d' its rate (inertial), the lateral error and its rate are

.. math::
    e = (I - n n^T) d, \\qquad
    \\dot e = (I - n n^T) \\dot d - (\\dot n \\cdot d) n - (n \\cdot d) \\dot n,

with :math:`\\dot n = (I - n n^T)(v_P - v_G) / |P - G|` for ``"tow_point"``, and the commanded force

.. math::
    F = -m_C (\\omega_L^2 e + 2 \\zeta_L \\omega_L \\dot e)

projected on the chaser's body x-y plane (side thrusters: no component along the tether, which is the thrust law's)
and clipped to ``max_force`` in magnitude. On a chaser held by a tether of length L under the tow's acceleration g
(a pendulum, the towed frame) the lateral error then obeys, linearised,
:math:`\\ddot e + 2 \\zeta_L \\omega_L \\dot e + (\\omega_L^2 + g / L) e = 0`: it decays as
:math:`e^{-\\zeta_L \\omega_L t}` (tests/multibody/control/test_lateral.py).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Layout of the law's constants ``params``: on (1/0), target (index in TARGETS), omega_L (rad/s), zeta_L (-),
#: max_force (N), t_on (s), chaser mass m_C (kg).
L_ON, L_TARGET, L_OMEGA, L_ZETA, L_MAX, L_T_ON, L_MASS, L_SIZE = range(8)
#: The target lines, name -> index in ``params[L_TARGET]`` (module doc).
TARGETS = {"tow_point": 0, "momentum_axis": 1}


def lateral_params(enabled: bool, target: str, natural_frequency: float, damping_ratio: float, max_force: float,
                   t_on: float, chaser_mass: float) -> np.ndarray:
    """The law's constants (``L_SIZE``,) float (layout ``L_*``); ``enabled`` False gives the all-zero vector the
    kernel skips (the default path).

    Parameters
    ----------
    enabled : bool
        Law on.
    target : str
        A key of :data:`TARGETS`.
    natural_frequency : float
        omega_L (rad/s).
    damping_ratio : float
        zeta_L (-).
    max_force : float
        Largest lateral force (N).
    t_on : float
        The law acts from this time (s, absolute).
    chaser_mass : float
        m_C (kg).
    """
    if target not in TARGETS:
        raise ValueError(f"unknown lateral target {target!r}; known: {sorted(TARGETS)}")
    if not enabled:
        return np.zeros(L_SIZE)
    return np.array([1.0, TARGETS[target], natural_frequency, damping_ratio, max_force, t_on, chaser_mass], float)


def tow_point_line_force(offset: float, tow_point_distance: float, chaser_distance: float, spin_rate: float,
                         chaser_mass: float) -> float:
    """Lateral force (N) the ``"tow_point"`` target asks in steady state: the tow point turns at ``spin_rate``
    (rad/s) on a circle of radius ``offset`` (m) about the spin axis at ``tow_point_distance`` (m) from the debris
    CoM, so the target point at ``chaser_distance`` (m) turns on a circle ``chaser_distance / tow_point_distance``
    times larger, and a chaser of ``chaser_mass`` (kg) that follows it needs the centripetal force

    .. math:: F = m_C \\omega^2 \\delta \\, |C - G| / |P - G|.
    """
    return chaser_mass * spin_rate ** 2 * offset * chaser_distance / tow_point_distance


@njit(cache=True)
def target_axis(target, com_d, vel_d, tow_point, tow_point_vel, momentum_d, com_c):
    """Unit direction n of the target line through the debris CoM and its rate (1/s), inertial (module doc).

    Parameters
    ----------
    target : int
        ``TARGETS["tow_point"]`` or ``TARGETS["momentum_axis"]``.
    com_d, vel_d : (3,) float
        Debris CoM (m) and its velocity (m/s), inertial.
    tow_point, tow_point_vel : (3,) float
        The net's central node (m) and its velocity (m/s), inertial.
    momentum_d : (3,) float
        Debris angular momentum about its CoM (N m s), inertial.
    com_c : (3,) float
        Chaser CoM (m), inertial (picks the sign of the momentum axis: towards the chaser).

    Returns
    -------
    n, n_rate : (3,) float
    """
    if target == 0:
        arm = tow_point - com_d
        length = math.sqrt(arm @ arm)
        n = arm / length
        w = (tow_point_vel - vel_d) / length
        return n, w - (n @ w) * n
    n = momentum_d / math.sqrt(momentum_d @ momentum_d)
    if n @ (com_c - com_d) < 0.0:
        n = -n
    return n, np.zeros(3)


@njit(cache=True)
def lateral_error(n, n_rate, com_c, vel_c, com_d, vel_d):
    """Chaser's distance from the target line e (m) and its rate (m/s), inertial (module doc).

    Parameters
    ----------
    n, n_rate : (3,) float
        Unit direction of the line (-) and its rate (1/s), inertial.
    com_c, vel_c, com_d, vel_d : (3,) float
        Chaser and debris CoM (m) and velocities (m/s), inertial.

    Returns
    -------
    e, e_rate : (3,) float
    """
    d, d_rate = com_c - com_d, vel_c - vel_d
    along = n @ d
    e = d - along * n
    e_rate = d_rate - (n @ d_rate) * n - (n_rate @ d) * n - along * n_rate
    return e, e_rate


@njit(cache=True)
def side_thrust(force_inertial, rot_c, max_force):
    """``force_inertial`` (N) reduced to the chaser's body x-y plane and clipped to ``max_force`` (N) in magnitude;
    returned in inertial components. ``rot_c`` (3, 3): chaser body -> inertial."""
    fx = rot_c[0, 0] * force_inertial[0] + rot_c[1, 0] * force_inertial[1] + rot_c[2, 0] * force_inertial[2]
    fy = rot_c[0, 1] * force_inertial[0] + rot_c[1, 1] * force_inertial[1] + rot_c[2, 1] * force_inertial[2]
    size = math.sqrt(fx * fx + fy * fy)
    if size > max_force:
        fx, fy = fx * max_force / size, fy * max_force / size
    out = np.empty(3)
    for i in range(3):
        out[i] = fx * rot_c[i, 0] + fy * rot_c[i, 1]
    return out


@njit(cache=True)
def lateral_thrust(t, params, com_c, vel_c, rot_c, com_d, vel_d, tow_point, tow_point_vel, momentum_d):
    """The lateral station-keeping force on the chaser (3,) (N, inertial; zero when off or before ``t_on``).

    Parameters
    ----------
    t : float
        Time (s, absolute).
    params : (L_SIZE,) float
        The law's constants (:func:`lateral_params`).
    com_c, vel_c : (3,) float
        Chaser CoM (m) and velocity (m/s), inertial.
    rot_c : (3, 3) float
        Chaser body -> inertial.
    com_d, vel_d, tow_point, tow_point_vel, momentum_d : (3,) float
        See :func:`target_axis`.
    """
    if params[L_ON] == 0.0 or t < params[L_T_ON]:
        return np.zeros(3)
    n, n_rate = target_axis(int(params[L_TARGET]), com_d, vel_d, tow_point, tow_point_vel, momentum_d, com_c)
    e, e_rate = lateral_error(n, n_rate, com_c, vel_c, com_d, vel_d)
    w, zeta = params[L_OMEGA], params[L_ZETA]
    return side_thrust(-params[L_MASS] * (w * w * e + 2.0 * zeta * w * e_rate), rot_c, params[L_MAX])
