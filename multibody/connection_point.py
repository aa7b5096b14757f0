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

from multibody.linalg3 import solve3
from multibody.net import tension_only_kelvin_voigt
from multibody.orbit import two_body_acceleration_xyz

#: Newton iterations and relative velocity tolerance of one implicit step.
MAX_ITERATIONS, TOLERANCE = 30, 1e-13


@njit(cache=True)
def point_force(x, v, points, point_velocities, stiffness, damping, rest, force, jac_x, jac_v):
    """Pull of the tethers from P (at ``x``, velocity ``v``) to ``points`` (k, 3) moving with
    ``point_velocities``; tether i has ``stiffness[i]`` (N/m), ``damping[i]`` (N s/m), ``rest[i]`` (m).
    Sets ``force`` (3,) (N) and its Jacobians ``jac_x`` = dF/dx (N/m), ``jac_v`` = dF/dv (N s/m).

    A taut tether pulls with :math:`-T u`, :math:`T = k(l - l_0) + c\\dot l`, :math:`u` = unit vector
    point -> P; :math:`\\partial(-Tu)/\\partial x = -u(k u + c(\\Delta v - \\dot l u)/l)^T - T(I - uu^T)/l`,
    :math:`\\partial(-Tu)/\\partial v = -c\\,uu^T`.
    """
    force[:] = 0.0
    jac_x[:] = 0.0
    jac_v[:] = 0.0
    for i in range(points.shape[0]):
        dx, dy, dz = x[0] - points[i, 0], x[1] - points[i, 1], x[2] - points[i, 2]
        rel = (v[0] - point_velocities[i, 0], v[1] - point_velocities[i, 1], v[2] - point_velocities[i, 2])
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        u = (dx / length, dy / length, dz / length)  # tuples, not arrays: no allocation in the Newton loop
        rate = rel[0] * u[0] + rel[1] * u[1] + rel[2] * u[2]
        tension = tension_only_kelvin_voigt(length - rest[i], rate, stiffness[i], damping[i])
        if tension <= 0.0:
            continue
        k, c = stiffness[i], damping[i]
        for a in range(3):
            force[a] -= tension * u[a]
            for b in range(3):
                jac_x[a, b] -= u[a] * (k * u[b] + c * (rel[b] - rate * u[b]) / length) + tension * (
                    (1.0 if a == b else 0.0) - u[a] * u[b]) / length
                jac_v[a, b] -= c * u[a] * u[b]


@njit(cache=True)
def implicit_point_step(x_hat, v_hat, beta, mass, reference, mu, points, point_velocities, stiffness, damping, rest,
                        v_guess, external):
    """Solve :math:`m(v - \\hat v) = \\beta (F(\\hat x + \\beta v, v) + m g(\\hat x + \\beta v))` for P's new
    velocity (Newton, the tether Jacobians of :func:`point_force`; the gravity gradient, 1e-6 1/s^2,
    is left out of the Newton matrix only). ``reference`` is P's reference position (absolute, m)
    for gravity (eq. 1; ``mu`` = 0 turns it off). Returns the new position and velocity (3,) each."""
    force, jac_x, jac_v, matrix, residual = np.empty(3), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty(3)
    v, x = v_guess.copy(), np.empty(3)
    for _ in range(MAX_ITERATIONS):
        for a in range(3):
            x[a] = x_hat[a] + beta * v[a]
        point_force(x, v, points, point_velocities, stiffness, damping, rest, force, jac_x, jac_v)
        for a in range(3):
            force[a] += external[a]   # other loads on P, held over the step (e.g. a diagnosis effect)
        if mu != 0.0:
            gx, gy, gz = two_body_acceleration_xyz(reference[0] + x[0], reference[1] + x[1], reference[2] + x[2], mu)
            force[0] += mass * gx
            force[1] += mass * gy
            force[2] += mass * gz
        for a in range(3):
            residual[a] = beta * force[a] - mass * (v[a] - v_hat[a])
            for b in range(3):
                matrix[a, b] = (1.0 if a == b else 0.0) * mass - beta * jac_v[a, b] - beta * beta * jac_x[a, b]
        dv = solve3(matrix, residual)
        v += dv
        if math.sqrt(dv[0] ** 2 + dv[1] ** 2 + dv[2] ** 2) <= TOLERANCE * (1.0 + math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)):
            break
    return x_hat + beta * v, v


#: Layout of P's integrator state (one float array): x_n, v_n, x_{n-1}, v_{n-1}, t_n, history flag.
X_N, V_N, X_PREVIOUS, V_PREVIOUS, TIME, HISTORY, STATE_SIZE = 0, 3, 6, 9, 12, 13, 14


def initial_point_state(velocity, time) -> np.ndarray:
    """P's integrator state at ``time`` (s): zero displacement, ``velocity`` (3,) (m/s), no history."""
    state = np.zeros(STATE_SIZE)
    state[V_N:V_N + 3] = velocity
    state[TIME] = time
    return state


@njit(cache=True)
def advance_point(state, t, step, mass, reference, mu, points, point_velocities, stiffness, damping, rest, external):
    """Advance P's ``state`` (:data:`STATE_SIZE`) to time ``t`` (s) if ``t`` is a new step: BDF2 when
    the previous step had the same length ``step``, backward Euler otherwise (first step). ``external``
    (3,) is a further force on P (N, inertial) held over the step."""
    h = t - state[TIME]
    if h <= 0.5 * step:
        return
    x_n, v_n = state[X_N:X_N + 3].copy(), state[V_N:V_N + 3].copy()
    if state[HISTORY] > 0.0 and abs(h - step) <= 1e-9 * step:
        beta = 2.0 * h / 3.0
        x_hat, v_hat = np.empty(3), np.empty(3)
        for a in range(3):
            x_hat[a] = (4.0 * x_n[a] - state[X_PREVIOUS + a]) / 3.0
            v_hat[a] = (4.0 * v_n[a] - state[V_PREVIOUS + a]) / 3.0
    else:
        beta, x_hat, v_hat = h, x_n, v_n
    x, v = implicit_point_step(x_hat, v_hat, beta, mass, reference, mu, points, point_velocities, stiffness, damping,
                               rest, v_n, external)
    state[X_PREVIOUS:X_PREVIOUS + 3], state[V_PREVIOUS:V_PREVIOUS + 3] = x_n, v_n
    state[X_N:X_N + 3], state[V_N:V_N + 3] = x, v
    state[TIME], state[HISTORY] = t, 1.0
