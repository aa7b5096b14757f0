"""Implicit update of the towing model's connection point P (Boonrath, Singh & Botta 2024, Sec. 2.2).

P is light (m_P = s_4 m_net, 0.27-2.7 kg) and hangs on the main tether and the sub-tethers at once:
with stiff, strongly damped sub-tethers its own mode is far faster than the chaser's and the
debris' motion (gamma = c_sum/m_P up to 5e4 1/s inside the bounds of eq. 24), and an explicit
step for P would have to resolve it. P is therefore advanced implicitly, once per step of the
explicit (Verlet) integration of chaser and debris, with the bodies' attachment points held at
the step's evaluation state: BDF2 (backward Euler on the first step),

.. math:: m_P (v_{n+1} - \\hat v) = \\beta F(\\hat x + \\beta v_{n+1}, v_{n+1}),
          \\quad \\beta = 2h/3,\\; \\hat x = (4x_n - x_{n-1})/3,\\; \\hat v = (4v_n - v_{n-1})/3,

solved by Newton's method on the 3 velocity components (the tether forces of eqs. 5 and 14 and
their Jacobians in :func:`point_force`). BDF2 is second order and L-stable: the fast mode of P
is damped for any step, whatever k_ST, c_ST and m_P, so the step no longer depends on s.
Every vector is in the Earth-centred inertial frame; positions are P-displacements from P's
reference position (m).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from multibody.maths.linalg3 import solve3
from multibody.net import tension_only_kelvin_voigt
from multibody.orbit import two_body_acceleration_xyz

#: Newton iterations and relative velocity tolerance of one implicit step.
MAX_ITERATIONS, TOLERANCE = 30, 1e-13


@njit(cache=True)
def point_force(x_inertial, v_inertial, points_inertial, point_velocities_inertial, stiffness, damping, rest,
                force_inertial, jac_x, jac_v):
    """Pull of the tethers from P (at ``x_inertial``, velocity ``v_inertial``) to ``points_inertial``
    moving with ``point_velocities_inertial``; sets ``force_inertial`` and its Jacobians ``jac_x``, ``jac_v``.

    A taut tether pulls with :math:`-T u`, :math:`T = k(l - l_0) + c\\dot l`, :math:`u` = unit vector
    point -> P; :math:`\\partial(-Tu)/\\partial x = -u(k u + c(\\Delta v - \\dot l u)/l)^T - T(I - uu^T)/l`,
    :math:`\\partial(-Tu)/\\partial v = -c\\,uu^T`.

    Parameters
    ----------
    x_inertial, v_inertial : (3,) float
        P's displacement from its reference position (m) and velocity (m/s), inertial frame.
    points_inertial : (k, 3) float
        Tether attachment points, displacements from P's reference position (m), inertial frame.
    point_velocities_inertial : (k, 3) float
        Velocities of the attachment points (m/s), inertial frame.
    stiffness, damping, rest : (k,) float
        Tether i's stiffness (N/m), damping (N s/m) and rest length (m).
    force_inertial : (3,) float
        Output: the tethers' force on P (N), inertial frame.
    jac_x, jac_v : (3, 3) float
        Output: dF/dx (N/m) and dF/dv (N s/m), inertial frame.
    """
    force_inertial[:] = 0.0
    jac_x[:] = 0.0
    jac_v[:] = 0.0
    for i in range(points_inertial.shape[0]):
        dx = x_inertial[0] - points_inertial[i, 0]
        dy = x_inertial[1] - points_inertial[i, 1]
        dz = x_inertial[2] - points_inertial[i, 2]
        rel_velocity_inertial = (v_inertial[0] - point_velocities_inertial[i, 0],
                                 v_inertial[1] - point_velocities_inertial[i, 1],
                                 v_inertial[2] - point_velocities_inertial[i, 2])
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        u_inertial = (dx / length, dy / length, dz / length)  # tuples, not arrays: no allocation in the Newton loop
        rate = (rel_velocity_inertial[0] * u_inertial[0] + rel_velocity_inertial[1] * u_inertial[1]
                + rel_velocity_inertial[2] * u_inertial[2])
        tension = tension_only_kelvin_voigt(length - rest[i], rate, stiffness[i], damping[i])
        if tension <= 0.0:
            continue
        k, c = stiffness[i], damping[i]
        for a in range(3):
            force_inertial[a] -= tension * u_inertial[a]
            for b in range(3):
                jac_x[a, b] -= (u_inertial[a] * (k * u_inertial[b]
                                                 + c * (rel_velocity_inertial[b] - rate * u_inertial[b]) / length)
                                + tension * ((1.0 if a == b else 0.0) - u_inertial[a] * u_inertial[b]) / length)
                jac_v[a, b] -= c * u_inertial[a] * u_inertial[b]


@njit(cache=True)
def implicit_point_step(x_hat_inertial, v_hat_inertial, beta, mass, reference_inertial, mu, points_inertial,
                        point_velocities_inertial, stiffness, damping, rest, v_guess_inertial, external_inertial):
    """Solve :math:`m(v - \\hat v) = \\beta (F(\\hat x + \\beta v, v) + m g(\\hat x + \\beta v))` for P's new
    velocity (Newton, the tether Jacobians of :func:`point_force`; the gravity gradient, 1e-6 1/s^2,
    is left out of the Newton matrix only).

    Parameters
    ----------
    x_hat_inertial, v_hat_inertial : (3,) float
        BDF2 (or backward-Euler) predictors of P's displacement (m) and velocity (m/s), inertial frame.
    beta : float
        Step factor (s): 2h/3 for BDF2, h for backward Euler.
    mass : float
        P's mass (kg).
    reference_inertial : (3,) float
        P's reference position from the Earth's centre (m), inertial frame, for gravity (eq. 1).
    mu : float
        Gravitational parameter (m^3/s^2); 0 turns gravity off.
    points_inertial, point_velocities_inertial, stiffness, damping, rest
        The tethers, as in :func:`point_force`.
    v_guess_inertial : (3,) float
        Newton's starting velocity (m/s), inertial frame.
    external_inertial : (3,) float
        Further force on P held over the step (N), inertial frame.

    Returns
    -------
    x_inertial, v_inertial : (3,) float
        P's new displacement from its reference position (m) and velocity (m/s), inertial frame.
    """
    force_inertial, jac_x, jac_v = np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    matrix, residual = np.empty((3, 3)), np.empty(3)
    v_inertial, x_inertial = v_guess_inertial.copy(), np.empty(3)
    for _ in range(MAX_ITERATIONS):
        for a in range(3):
            x_inertial[a] = x_hat_inertial[a] + beta * v_inertial[a]
        point_force(x_inertial, v_inertial, points_inertial, point_velocities_inertial, stiffness, damping, rest,
                    force_inertial, jac_x, jac_v)
        for a in range(3):
            force_inertial[a] += external_inertial[a]   # other loads on P, held over the step (e.g. a diagnosis effect)
        if mu != 0.0:
            gx, gy, gz = two_body_acceleration_xyz(reference_inertial[0] + x_inertial[0],
                                                   reference_inertial[1] + x_inertial[1],
                                                   reference_inertial[2] + x_inertial[2], mu)
            force_inertial[0] += mass * gx
            force_inertial[1] += mass * gy
            force_inertial[2] += mass * gz
        for a in range(3):
            residual[a] = beta * force_inertial[a] - mass * (v_inertial[a] - v_hat_inertial[a])
            for b in range(3):
                matrix[a, b] = (1.0 if a == b else 0.0) * mass - beta * jac_v[a, b] - beta * beta * jac_x[a, b]
        dv_inertial = solve3(matrix, residual)
        v_inertial += dv_inertial
        speed = math.sqrt(v_inertial[0] ** 2 + v_inertial[1] ** 2 + v_inertial[2] ** 2)
        if math.sqrt(dv_inertial[0] ** 2 + dv_inertial[1] ** 2 + dv_inertial[2] ** 2) <= TOLERANCE * (1.0 + speed):
            break
    return x_hat_inertial + beta * v_inertial, v_inertial


#: Layout of P's integrator state (one float array): x_n, v_n, x_{n-1}, v_{n-1}, t_n, history flag.
X_N, V_N, X_PREVIOUS, V_PREVIOUS, TIME, HISTORY, STATE_SIZE = 0, 3, 6, 9, 12, 13, 14


def initial_point_state(velocity_inertial, time) -> np.ndarray:
    """P's integrator state at ``time``: zero displacement, the given velocity, no history.

    Parameters
    ----------
    velocity_inertial : (3,) float
        P's velocity (m/s), inertial frame.
    time : float
        Time of the state (s).

    Returns
    -------
    (STATE_SIZE,) float
        The state, laid out as :data:`X_N` ... :data:`HISTORY`.
    """
    state = np.zeros(STATE_SIZE)
    state[V_N:V_N + 3] = velocity_inertial
    state[TIME] = time
    return state


@njit(cache=True)
def advance_point(state, t, step, mass, reference_inertial, mu, points_inertial, point_velocities_inertial,
                  stiffness, damping, rest, external_inertial):
    """Advance P's ``state`` to time ``t`` if ``t`` is a new step: BDF2 when the previous step had the
    same length ``step``, backward Euler otherwise (first step).

    Parameters
    ----------
    state : (STATE_SIZE,) float
        P's integrator state (:func:`initial_point_state`), updated in place.
    t : float
        Time to advance to (s); nothing happens unless it is more than half a step past the state's.
    step : float
        The integrator's step (s).
    mass, reference_inertial, mu, points_inertial, point_velocities_inertial, stiffness, damping, rest
        As in :func:`implicit_point_step`.
    external_inertial : (3,) float
        Further force on P (N), inertial frame, held over the step.
    """
    h = t - state[TIME]
    if h <= 0.5 * step:
        return
    x_n_inertial, v_n_inertial = state[X_N:X_N + 3].copy(), state[V_N:V_N + 3].copy()
    if state[HISTORY] > 0.0 and abs(h - step) <= 1e-9 * step:
        beta = 2.0 * h / 3.0
        x_hat_inertial, v_hat_inertial = np.empty(3), np.empty(3)
        for a in range(3):
            x_hat_inertial[a] = (4.0 * x_n_inertial[a] - state[X_PREVIOUS + a]) / 3.0
            v_hat_inertial[a] = (4.0 * v_n_inertial[a] - state[V_PREVIOUS + a]) / 3.0
    else:
        beta, x_hat_inertial, v_hat_inertial = h, x_n_inertial, v_n_inertial
    x_inertial, v_inertial = implicit_point_step(x_hat_inertial, v_hat_inertial, beta, mass, reference_inertial, mu,
                                                 points_inertial, point_velocities_inertial, stiffness, damping, rest,
                                                 v_n_inertial, external_inertial)
    state[X_PREVIOUS:X_PREVIOUS + 3], state[V_PREVIOUS:V_PREVIOUS + 3] = x_n_inertial, v_n_inertial
    state[X_N:X_N + 3], state[V_N:V_N + 3] = x_inertial, v_inertial
    state[TIME], state[HISTORY] = t, 1.0
