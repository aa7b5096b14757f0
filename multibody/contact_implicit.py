"""A node's contact with one body surface over one step, implicit and node-local.

The sub-cycle of :func:`multibody.contact.contact_over_step` resolves a contact's oscillation
explicitly at 0.02 rad per sub-step (docs/model.md): about 50 sub-steps per node and step for a
7.7 g node held on a surface by taut threads (contact period about 0.6 ms at 1e-4 s steps), which
was 43 % of the reference case's step. Such resting contacts do not need their oscillation
resolved, only their impulse and energy: here one implicit step of the 1-D normal motion
(node against the body's effective mass along the normal) replaces the sub-cycle,

.. math::

    \\dot\\delta_1 = \\dot\\delta_0 - h\\, a_n - \\frac{h}{m_r} \\bar F,\\qquad
    \\delta_1 = \\delta_0 + \\frac{h}{2}(\\dot\\delta_0 + \\dot\\delta_1),\\qquad
    \\bar F = \\max\\Big(0,\\; \\frac{E(\\delta_1) - E(\\delta_0)}{\\delta_1 - \\delta_0}
               + d_n\\, \\bar\\delta^{\\,n} \\frac{\\delta_1 - \\delta_0}{h}\\Big)

with :math:`E(\\delta) = k\\delta^{n+1}/(n+1)` (Hertz energy, zero for a gap), :math:`\\bar\\delta` the
mean penetration (Hunt-Crossley damping, paper eq. (6)) and :math:`m_r` the reduced mass. The elastic
part is a discrete gradient (Gonzalez 1996, J. Nonlinear Sci. 6, eq. (3.3)): the step conserves
kinetic plus Hertz energy exactly, whatever the step, so a resting contact neither gains nor loses
energy numerically, and the penetration never exceeds what the energy allows. The damping's work
:math:`(\\bar F - \\text{secant})(\\delta_1 - \\delta_0)` is booked as dissipated, so the balance closes
to round-off. A few Newton iterations on :math:`\\delta_1` (safeguarded by bisection: the residual is
monotonic) solve it. Friction (Hollar, paper eq. (7)) acts once over the step against the slip it
would have without friction at mid-step, never reversing it; its work on the mean slip is booked.

Opt-in (``multibody.assembly.SolverSpec.implicit_contact_speed``, suggested :data:`IMPLICIT_CONTACT_SPEED`).
Fast approaches and rebounds keep the explicit sub-cycle: there the
Hunt-Crossley damping sets the restitution, which the sub-cycle reproduces within 0.5 %
(tests/multibody/test_contact.py).

Returns the same quantities as :func:`multibody.contact.contact_over_step` (trapezoidal: the contact's
mean velocity change over the step is half its end change).
"""
from __future__ import annotations

import math

from numba import njit

from multibody.contact import _power, hollar_friction_coefficient_inverse

#: Off by default (``SolverSpec.implicit_contact_speed = 0``, every contact sub-cycled): with this value
#: the reference case's results held (docs/model.md, Speed), but in the perception scenario
#: (cases/tang2023_debris_perception.toml, 3 s collision run) the net left the tumbling debris 0.2-0.4 s
#: later, leaving 6-8 LiDAR frames of free flight where tests/riskassess/stages/test_perceive.py needs 10 (the
#: sub-cycled run has 10-11: the margin is thin there too); not understood yet.
#: Suggested value, when switched on: below this normal relative speed (m/s) at the start of the step,
#: a node's single contact takes the implicit step. At 0.15 m/s the Hunt-Crossley restitution is 1 - (2/3) alpha v = 0.995 for the
#: paper's alpha = 0.05 s/m: the whole damping effect is 0.5 % of the speed, so an approximate
#: damping integral cannot move a rebound by more than a fraction of that, while resting contacts
#: (normal speeds of mm/s to cm/s) all take the cheap path.
IMPLICIT_CONTACT_SPEED = 0.15

#: Newton iterations on the end penetration; converged (residual 1e-12 of the step's speeds) within 2-6 in practice.
MAX_NEWTON_ITERATIONS = 40


@njit(cache=True, inline="always")
def _hertz_energy(penetration, stiffness, exponent):
    if penetration <= 0.0:
        return 0.0
    return stiffness * _power(penetration, exponent) * penetration / (exponent + 1.0)


