"""Once-per-turn thrust budget of the MRAC laws (``mrac.tow_point_offset``; :mod:`multibody.control.mrac`).

The tow point of a netted body whose CoM sits off its middle circles the CoM once per turn; following it costs the
chaser a thrust line :math:`m_C\\omega^2\\delta` (:func:`once_per_turn_thrust`), and the reference governor
:func:`governed_elongation` lowers the desired elongation so that the steady thrust leaves that line inside the
actuator's upper bound. Measured on the full net (docs/towing.md, "A range-rate notch at the spin rate, and a thrust
budget"): off in the shipped case.
"""
from __future__ import annotations

import math


def once_per_turn_thrust(case) -> float:
    r"""Thrust amplitude (N) the once-per-turn motion of the tow point asks of the chaser: with ``mrac.tow_point_offset``
    = delta (m, the debris CoM's distance from the middle of the netted body, which the bag's tow point circles once
    per turn), :math:`m_C \omega^2 \delta` at the tow's spin rate omega; 0 without it.

    It is both the thrust that lets the chaser follow the tow point at constant tension and, when the chaser-bag mode
    sits on omega (29.01 deg/s on the Zenit-2 case), the thrust any damping law spends there in steady state: on
    resonance the separation's balance :math:`(K - \mu\omega^2) s = K x + \alpha F` leaves
    :math:`\alpha |F| = K |x|` with :math:`K = \mu\omega^2`, :math:`\mu/\alpha = m_C` (two-body reduction, alpha =
    m_D/(m_C + m_D)) whatever the damping (docs/towing.md, "A range-rate notch at the spin rate, and a thrust budget").

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        Read: ``mrac.tow_point_offset``, ``chaser.mass``, ``debris.spin_rate_deg_s`` (the tow's spin, the GNC's
        estimate).
    """
    delta = case.mrac.tow_point_offset
    if delta is None:
        return 0.0
    return case.chaser.mass * math.radians(case.debris.spin_rate_deg_s) ** 2 * delta


def governed_elongation(case, k_abstracted) -> float:
    r"""The elongation the laws are asked to hold (m): ``mrac.desired_elongation``, lowered where its steady thrust
    :math:`k z_d` would not leave the once-per-turn thrust (:func:`once_per_turn_thrust`) inside the actuator's upper
    bound: :math:`\min(z_d, (u_{max} - m_C\omega^2\delta) / k)`, a reference governor on the thrust budget. Without
    ``mrac.tow_point_offset``, or where the budget holds (Zenit-2: up to 23.5 deg/s for delta = 0.217 m), it is
    ``mrac.desired_elongation`` itself.

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        Read: ``mrac.desired_elongation``, ``mrac.max_thrust``, ``thrust.max_force`` and :func:`once_per_turn_thrust`'s.
    k_abstracted : float
        The abstracted model's tether stiffness (N/m), :func:`multibody.control.mrac.abstracted_tether`.

    Raises
    ------
    ValueError
        The once-per-turn thrust alone reaches the upper bound: no elongation leaves it room.
    """
    m = case.mrac
    u_max = case.thrust.max_force if m.max_thrust is None else m.max_thrust
    room = u_max - once_per_turn_thrust(case)
    if room <= 0.0:
        raise ValueError(f"mrac.tow_point_offset: the once-per-turn thrust m_C omega^2 delta = "
                         f"{once_per_turn_thrust(case):g} N at {case.debris.spin_rate_deg_s:g} deg/s reaches the "
                         f"upper thrust bound {u_max:g} N; no desired elongation leaves room for it")
    return min(m.desired_elongation, room / k_abstracted)
