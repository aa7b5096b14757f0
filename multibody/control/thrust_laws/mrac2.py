"""MRAC-2 main-tether elongation control (eqs. 17-21 of the MRAC tether-control seed paper,
``towing-mrac-tether-control``): thrust along the chaser's body z; shared parts (abstracted model,
reference model, parameter head) in :mod:`multibody.control.mrac`.

``params`` = the common head (:data:`multibody.control.mrac.T_ON` ... ``RANGE_NOTCH_SIGMA``), then Gamma_z (2),
gamma_r, Gamma_theta (2), xi_2 (-) and P (2x2 row-major, eq. 21a); ``state`` = [z_m (m), z_m rate
(m/s), last elongation (m), last rate estimate (m/s), the breathing notch's last two inputs and
outputs (m), the last slack sample's time (s), the range-rate notch's last two inputs and outputs (m/s), Kz1 (N/m), Kz2 (N s/m), kr (N/m), theta1 (N/m),
theta2 (N s/m)]. The elongation and its rate are
:func:`multibody.control.mrac.law_measurement`'s.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg import solve_continuous_lyapunov

from multibody.control.mrac import (A0, B, C_MT, K_D, K_MT, K_P, N_COMMON, T_ON, Z_D, ZM, ZM_RATE, actuate,
                                    advance_reference, common_params, initial_state, law_measurement, pulling,
                                    range_damping_force, range_rate_seen, reference_acceleration, slack_hold)
from multibody.control.thrust import THRUST_SIGNATURE

NAME = "mrac2"
ALONG_BODY_Z = True
CASE_SECTIONS = ("mrac",)
GZ1, GZ2, GAMMA_R, GT1, GT2, XI_2, P11, P12, P21, P22 = range(N_COMMON, N_COMMON + 10)
# state: the adaptive parameters after the common head
KZ1, KZ2, KR, TH1, TH2 = range(A0, A0 + 5)


@njit(THRUST_SIGNATURE, cache=True)
def command(t, z, z_rate, range_rate, params, state, step, advance):
    """MRAC-2 thrust (N), eqs. (19)-(21), saturated to [u_min, u_max]; 0 before t_on.

    The :math:`\\hat\\Theta` law is taken with the sign that makes the Lyapunov derivative of
    the e-modification vanish for :math:`u = \\dots - \\hat\\Theta^T\\phi` (Lavretsky & Wise 2013,
    Sec. 10.2): :math:`\\dot{\\hat\\Theta} = +\\Gamma_\\theta\\phi\\,e^TPB - \\dots`; the seed paper's
    eq. (20c) prints :math:`-\\Gamma_\\theta\\hat\\Theta^T e^TPB`, a typo (it does not type-check).

    Parameters
    ----------
    t, z, z_rate, range_rate, step, advance
        As :func:`multibody.control.thrust_laws.mrac1.command` takes them (s, m, m/s, m/s, s, bool).
    params : (28,) float
        The common head (:mod:`multibody.control.mrac`), then Gamma_z (2), gamma_r, Gamma_theta (2), xi_2, P (2x2).
    state : (18,) float
        z_m (m), z_m rate (m/s), last elongation (m) and rate estimate (m/s), notch memory (4, m), last slack
        sample (s), range-rate notch memory (4, m/s), Kz (2), kr, Theta (2); advanced
        in place when ``advance``.
    """
    hold = slack_hold(t, z, params, state, advance)                        # on the measured elongation
    z, z_rate = law_measurement(params, state, z, z_rate, step, advance)   # notched (mrac.breathing_notch) or not
    range_rate = range_rate_seen(params, state, range_rate, step, advance)  # notched at the spin (mrac.range_notch) or not
    if t < params[T_ON]:
        return 0.0
    zm_acc = reference_acceleration(params, state[ZM], state[ZM_RATE])
    g = pulling(z, z_rate, params[K_MT], params[C_MT])
    phi1, phi2 = (g - 1.0) * z, (g - 1.0) * z_rate                           # eq. (18c)
    z_d = params[Z_D]
    u = (state[KZ1] * z + state[KZ2] * z_rate + state[KR] * z_d
         - (state[TH1] * phi1 + state[TH2] * phi2))                             # eq. (19)
    u += range_damping_force(params, range_rate)                              # mrac.range_damping (0: the paper's)
    force, adapt = actuate(u, hold, params)                                       # eq. (16), H(u_max - |u|)
    if advance:
        if adapt:
            e1, e2 = z - state[ZM], z_rate - state[ZM_RATE]
            epb = (e1 * params[P12] + e2 * params[P22]) * params[B]        # e^T P B, B = [0, b]
            damp = params[XI_2] * abs(epb)
            state[KZ1] += step * params[GZ1] * (-z * epb - damp * state[KZ1])   # eq. (20a)
            state[KZ2] += step * params[GZ2] * (-z_rate * epb - damp * state[KZ2])
            state[KR] += step * params[GAMMA_R] * (-z_d * epb - damp * z_d * state[KR])   # eq. (20b)
            state[TH1] += step * params[GT1] * (phi1 * epb - damp * state[TH1])  # eq. (20c), sign: see above
            state[TH2] += step * params[GT2] * (phi2 * epb - damp * state[TH2])
        advance_reference(params, state, zm_acc, step)
    return force


def arrays(case, tether, z0, z_rate0) -> tuple[np.ndarray, np.ndarray]:
    """``params`` from the case's ``[thrust]`` and ``[mrac]`` with P solving eq. (21a) for
    Q = diag(``mrac.q``); the reference model starts on the measured state and the adaptive
    parameters at their ideal values for the abstracted model (:math:`\\hat K_z = [-K_P, -K_D]`,
    :math:`\\hat k_r = K_P`, :math:`\\hat\\Theta = [-k, -c]`).

    Parameters
    ----------
    case, tether, z0, z_rate0
        See :mod:`multibody.control.thrust_laws`; reads ``[thrust]``, ``[mrac]`` (MRAC-2 gains and Q),
        the chaser mass and k_MT, c_MT.
    """
    m = case.mrac
    head = common_params(case, tether)
    b, k_mt, c_mt, k_p, k_d = head[B], head[K_MT], head[C_MT], head[K_P], head[K_D]
    a_m = np.array([[0.0, 1.0], [-b * (k_mt + k_p), -b * (c_mt + k_d)]])
    p = solve_continuous_lyapunov(a_m.T, -np.asarray(np.diag(m.q), float))  # eq. (21a): P A + A^T P = -Q
    params = np.array(head + [*m.gamma_z, m.gamma_r, *m.gamma_theta, m.xi_2, *p.ravel()], float)
    return params, np.array(initial_state(z0, z_rate0) + [-params[K_P], -params[K_D], params[K_P], -params[K_MT],
                                                          -params[C_MT]])

