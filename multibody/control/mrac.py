"""Model-reference adaptive control of the main-tether elongation (MRAC-1 eqs. 9-16 and MRAC-2
eqs. 17-21 of the MRAC tether-control seed paper, ``towing-mrac-tether-control``).

Both laws see the chaser as a single-DoF mass on the main tether (abstracted model, eq. 9):

.. math:: \\ddot z + b\\,(c_{MT}\\dot z + k_{MT} z)\\,g(z, \\dot z) = b F_t,\\qquad b = 1/m_C

with :math:`g = 1` while the tether pulls (:func:`multibody.net.tension_only_kelvin_voigt` > 0)
and 0 otherwise. Both follow the reference model of eq. (13), a PD-controlled copy of that
mass with saturated force. The adaptive states are integrated with the controller's sampling
step (forward Euler, the controller is digital with zero-order hold) and frozen while the
command saturates (the :math:`H(u_{max}-|u|)` factor of eqs. 15 and 20).

This module holds what both laws share (parameter head, reference model); each law is a plug-in of
:mod:`multibody.control.thrust_laws` (``mrac1.py``, ``mrac2.py``: its gains, ``command``, initial
state); ``params`` and ``state`` are flat float arrays for the compiled towing kernels, the common
interface is described in :mod:`multibody.control.thrust`.
"""
from __future__ import annotations

from numba import njit

# params indices common to both laws; each law appends its gains (thrust_laws/mrac1.py, mrac2.py)
T_ON, U_MAX, B, K_MT, C_MT, Z_D, K_P, K_D = range(8)
N_COMMON = 8
# state: reference model z_m, z_m rate, then adaptive parameters
ZM, ZM_RATE, A0 = 0, 1, 2


def command_elongation(desired, k_mt, k_p, settle_at_desired) -> float:
    """The elongation command z_d of the reference model (eq. 13) (m): ``desired`` itself, or, with
    ``settle_at_desired``, ``desired`` (k_MT + K_P) / K_P, the command whose static balance
    :math:`k_{MT} z_m = K_P (z_d - z_m)` puts the reference at ``desired``.

    Parameters
    ----------
    desired : float
        Desired elongation (m).
    k_mt : float
        Main-tether stiffness (N/m).
    k_p : float
        Reference-model proportional gain (N/m).
    settle_at_desired : bool
        Command the reference model so that it settles at ``desired``.
    """
    return desired * (k_mt + k_p) / k_p if settle_at_desired else desired


def common_params(case, tether) -> list:
    """The parameters both laws share (indices ``T_ON`` ... ``K_D``) from a towing case (``thrust``,
    ``mrac``, ``chaser.mass``, ``main_tether.stiffness``) and its main tether ``tether`` = [k_MT (N/m),
    c_MT (N s/m), ...]: thrust-on time (s), saturation u_max (N), b = 1/m_C (1/kg), k_MT, c_MT,
    z_d (m), K_P (N/m), K_D (N s/m).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The towing case (read: ``thrust``, ``mrac``, ``chaser.mass``, ``main_tether.stiffness``).
    tether : (>= 2,) float
        k_MT (N/m), c_MT (N s/m), ... of the model's main tether.
    """
    th, m = case.thrust, case.mrac
    z_d = command_elongation(m.desired_elongation, case.main_tether.stiffness, m.k_p, m.settle_at_desired)
    return [th.t_on, th.max_force, 1.0 / case.chaser.mass, tether[0], tether[1], z_d, m.k_p, m.k_d]


def reference_steady_elongation(k_mt, k_p, z_d) -> float:
    """Elongation (m) the reference model of eq. (13) settles at while taut: its PD force balances the
    tether, :math:`k_{MT} z_m = K_P (z_d - z_m)`, so :math:`z_m = K_P z_d / (k_{MT} + K_P)` (not
    :math:`z_d` itself: eq. 13 has no integral action).

    Parameters
    ----------
    k_mt : float
        Main-tether stiffness (N/m).
    k_p : float
        Reference-model proportional gain (N/m).
    z_d : float
        Desired elongation (m).
    """
    return k_p * z_d / (k_mt + k_p)


@njit(cache=True)
def pulling(z, z_rate, k, c):
    """:math:`g(z, \\dot z)`: 1 while a tension-only tether pulls, else 0.

    Parameters
    ----------
    z : float
        Elongation (m).
    z_rate : float
        Elongation rate (m/s).
    k, c : float
        Tether stiffness (N/m) and damping (N s/m).
    """
    return 1.0 if z > 0.0 and k * z + c * z_rate > 0.0 else 0.0


@njit(cache=True)
def reference_acceleration(params, zm, zm_rate):
    """Reference model, eq. (13): the abstracted mass under a saturated PD force (m/s^2).

    Parameters
    ----------
    params : (k,) float
        The law's parameters (common head ``T_ON`` ... ``K_D`` used).
    zm, zm_rate : float
        Reference elongation (m) and its rate (m/s).
    """
    b, k, c = params[B], params[K_MT], params[C_MT]
    pd = params[K_P] * (params[Z_D] - zm) - params[K_D] * zm_rate
    pd = min(max(pd, -params[U_MAX]), params[U_MAX])
    return -b * (k * zm + c * zm_rate) * pulling(zm, zm_rate, k, c) + b * pd


@njit(cache=True)
def advance_reference(params, state, zm_acc, step):
    """Reference model's state (z_m (m), its rate (m/s)) advanced over ``step`` (s) by forward Euler
    (digital controller) with the acceleration ``zm_acc`` (m/s^2).

    Parameters
    ----------
    params : (k,) float
        The law's parameters (unused here; kept for the laws' call shape).
    state : (j,) float
        The law's state, ``ZM`` and ``ZM_RATE`` advanced in place.
    zm_acc : float
        Reference acceleration (m/s^2).
    step : float
        The controller's sampling step (s).
    """
    state[ZM] += step * state[ZM_RATE]
    state[ZM_RATE] += step * zm_acc