@njit(cache=True, inline="always")
def _power_and_ratio(base, exponent):
    """``base ** exponent`` and ``base ** (exponent - 1)`` for ``base`` > 0; for the Hertz exponent 1.5 one
    square root and no division (the Newton residuals below need both, several times per contact and step)."""
    if exponent == 1.5:
        root = math.sqrt(base)
        return base * root, root
    power = base ** exponent
    return power, power / base


# the Newton residuals are inlined (numba IR): called 3-8 times per contact and step, the call
# overhead was a visible share of the implicit contact. Divisions by the step and the reduced mass are
# products with reciprocals formed once per contact (a division is 4-5 times the latency of a product,
# and the residual's chain is long): 276 -> 183 ns per normal solve on contacts recorded from the
# reference run (the results move at round-off, 1e-9 of the velocity change at most).
@njit(cache=True, inline="always")
def _normal_residual(d1, d0, p0, e0, rate0, accel_n, inv_step, step, step_over_mass, stiffness, exponent, damping):
    """Residual of the implicit normal step at end penetration d1 (m/s), its derivative (1/s), the
    mean contact force (N) and its non-conservative part (N).

    The elastic part is the discrete gradient (E(d1) - E(d0)) / (d1 - d0) of the Hertz energy (``p0``,
    ``e0``: the start penetration clipped at 0 and its energy), the midpoint force when d1 and d0 nearly
    agree (to O((d1 - d0)^2)). Its derivative for Newton is the secant's own, (E'(d1) - secant) / (d1 - d0),
    so Newton converges quadratically; the midpoint estimate (the derivative of the midpoint force) is kept
    where the midpoint force is. The midpoint estimate everywhere, used before, made Newton converge only
    linearly (by 1/10 to 1/50 an iteration) wherever d1 and d0 differ much: rebounds, a gap closing within
    the step. On 383 175 implicit contacts recorded from the reference run: 4.34 -> 2.82 residual
    evaluations a contact, the end state the same to the tolerance (docs/model.md, Speed). ``inv_step`` is
    1 / step, ``step_over_mass`` step / reduced mass.
    """
    p1 = d1 if d1 > 0.0 else 0.0
    scale = max(p0, p1)
    change = d1 - d0
    secant = 0.0
    slope = 0.0
    if scale > 0.0:
        if abs(change) <= 1e-7 * scale:
            pm = 0.5 * (p0 + p1)
            force_mid, ratio_mid = _power_and_ratio(pm, exponent)
            slope = 0.5 * exponent * stiffness * ratio_mid
            secant = stiffness * force_mid * ((p1 - p0) / change if change != 0.0 else 1.0)
        else:
            # E(p1) as _hertz_energy, with its power E'(p1) / k kept for the slope
            power1 = _power(p1, exponent) if p1 > 0.0 else 0.0
            energy1 = stiffness * power1 * p1 / (exponent + 1.0) if p1 > 0.0 else 0.0
            secant = (energy1 - e0) / change
            slope = (stiffness * power1 - secant) / change
    mean = 0.5 * (d0 + d1)
    viscous = 0.0
    viscous_slope = 0.0
    if mean > 0.0:
        dn, ratio = _power_and_ratio(mean, exponent)
        rate_mean = change * inv_step
        viscous = damping * dn * rate_mean
        viscous_slope = damping * (0.5 * exponent * ratio * rate_mean + dn * inv_step)
    force = secant + viscous
    derivative = 2.0 * inv_step
    if force > 0.0:
        derivative += step_over_mass * (slope + viscous_slope)
    else:
        force = 0.0
    residual = 2.0 * change * inv_step - 2.0 * rate0 + step * accel_n + step_over_mass * force
    return residual, derivative, force, force - secant


