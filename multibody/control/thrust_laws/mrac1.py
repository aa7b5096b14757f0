"""MRAC-1 main-tether elongation control (eqs. 9-16 of the MRAC tether-control seed paper,
``towing-mrac-tether-control``): thrust along the chaser's body z; shared parts (abstracted model,
reference model, parameter head) in :mod:`multibody.control.mrac`.

``params`` = the common head (:data:`multibody.control.mrac.T_ON` ... ``RANGE_NOTCH_SIGMA``), then lambda_0 (1/s),
k_s (N s/m), gamma, xi_h, xi_a (2) (-); ``state`` = [z_m (m), z_m rate (m/s), last elongation (m), last
rate estimate (m/s), the breathing notch's last two inputs and outputs (m), the last slack
sample's time (s), the range-rate notch's last two inputs and outputs (m/s), h (kg), a1 (N/m),
a2 (N s/m)]. The elongation and its rate are :func:`multibody.control.mrac.law_measurement`'s.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.control.mrac import (A0, B, C_MT, K_MT, N_COMMON, T_ON, ZM, ZM_RATE, actuate, advance_reference,
                                    common_params, initial_state, law_measurement, pulling,
                                    range_damping_force, range_rate_seen, reference_acceleration, slack_hold)
from multibody.control.thrust import THRUST_SIGNATURE

NAME = "mrac1"
ALONG_BODY_Z = True
CASE_SECTIONS = ("mrac",)
LAMBDA0, K_S, GAMMA, XI_H, XI_A1, XI_A2 = range(N_COMMON, N_COMMON + 6)


@njit(THRUST_SIGNATURE, cache=True)
def command(t, z, z_rate, range_rate, params, state, step, advance):
    """MRAC-1 thrust (N), eqs. (11), (12), (14)-(16), saturated to [u_min, u_max]; 0 before t_on.

    Parameters
    ----------
    t, z, z_rate, range_rate, step, advance
        As in the thrust-law interface (:mod:`multibody.control.thrust`): time (s), main-tether
        elongation (m) and rate (m/s), chaser-debris range rate (m/s), sampling step (s), whether to advance the
        states.
    params : (24,) float
        The common head (:mod:`multibody.control.mrac`), then lambda_0 (1/s), k_s (N s/m), gamma, xi_h, xi_a (2) (-).
    state : (16,) float
        z_m (m), z_m rate (m/s), last elongation (m) and rate estimate (m/s), notch memory (4, m), last slack
        sample (s), range-rate notch memory (4, m/s), h (kg), a1 (N/m), a2 (N s/m);
        advanced in place when ``advance``.
    """
    hold = slack_hold(t, z, params, state, advance)                        # on the measured elongation
    z, z_rate = law_measurement(params, state, z, z_rate, step, advance)   # notched (mrac.breathing_notch) or not
    range_rate = range_rate_seen(params, state, range_rate, step, advance)  # notched at the spin (mrac.range_notch) or not
    if t < params[T_ON]:
        return 0.0
    zm_acc = reference_acceleration(params, state[ZM], state[ZM_RATE])
    lam = params[LAMBDA0]
    eta = zm_acc - lam * (z_rate - state[ZM_RATE])                          # eq. (12)
    s = (z_rate - state[ZM_RATE]) + lam * (z - state[ZM])                   # eq. (14)
    g = pulling(z, z_rate, params[K_MT], params[C_MT])
    u = state[A0] * eta + g * (state[A0 + 1] * z + state[A0 + 2] * z_rate) - params[K_S] * s   # eq. (11)
    u += range_damping_force(params, range_rate)                              # mrac.range_damping (0: the paper's)
    force, adapt = actuate(u, hold, params)                                    # eq. (16), H(u_max - |u|)
    if advance:
        if adapt:
            gamma = params[GAMMA]
            state[A0] += step * (-s * gamma * eta - s * s * params[XI_H] * state[A0])            # eq. (15a)
            state[A0 + 1] += step * (-s * gamma * z - s * s * params[XI_A1] * state[A0 + 1])     # eq. (15b)
            state[A0 + 2] += step * (-s * gamma * z_rate - s * s * params[XI_A2] * state[A0 + 2])
        advance_reference(params, state, zm_acc, step)
    return force


def arrays(case, tether, z0, z_rate0) -> tuple[np.ndarray, np.ndarray]:
    """``params`` from the case's ``[thrust]`` and ``[mrac]``; the reference model starts on the
    measured state and the adaptive parameters at their ideal values for the abstracted model
    (:math:`\\hat h = m_C`, :math:`\\hat a = [k, c]`).

    Parameters
    ----------
    case, tether, z0, z_rate0
        See :mod:`multibody.control.thrust_laws`; reads ``[thrust]``, ``[mrac]`` (MRAC-1 gains), the
        chaser mass and k_MT, c_MT.
    """
    m = case.mrac
    params = np.array(common_params(case, tether) + [m.lambda0, m.k_s, m.gamma, m.xi_h, *m.xi_a], float)
    return params, np.array(initial_state(z0, z_rate0) + [1.0 / params[B], params[K_MT], params[C_MT]])
