"""Model-reference adaptive control of the main-tether elongation (MRAC-1 eqs. 9-16 and MRAC-2
eqs. 17-21 of the MRAC tether-control seed paper, ``towing-mrac-tether-control``).

Both laws see the chaser as a single-DoF mass on the main tether (abstracted model, eq. 9):

.. math:: \\ddot z + b\\,(c_{MT}\\dot z + k_{MT} z)\\,g(z, \\dot z) = b F_t,\\qquad b = 1/m_C

with :math:`g = 1` while the tether pulls (:func:`multibody.net.tension_only_kelvin_voigt` > 0)
and 0 otherwise. Both follow the reference model of eq. (13), a PD-controlled copy of that
mass with saturated force. The adaptive states are integrated with the controller's sampling
step (forward Euler, the controller is digital with zero-order hold) and frozen while the
command saturates (the :math:`H(u_{max}-|u|)` factor of eqs. 15 and 20).

``params`` layouts (see :func:`mrac_params`) and ``state`` layouts (:func:`mrac_initial_state`)
are flat float arrays for the compiled towing kernel; the common interface is described in
:mod:`multibody.control.thrust`.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg import solve_continuous_lyapunov

# params indices common to both laws
T_ON, U_MAX, B, K_MT, C_MT, Z_D, K_P, K_D = range(8)
# MRAC-1 constants
LAMBDA0, K_S, GAMMA, XI_H, XI_A1, XI_A2 = range(8, 14)
# MRAC-2 constants: Gamma_z (2), gamma_r, Gamma_theta (2), xi_2, P (2x2 row-major)
GZ1, GZ2, GAMMA_R, GT1, GT2, XI_2, P11, P12, P21, P22 = range(8, 18)
# state: reference model z_m, z_m rate, then adaptive parameters
ZM, ZM_RATE, A0 = 0, 1, 2
N_STATE = {1: 5, 2: 7}


def mrac_params(kind, t_on, u_max, chaser_mass, k_mt, c_mt, z_d, k_p, k_d, **gains) -> np.ndarray:
    """Flat parameter array of MRAC-``kind`` (1 or 2).

    Parameters
    ----------
    kind : {1, 2}       MRAC-1 or MRAC-2.
    t_on : float        Time the controller starts (s); thrust is 0 before.
    u_max : float       Thrust saturation (N).
    chaser_mass : float :math:`m_C` (kg), :math:`b = 1/m_C`.
    k_mt, c_mt : float  Main-tether stiffness (N/m) and damping (N s/m) of the abstracted model.
    z_d : float         Desired elongation (m).
    k_p, k_d : float    Reference-model PD gains (N/m, N s/m).
    gains : MRAC-1: ``lambda0`` (1/s), ``k_s`` (N s/m), ``gamma`` (-), ``xi_h``, ``xi_a`` (2,);
            MRAC-2: ``gamma_z`` (2,), ``gamma_r``, ``gamma_theta`` (2,), ``xi_2``, ``q`` (2, 2).
    """
    b = 1.0 / chaser_mass
    head = [t_on, u_max, b, k_mt, c_mt, z_d, k_p, k_d]
    if kind == 1:
        return np.array(head + [gains["lambda0"], gains["k_s"], gains["gamma"], gains["xi_h"], *gains["xi_a"]], float)
    a_m = np.array([[0.0, 1.0], [-b * (k_mt + k_p), -b * (c_mt + k_d)]])
    p = solve_continuous_lyapunov(a_m.T, -np.asarray(gains["q"], float))  # eq. (21a): P A + A^T P = -Q
    return np.array(head + [*gains["gamma_z"], gains["gamma_r"], *gains["gamma_theta"], gains["xi_2"],
                            *p.ravel()], float)


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


def mrac_initial_state(kind, params, z0, z_rate0) -> np.ndarray:
    """Reference model started on the measured state; adaptive parameters at their ideal values
    for the abstracted model (MRAC-1: :math:`\\hat h = m_C`, :math:`\\hat a = [k, c]`; MRAC-2:
    :math:`\\hat K_z = [-K_P, -K_D]`, :math:`\\hat k_r = K_P`, :math:`\\hat\\Theta = [-k, -c]`).

    Parameters
    ----------
    kind : {1, 2}
        MRAC-1 or MRAC-2.
    params : (k,) float
        :func:`mrac_params` of that law.
    z0 : float
        Measured main-tether elongation at the start (m).
    z_rate0 : float
        Its rate (m/s).

    Returns
    -------
    (N_STATE[kind],) float
        [z_m, z_m rate, adaptive parameters...].
    """
    if kind == 1:
        return np.array([z0, z_rate0, 1.0 / params[B], params[K_MT], params[C_MT]])
    return np.array([z0, z_rate0, -params[K_P], -params[K_D], params[K_P], -params[K_MT], -params[C_MT]])


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
def _reference_acceleration(params, zm, zm_rate):
    """Reference model, eq. (13): the abstracted mass under a saturated PD force (m/s^2)."""
    b, k, c = params[B], params[K_MT], params[C_MT]
    pd = params[K_P] * (params[Z_D] - zm) - params[K_D] * zm_rate
    pd = min(max(pd, -params[U_MAX]), params[U_MAX])
    return -b * (k * zm + c * zm_rate) * pulling(zm, zm_rate, k, c) + b * pd


@njit(cache=True)
def _advance_reference(params, state, zm_acc, step):
    state[ZM] += step * state[ZM_RATE]
    state[ZM_RATE] += step * zm_acc


@njit(cache=True)
def mrac1_command(t, z, z_rate, params, state, step, advance):
    """MRAC-1 thrust (N), eqs. (11), (12), (14)-(16); ``state = [z_m, z_m rate, h, a1, a2]``.

    Parameters
    ----------
    t : float
        Time (s).
    z : float
        Main-tether elongation (m).
    z_rate : float
        Its rate (m/s).
    params : (k,) float
        :func:`mrac_params` of this law.
    state : (n,) float
        The law's state (:func:`mrac_initial_state`), advanced in place when ``advance``.
    step : float
        The controller's sampling step (s).
    advance : bool
        True once per new sampling time: integrate the adaptive and reference states.

    Returns
    -------
    float
        Commanded thrust (N), saturated at ``u_max``; 0 before ``t_on``.
    """
    if t < params[T_ON]:
        return 0.0
    zm_acc = _reference_acceleration(params, state[ZM], state[ZM_RATE])
    lam = params[LAMBDA0]
    eta = zm_acc - lam * (z_rate - state[ZM_RATE])                          # eq. (12)
    s = (z_rate - state[ZM_RATE]) + lam * (z - state[ZM])                   # eq. (14)
    g = pulling(z, z_rate, params[K_MT], params[C_MT])
    u = state[A0] * eta + g * (state[A0 + 1] * z + state[A0 + 2] * z_rate) - params[K_S] * s   # eq. (11)
    force = min(max(u, -params[U_MAX]), params[U_MAX])                      # eq. (16)
    if advance:
        if abs(u) < params[U_MAX]:                                          # H(u_max - |u|)
            gamma = params[GAMMA]
            state[A0] += step * (-s * gamma * eta - s * s * params[XI_H] * state[A0])            # eq. (15a)
            state[A0 + 1] += step * (-s * gamma * z - s * s * params[XI_A1] * state[A0 + 1])     # eq. (15b)
            state[A0 + 2] += step * (-s * gamma * z_rate - s * s * params[XI_A2] * state[A0 + 2])
        _advance_reference(params, state, zm_acc, step)
    return force


@njit(cache=True)
def mrac2_command(t, z, z_rate, params, state, step, advance):
    """MRAC-2 thrust (N), eqs. (19)-(21); ``state = [z_m, z_m rate, Kz1, Kz2, kr, theta1, theta2]``.

    The :math:`\\hat\\Theta` law is taken with the sign that makes the Lyapunov derivative of
    the e-modification vanish for :math:`u = \\dots - \\hat\\Theta^T\\phi` (Lavretsky & Wise 2013,
    Sec. 10.2): :math:`\\dot{\\hat\\Theta} = +\\Gamma_\\theta\\phi\\,e^TPB - \\dots`; the seed paper's
    eq. (20c) prints :math:`-\\Gamma_\\theta\\hat\\Theta^T e^TPB`, a typo (it does not type-check).

    Parameters
    ----------
    t : float
        Time (s).
    z : float
        Main-tether elongation (m).
    z_rate : float
        Its rate (m/s).
    params : (k,) float
        :func:`mrac_params` of this law.
    state : (n,) float
        The law's state (:func:`mrac_initial_state`), advanced in place when ``advance``.
    step : float
        The controller's sampling step (s).
    advance : bool
        True once per new sampling time: integrate the adaptive and reference states.

    Returns
    -------
    float
        Commanded thrust (N), saturated at ``u_max``; 0 before ``t_on``.
    """
    if t < params[T_ON]:
        return 0.0
    zm_acc = _reference_acceleration(params, state[ZM], state[ZM_RATE])
    g = pulling(z, z_rate, params[K_MT], params[C_MT])
    phi1, phi2 = (g - 1.0) * z, (g - 1.0) * z_rate                           # eq. (18c)
    z_d = params[Z_D]
    u = (state[2] * z + state[3] * z_rate + state[4] * z_d
         - (state[5] * phi1 + state[6] * phi2))                             # eq. (19)
    force = min(max(u, -params[U_MAX]), params[U_MAX])
    if advance:
        if abs(u) < params[U_MAX]:
            e1, e2 = z - state[ZM], z_rate - state[ZM_RATE]
            epb = (e1 * params[P12] + e2 * params[P22]) * params[B]        # e^T P B, B = [0, b]
            damp = params[XI_2] * abs(epb)
            state[2] += step * params[GZ1] * (-z * epb - damp * state[2])   # eq. (20a)
            state[3] += step * params[GZ2] * (-z_rate * epb - damp * state[3])
            state[4] += step * params[GAMMA_R] * (-z_d * epb - damp * z_d * state[4])   # eq. (20b)
            state[5] += step * params[GT1] * (phi1 * epb - damp * state[5])  # eq. (20c), sign: see above
            state[6] += step * params[GT2] * (phi2 * epb - damp * state[6])
        _advance_reference(params, state, zm_acc, step)
    return force