@njit(cache=True)
def implicit_normal_step(d0, rate0, accel_n, step, reduced_mass, stiffness, exponent, damping):
    """End penetration (m), mean normal contact force over the step (N) and its non-elastic part (N).

    Solves the module's equations for the end penetration by safeguarded Newton.

    Parameters
    ----------
    d0 : float
        Penetration at the start (m), negative for a gap.
    rate0 : float
        Its rate (m/s), positive approaching.
    accel_n : float
        Non-contact relative acceleration along the normal (m/s^2), positive away from the body.
    step : float
        (s).
    reduced_mass : float
        Node-body reduced mass along the normal (kg).
    stiffness, exponent, damping : float
        Hunt-Crossley :math:`k` (N/m^n), :math:`n` (-), :math:`d_n` (N s/m^(n+1)).
    """
    free = d0 + step * rate0 - 0.5 * step * step * accel_n  # no contact force: the upper bracket
    if d0 <= 0.0 and free <= 0.0:
        return free, 0.0, 0.0  # a gap at both ends: free flight (the end penetration is at most ``free``)
    inv_step = 1.0 / step
    step_over_mass = step / reduced_mass
    p0 = d0 if d0 > 0.0 else 0.0
    e0 = _hertz_energy(p0, stiffness, exponent)
    # The residual is increasing and convex in d1 (the secant of a convex energy): Newton from above the
    # root falls monotonically onto it; a bisection against a lower bracket guards the damping term's
    # departures from convexity. Start: the step linearized about the start penetration (tangent
    # stiffness and damping there), when it lies below the free-flight end (the upper bracket); else the
    # free-flight end. On the reference run's resting contacts this saves about one evaluation in six.
    hi = free
    lo = -math.inf
    d1 = free
    if p0 > 0.0:
        force0, ratio0 = _power_and_ratio(p0, exponent)
        tangent = 0.5 * exponent * stiffness * ratio0 + damping * force0 * inv_step
        guess = d0 + (2.0 * rate0 - step * accel_n - step_over_mass * stiffness * force0) / (
            2.0 * inv_step + step_over_mass * tangent)
        if guess < free:
            d1 = guess
    r, dr, force, extra = _normal_residual(d1, d0, p0, e0, rate0, accel_n, inv_step, step, step_over_mass, stiffness,
                                           exponent, damping)
    # residual in m/s: converged when the rate 2 (d1 - d0) / h - rate0 is good to 1e-12 of the step's speeds
    tolerance = 1e-12 * (abs(rate0) + abs(accel_n) * step + abs(d0) * inv_step) + 1e-300
    for _ in range(MAX_NEWTON_ITERATIONS):
        if r <= 0.0:
            lo = d1
            if r >= -tolerance:
                break
        else:
            hi = d1
            if r <= tolerance:
                break
        trial = d1 - r / dr
        if not (trial < hi and trial > lo):
            if lo == -math.inf:
                lo = _lower_bracket(d0, free, rate0, accel_n, step, reduced_mass, stiffness, exponent, damping)
            trial = 0.5 * (lo + hi)
        if trial == d1:
            break
        d1 = trial
        r, dr, force, extra = _normal_residual(d1, d0, p0, e0, rate0, accel_n, inv_step, step, step_over_mass,
                                               stiffness, exponent, damping)
    return d1, force, extra


@njit(cache=True)
def _lower_bracket(d0, free, rate0, accel_n, step, reduced_mass, stiffness, exponent, damping):
    """An end penetration whose residual is negative: a rebound cannot leave faster than the stored
    energy and the approach allow."""
    p0 = d0 if d0 > 0.0 else 0.0
    e0 = _hertz_energy(p0, stiffness, exponent)
    reach = step * (2.0 * abs(rate0) + math.sqrt(2.0 * e0 / reduced_mass) + 2.0 * abs(accel_n) * step) + 1e-12
    lo = min(d0, free) - reach
    while _normal_residual(lo, d0, p0, e0, rate0, accel_n, 1.0 / step, step, step / reduced_mass, stiffness,
                           exponent, damping)[0] > 0.0:
        reach *= 2.0
        lo = min(d0, free) - reach
    return lo


#: Iteration cap of the friction impulse's safeguarded Newton solve; it converges within 2-6 evaluations.
MAX_FRICTION_ITERATIONS = 60


@njit(cache=True, inline="always")
def _friction_residual(j, free_mid_slip, normal_impulse, half_inverse_mass, mu_static, mu_kinetic,
                       inverse_transition_speed):
    """j - mu(mean slip) N (N s) at friction impulse j, and its derivative with respect to j (-); the Hollar
    law and its slope (:func:`multibody.contact.hollar_friction_coefficient_and_slope`) with one division."""
    mean_slip = free_mid_slip - j * half_inverse_mass
    if mean_slip <= 0.0:
        mu_zero = hollar_friction_coefficient_inverse(0.0, mu_static, mu_kinetic, inverse_transition_speed)
        return j - mu_zero * normal_impulse, 1.0
    ratio = mean_slip * inverse_transition_speed
    inverse_denominator = 1.0 / (1.0 + ratio * ratio)
    drop = mu_static - mu_kinetic
    mu = mu_kinetic + 2.0 * drop * inverse_denominator
    mu_slope = -4.0 * drop * ratio * inverse_denominator * inverse_denominator  # d mu / d ratio
    if ratio < 1.0:
        mu, slope = ratio * mu, (mu + ratio * mu_slope) * inverse_transition_speed
    else:
        slope = mu_slope * inverse_transition_speed
    return j - mu * normal_impulse, 1.0 + slope * normal_impulse * half_inverse_mass


@njit(cache=True)
def friction_impulse(free_mid_slip, free_end_slip, normal_impulse, reduced_mass, mu_static, mu_kinetic,
                     transition_speed):
    """Friction impulse (N s) over one step, consistent with the slip it leaves.

    The Hollar coefficient is read at the step's mean slip *with* the friction acting: the impulse
    j slows the slip linearly over the step, so its mean is ``free_mid_slip - j / (2 m)``, and
    j = mu(mean slip) N h solves for it. Reading mu at the slip without friction overstated it in
    the regularised range (slip below ``transition_speed``), which made resting contacts stick: the
    net stayed on a tumbling target 0.3 s longer than the sub-cycle's (docs/model.md, "Contact").
    Friction may stop the slip within the step but never reverses it.

    The root is bracketed between 0 (residual -mu N < 0) and the impulse that stops the slip
    (residual > 0 when friction cannot stop it); Newton's iterates are kept inside the bracket and
    replaced by its midpoint when they leave it (Press et al., Numerical Recipes, 3rd ed., Sec. 9.4,
    ``rtsafe``). A plain bisection to round-off took 50 evaluations per sliding contact and step, half
    of the reference case's run time; this takes 3-8. Where mu falls steeply with the slip (above the
    transition speed, under a large normal impulse) the equation can have several roots; any of them
    is a slip consistent with its friction, and this returns one inside the bracket.

    Parameters
    ----------
    free_mid_slip, free_end_slip : float   Slip speed without friction at mid-step and end (m/s).
    normal_impulse : float                 Normal contact impulse over the step, N h (N s).
    reduced_mass : float                   Node-body reduced mass (kg).
    mu_static, mu_kinetic : float          Hollar's coefficients (-).
    transition_speed : float               Hollar's transition slip speed (m/s).
    """
    stop = reduced_mass * max(free_end_slip, 0.0)
    if stop <= 0.0:
        return 0.0
    inverse_transition_speed = 1.0 / transition_speed
    half_inverse_mass = 0.5 / reduced_mass
    mean_slip = max(free_mid_slip - stop * half_inverse_mass, 0.0)
    if stop <= hollar_friction_coefficient_inverse(mean_slip, mu_static, mu_kinetic,
                                                   inverse_transition_speed) * normal_impulse:
        return stop            # friction enough to stop the slip within the step
    lo, hi = 0.0, stop
    # start from the friction at the free slip, clipped into the bracket
    j = min(hollar_friction_coefficient_inverse(free_mid_slip, mu_static, mu_kinetic, inverse_transition_speed)
            * normal_impulse, 0.5 * stop)
    # 1e-13 of the impulse that stops the slip (4e-16, round-off, took one evaluation in four more:
    # 205-221 -> 171-177 ns a contact on the reference run's recorded contacts; the residual left is at
    # most 2.3e-13 of the stopping impulse on tests/multibody/test_contact_implicit.py's inputs)
    tolerance = 1e-13 * stop
    for _ in range(MAX_FRICTION_ITERATIONS):
        residual, derivative = _friction_residual(j, free_mid_slip, normal_impulse, half_inverse_mass, mu_static,
                                                  mu_kinetic, inverse_transition_speed)
        if residual == 0.0:
            return j
        if residual < 0.0:
            lo = j
        else:
            hi = j
        trial = j - residual / derivative if derivative > 0.0 else -1.0
        if derivative > 0.0 and abs(trial - j) <= tolerance:
            # Newton has converged. Its last step can round onto the bracket's end that j just became, which
            # the test below took for a step outside the bracket: it bisected from the far end instead, about
            # 40 more evaluations, on 4.5 % of the reference run's sliding contacts.
            return min(max(trial, lo), hi)
        if not (lo < trial < hi):
            trial = 0.5 * (lo + hi)  # Newton left the bracket (or mu falls too steeply): bisect
        if abs(trial - j) <= tolerance or hi - lo <= tolerance:
            return trial
        j = trial
    return 0.5 * (lo + hi)


@njit(cache=True, inline="always")
def contact_implicit_step(penetration, relative_velocity, normal, external_force, node_mass, body_mass, step,
                          stiffness, exponent, damping, mu_static, mu_kinetic, transition_speed, impulse):
    """One node's single contact over one step, implicit (module doc).

    Parameters
    ----------
    penetration : float
        :math:`\\delta_0` (m); negative for a gap.
    relative_velocity : (3,) float
        Node velocity minus the body's surface velocity at the node (m/s), global frame, at the start.
    normal : (3,) float
        Unit normal from the body to the node, global frame.
    external_force : (3,) float
        Non-contact force on the node (N), global frame, constant over the step.
    node_mass, body_mass : float
        (kg); ``body_mass`` the body's effective mass at the contact along the normal.
    step : float
        (s).
    impulse : (3,) float
        Output: the contact impulse on the node over the step (N s), global frame.

    Returns
    -------
    mean_x, mean_y, mean_z, end_x, end_y, end_z, dissipated
        As :func:`multibody.contact.contact_over_step`: the node's velocity change by contact,
        averaged over the step and at its end (m/s), and the energy dissipated (J).
    """
    mx, my, mz, ex, ey, ez, dissipated, jx, jy, jz = contact_implicit_step_xyz(
        penetration, relative_velocity[0], relative_velocity[1], relative_velocity[2], normal[0], normal[1], normal[2],
        external_force[0], external_force[1], external_force[2], node_mass, body_mass, step, stiffness, exponent,
        damping, mu_static, mu_kinetic, transition_speed)
    impulse[0], impulse[1], impulse[2] = jx, jy, jz
    return mx, my, mz, ex, ey, ez, dissipated


# in scalars, so the compiled contact pass hands over no array views: each view is a reference count taken
# and dropped per contact and step (numba's NRT_incref/decref were 6 % of the reference case's run)
@njit(cache=True, inline="always")
def contact_implicit_step_xyz(penetration, wx, wy, wz, nx, ny, nz, fx, fy, fz, node_mass, body_mass, step,
                              stiffness, exponent, damping, mu_static, mu_kinetic, transition_speed):
    """:func:`contact_implicit_step` with its vectors as components (relative velocity ``w`` (m/s), unit
    normal ``n``, non-contact force ``f`` (N), global frame); returns its seven values and then the
    impulse on the node over the step (3 components, N s, global frame)."""
    reduced_mass = node_mass * body_mass / (node_mass + body_mass)
    ax, ay, az = fx / node_mass, fy / node_mass, fz / node_mass
    w_n = wx * nx + wy * ny + wz * nz
    a_n = ax * nx + ay * ny + az * nz
    d1, force, extra = implicit_normal_step(penetration, -w_n, a_n, step, reduced_mass, stiffness, exponent, damping)
    dissipated = extra * (d1 - penetration)
    jx, jy, jz = force * step * nx, force * step * ny, force * step * nz
    if force > 0.0:
        # tangential slip at the start (m/s) and the change the non-contact force makes over the step
        gx, gy, gz = wx - w_n * nx, wy - w_n * ny, wz - w_n * nz
        tx, ty, tz = step * (ax - a_n * nx), step * (ay - a_n * ny), step * (az - a_n * nz)
        # friction acts against the slip it would have at mid-step without friction
        mx, my, mz = gx + 0.5 * tx, gy + 0.5 * ty, gz + 0.5 * tz
        slip = math.sqrt(mx * mx + my * my + mz * mz)
        if slip > 0.0:
            ux, uy, uz = mx / slip, my / slip, mz / slip
            start = gx * ux + gy * uy + gz * uz
            end_free = start + tx * ux + ty * uy + tz * uz
            j_t = friction_impulse(slip, end_free, force * step, reduced_mass, mu_static, mu_kinetic, transition_speed)
            jx -= j_t * ux
            jy -= j_t * uy
            jz -= j_t * uz
            # its work on the step's mean slip (trapezoid, as the drift): booked as dissipated
            dissipated += j_t * max(0.5 * (start + end_free - j_t / reduced_mass), 0.0)
    ex, ey, ez = jx / node_mass, jy / node_mass, jz / node_mass
    return 0.5 * ex, 0.5 * ey, 0.5 * ez, ex, ey, ez, dissipated, jx, jy, jz
