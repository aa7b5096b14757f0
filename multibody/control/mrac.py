"""Model-reference adaptive control of the main-tether elongation (MRAC-1 eqs. 9-16 and MRAC-2
eqs. 17-21 of the MRAC tether-control seed paper, ``towing-mrac-tether-control``).

Both laws see the chaser as a single-DoF mass on the main tether (abstracted model, eq. 9):

.. math:: \\ddot z + b\\,(c_{MT}\\dot z + k_{MT} z)\\,g(z, \\dot z) = b F_t,\\qquad b = 1/m_C

with :math:`g = 1` while the tether pulls (:func:`multibody.net.tension_only_kelvin_voigt` > 0)
and 0 otherwise. Both follow the reference model of eq. (13), a PD-controlled copy of that
mass with saturated force. The adaptive states are integrated with the controller's sampling
step (forward Euler, the controller is digital with zero-order hold) and frozen while the
command saturates (the :math:`H(u_{max}-|u|)` factor of eqs. 15 and 20).

**Breathing notch** (``mrac.breathing_notch``). On the full net the netted stage, tumbling in the bag, presents its
outline twice per revolution: the main-tether elongation breathes at twice the spin rate (79-82 % of its variance
under constant thrust, docs/towing.md). With the notch on, both laws see the elongation through
:func:`breathing_notch` (a second-order digital notch whose zeros sit exactly on :math:`2\\omega_{spin}`; unit gain at
zero frequency), so they neither chase that periodic swing nor adapt on it; the rate estimate below is then the
difference quotient of the notched elongation. The spin rate is the tow's (the GNC's estimate from perception,
``debris.spin_rate_deg_s`` or the rate the run is made at) unless ``mrac.notch_frequency`` states the frequency.

**Measured elongation rate.** Both laws take :math:`\\dot z` from :func:`elongation_rate_estimate`: with
``RATE_TAU`` > 0 the band-limited difference quotient of the sampled elongation (a first-order
"dirty derivative", time constant tau), with 0 the plant's instantaneous rate. On the full-net plant
the tether's far end is the net's central node (9.5 g on Kevlar threads of ~35 kN/m): its velocity
vibrates far above the control band, and the instantaneous rate sampled every step is that vibration
aliased (measured: standard deviation 0.06-0.14 m/s at 2 ms samples while the elongation moves by
millimetres per second), which the laws' rate gains (k_s, K_D ~ 2-5 kN s/m) turn into +-u_max
chattering. tau is set one decade above the reference model's natural frequency
:math:`\\omega_m = \\sqrt{b (k_{MT} + K_P)}` (:func:`rate_filter_time`), so the reference dynamics
pass with < 6 deg of phase lag.

**Range-rate damping** (``mrac.range_damping``, :func:`range_damping_force`). On the full net the chaser hangs on the
main tether in series with the net bag; the laws' rate gain acts on the tether's elongation rate, which the bag's
compliance and the central node's vibration dominate, so the chaser-bag mode, which the breathing drives near
resonance at 20.44 deg/s, is damped weakly and through a saturating channel. Both laws may add :math:`-c_R \dot r`,
:math:`\dot r` the chaser-debris range rate (zero in steady towing); with it the rate estimate's corner can sit at
:math:`\omega_m` (docs/towing.md, MRAC: "Why the taut-phase swing grows at 20.44 deg/s").

**Range-rate notch at the spin rate** (``mrac.range_notch``, :func:`range_rate_seen`). The Zenit-2 stage's CoM sits
0.217 m off the middle of its cylinder, so the bag's tow point moves relative to the CoM once per turn: the range rate
carries a line at :math:`\omega_{spin}` (docs/towing.md, "What grows the swing at 29.01 deg/s"). That line is a
forced motion of the tow point, not the chaser-bag mode the range damping is there for; damping it costs thrust at
:math:`\omega_{spin}` (:math:`c_R \omega |\dot r|`-sized, the larger part of the thrust swing at 29.01 deg/s) and pulls
on the tether once per turn. With the notch on, the range damping acts on the range rate through a second-order notch
at the spin rate (the GNC's estimate, as for the breathing notch): it leaves the once-per-turn line to the laws'
elongation feedback and damps every other frequency as before. Measured on the full net (docs/towing.md, "A range-rate
notch at the spin rate, and a thrust budget"): it does not hold 29.01 deg/s (MRAC-2 fails, MRAC-1 holds in 1 of 3
replicas) and breaks 20.44 deg/s, so it is off in the shipped case.

**Once-per-turn thrust budget** (``mrac.tow_point_offset``,
:func:`multibody.control.thrust_budget.governed_elongation`): the desired elongation is
lowered where its steady thrust would not leave the once-per-turn thrust :math:`m_C\omega^2\delta` below u_max.
Measured: with 87-89 N of headroom at 29.01 deg/s the once-per-turn line still grows and both laws fail (2 + 2
replicas); off in the shipped case.

This module holds what both laws share (parameter head, reference model); each law is a plug-in of
:mod:`multibody.control.thrust_laws` (``mrac1.py``, ``mrac2.py``: its gains, ``command``, initial
state); ``params`` and ``state`` are flat float arrays for the compiled towing kernels, the common
interface is described in :mod:`multibody.control.thrust`.
"""
from __future__ import annotations

from numba import njit

from multibody.control.notch import notch_frequency, notch_output, range_notch_frequency, shift_notch
from multibody.control.thrust_budget import governed_elongation

# params indices common to both laws; each law appends its gains (thrust_laws/mrac1.py, mrac2.py)
(T_ON, U_MAX, B, K_MT, C_MT, Z_D, K_P, K_D, RATE_TAU, U_MIN, Z_SLACK, F_STEADY, NOTCH_W, NOTCH_SIGMA,
 HOLD_TIME, C_RANGE, RANGE_NOTCH_W, RANGE_NOTCH_SIGMA) = range(18)
N_COMMON = 18
# state: reference model z_m, z_m rate, the rate estimate's last elongation and last rate, the breathing notch's last
# two inputs and outputs, the time of the last slack sample, the range-rate notch's last two inputs and outputs, then
# adaptive parameters
(ZM, ZM_RATE, Z_LAST, RATE_LAST, NOTCH_X1, NOTCH_X2, NOTCH_Y1, NOTCH_Y2, SLACK_AT, RANGE_X1, RANGE_X2, RANGE_Y1,
 RANGE_Y2, A0) = range(14)
NEVER = -1e30   # SLACK_AT before any slack sample (s)


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


def rate_filter_time(k_mt, k_p, chaser_mass, decades=1.0) -> float:
    """Time constant (s) of the elongation-rate estimate that puts its corner ``decades`` above the
    reference model's natural frequency :math:`\\omega_m = \\sqrt{(k_{MT} + K_P)/m_C}` (eq. 13 taut):
    :math:`\\tau = 10^{-decades}/\\omega_m`; the phase lag at :math:`\\omega_m` is
    :math:`\\arctan(\\omega_m\\tau)` (5.7 deg for one decade).

    Parameters
    ----------
    k_mt, k_p : float
        Main-tether stiffness and reference-model proportional gain (N/m).
    chaser_mass : float
        m_C (kg).
    decades : float
        Separation of the corner from omega_m (decades).
    """
    return 10.0 ** (-decades) / (((k_mt + k_p) / chaser_mass) ** 0.5)


def abstracted_tether(case, tether) -> tuple[float, float]:
    """Stiffness (N/m) and damping (N s/m) of the main tether as the abstracted model (eq. 9) sees it.

    The paper's assumption (iv), m_C << m_D, fixes the tether's far end (a wall). Our chaser is
    1600 kg against 9000 kg (m_C/m_D = 0.18): the far end accelerates with the debris, and the
    elongation of two free masses on a tether obeys
    :math:`\\ddot z = F_t/m_C - (1/m_C + 1/m_D)\\,T`, i.e. eq. (9) with the tether terms scaled by
    :math:`1 + m_C/m_D`. With ``mrac.free_debris`` that scaled tether is the model (reference model,
    the laws' ideal parameters, eq. 21a); in steady towing it puts the thrust at
    :math:`F_t = (1 + m_C/m_D)\\,k_{MT} z` (the debris takes its share of the acceleration), where the wall
    model predicts :math:`k_{MT} z`: 18 % too little thrust, which only the adaptation can make up.
    Without it, the paper's wall (the tether as given).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The towing case (read: ``mrac.free_debris``, ``chaser.mass``, ``debris.nominal_mass``).
    tether : (>= 2,) float
        k_MT (N/m), c_MT (N s/m), ... of the model's main tether.
    """
    scale = 1.0 + case.chaser.mass / case.debris.nominal_mass if case.mrac.free_debris else 1.0
    return scale * float(tether[0]), scale * float(tether[1])


def common_params(case, tether) -> list:
    """The parameters both laws share (indices ``T_ON`` ... ``U_MIN``) from a towing case (``thrust``,
    ``mrac``, ``chaser.mass``, ``main_tether.stiffness``) and its main tether ``tether`` = [k_MT (N/m),
    c_MT (N s/m), ...]: thrust-on time (s), saturation u_max (N; :func:`actuator_range`), b = 1/m_C (1/kg),
    k_MT, c_MT,
    z_d (m), K_P (N/m), K_D (N s/m), the rate estimate's time constant (s, 0: the measured rate), the
    saturation's lower bound u_min (N; :func:`actuator_range`, default -u_max: the paper's symmetric sat), the
    slack threshold (m; ``mrac.slack_elongation``, -1: off) and the steady thrust (N; :func:`steady_thrust`), which
    :func:`slack_hold` commands below that threshold, the range damping c_R (N s/m; ``mrac.range_damping``,
    :func:`range_damping_force`) and its notch's centre (rad/s, 0: off;
    :func:`multibody.control.notch.range_notch_frequency`) and pole decay
    rate (1/s).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The towing case (read: ``thrust``, ``mrac``, ``chaser.mass``, ``main_tether.stiffness``).
    tether : (>= 2,) float
        k_MT (N/m), c_MT (N s/m), ... of the model's main tether.
    """
    th, m = case.thrust, case.mrac
    k_mt, c_mt = abstracted_tether(case, tether)
    desired = governed_elongation(case, k_mt)
    z_d = command_elongation(desired, k_mt, m.k_p, m.settle_at_desired)
    f_steady = steady_thrust(k_mt, desired)
    u_min, u_max = actuator_range(case, f_steady)
    z_slack = -1.0 if m.slack_elongation is None else m.slack_elongation
    omega_notch = notch_frequency(case)
    omega_range = range_notch_frequency(case)
    return [th.t_on, u_max, 1.0 / case.chaser.mass, k_mt, c_mt, z_d, m.k_p, m.k_d,
            m.rate_filter_time, u_min, z_slack, f_steady, omega_notch, omega_notch / (2.0 * m.notch_quality),
            hold_time(case), m.range_damping, omega_range, omega_range / (2.0 * m.range_notch_quality)]


def hold_time(case) -> float:
    """How long the slack hold lasts after the last slack sample (s): ``mrac.slack_hold_periods`` breathing periods,
    a breathing period being half a spin period, :math:`\\pi / \\omega_{spin}` (the net breathes at twice the spin;
    ``debris.spin_rate_deg_s``, which the model builders set to the rate the run is made at); 0 without it (the hold
    lasts only while the elongation reads slack).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        Read: ``mrac.slack_hold_periods``, ``debris.spin_rate_deg_s``.

    Raises
    ------
    ValueError
        Periods are asked for and the debris does not spin.
    """
    periods = case.mrac.slack_hold_periods
    if periods == 0.0:
        return 0.0
    if case.debris.spin_rate_deg_s <= 0.0:
        raise ValueError("mrac.slack_hold_periods counts breathing periods (half a spin period), but the debris does "
                         "not spin (debris.spin_rate_deg_s = 0); set mrac.slack_hold_periods = 0")
    return periods * 180.0 / case.debris.spin_rate_deg_s


def steady_thrust(k_abstracted, desired) -> float:
    """Thrust (N) that holds the abstracted model at the desired elongation in steady towing: the tether force
    :math:`k z_d` with the abstracted stiffness (with ``mrac.free_debris``, :math:`(1 + m_C/m_D) k_{MT} z_d`: the
    chaser pulls its own share of the common acceleration too).

    Parameters
    ----------
    k_abstracted : float
        The abstracted model's tether stiffness (N/m), :func:`abstracted_tether`.
    desired : float
        Desired elongation (m).
    """
    return k_abstracted * desired


def actuator_range(case, f_steady) -> tuple[float, float]:
    """[u_min, u_max] (N) of sat(u), eq. (16): with ``mrac.thrust_band`` = beta the band
    :math:`[(1-\\beta) F_{ss}, (1+\\beta) F_{ss}]` about the steady thrust ``f_steady`` (clipped to
    +-``thrust.max_force``); otherwise ``mrac.min_thrust`` / ``mrac.max_thrust``, each defaulting to the paper's
    symmetric saturation -+``thrust.max_force``.

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        Read: ``thrust.max_force``, ``mrac.thrust_band``, ``mrac.min_thrust``, ``mrac.max_thrust``.
    f_steady : float
        Steady thrust (N), :func:`steady_thrust`.
    """
    f_max, m = case.thrust.max_force, case.mrac
    if m.thrust_band is not None:
        return max(-f_max, (1.0 - m.thrust_band) * f_steady), min(f_max, (1.0 + m.thrust_band) * f_steady)
    return (-f_max if m.min_thrust is None else m.min_thrust), (f_max if m.max_thrust is None else m.max_thrust)


def initial_state(z0, z_rate0) -> list:
    """The shared head of a law's state: reference model on the measured state (z0 (m), z_rate0 (m/s)),
    the rate estimate and the breathing notch started on it (the notch at rest on z0: its output is z0), no slack
    sample yet, the range-rate notch at rest on a zero range rate (the chaser and the debris start co-moving).

    Parameters
    ----------
    z0, z_rate0 : float
        Elongation (m) and its rate (m/s) at the start.
    """
    return [z0, z_rate0, z0, z_rate0, z0, z0, z0, z0, NEVER, 0.0, 0.0, 0.0, 0.0]


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
def range_damping_force(params, range_rate):
    """The range-rate damping both laws add to their command (N): :math:`-c_R \dot r`, with :math:`\dot r` the rate
    of the chaser-debris CoM distance (m/s, > 0 separating) and c_R = ``params[C_RANGE]`` (``mrac.range_damping``;
    0: the paper's laws).

    On the netted plant the chaser hangs on the main tether in series with the net bag, whose dynamic stiffness is
    some 300-1100 N/m against the tether's 3000 N/m (docs/towing.md): the laws' rate gain acts on the main tether's
    elongation rate, i.e. on the tension rate, which the bag's compliance and the central node's vibration dominate,
    so it damps the chaser-bag mode only weakly and through a channel that chatters at the saturation. The mode
    itself is the chaser moving against the debris; a force against the range rate damps it directly and vanishes
    in steady towing (both bodies then share the acceleration, :math:`\dot r = 0`), so the laws' static balance and
    their reference model are unchanged.

    Parameters
    ----------
    params : (k,) float
        The law's parameters (``C_RANGE`` used).
    range_rate : float
        Chaser-debris range rate (m/s), :func:`multibody.control.thrust.range_rate`.
    """
    return -params[C_RANGE] * range_rate


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
    pd = saturated(pd, params)
    return -b * (k * zm + c * zm_rate) * pulling(zm, zm_rate, k, c) + b * pd


@njit(cache=True)
def saturated(u, params):
    """The actuator's saturation, :math:`\\mathrm{sat}(u)` of eq. (16) (N): u clipped to [u_min, u_max]
    (the paper: u_min = -u_max; ``mrac.min_thrust`` sets a floor, e.g. 0 for a main engine that cannot
    push the chaser back towards the debris).

    Parameters
    ----------
    u : float
        Pre-saturation command (N).
    params : (k,) float
        The law's parameters (``U_MIN``, ``U_MAX`` used).
    """
    return min(max(u, params[U_MIN]), params[U_MAX])


@njit(cache=True)
def adapting(u, params):
    """:math:`H(u_{max} - |u|)` of eqs. (15) and (20) for the actuator's range [u_min, u_max]: True while the
    command is inside it (the adaptation is frozen while the command saturates).

    Parameters
    ----------
    u : float
        Pre-saturation command (N).
    params : (k,) float
        The law's parameters (``U_MIN``, ``U_MAX`` used).
    """
    return params[U_MIN] < u < params[U_MAX]


@njit(cache=True)
def slack_hold(t, z, params, state, advance):
    """True while the law holds the steady thrust ``params[F_STEADY]`` without adapting: the measured elongation ``z``
    (m) is below the slack threshold ``params[Z_SLACK]``, or was within the last ``params[HOLD_TIME]`` seconds.

    On the full net a slack main tether reads z ~ 0 whatever the distance to the debris (the central node hangs at
    the tether's natural length), and the re-engagement that follows is a snap through the net, not the abstracted
    model's spring: while slack and until the tether has pulled again for HOLD_TIME (``mrac.slack_hold_periods``
    breathing periods), the elongation says nothing the laws' model can use, and their own reactions to it (MRAC-2:
    K_P z_cmd, 181 N while slack, then -30 N during the snap; MRAC-1: k_s lambda_0 (z_m - z), 84 N) drive the
    slack-and-snap cycle (docs/towing.md, MRAC on the full net). The threshold -1 (the default) never holds.

    Parameters
    ----------
    t : float
        Time (s).
    z : float
        Measured elongation (m), before any filter.
    params : (k,) float
        The law's parameters (``Z_SLACK``, ``HOLD_TIME`` used).
    state : (j,) float
        The law's state (``SLACK_AT``: time of the last slack sample (s), written when ``advance``).
    advance : bool
        A new sample (record it).
    """
    if z < params[Z_SLACK]:
        if advance:
            state[SLACK_AT] = t
        return True
    return t - state[SLACK_AT] < params[HOLD_TIME]


@njit(cache=True)
def actuate(u, hold, params):
    """The thrust a law delivers for its command ``u`` (N), and whether it adapts: sat(u) of eq. (16) and the
    :math:`H(\\cdot)` of eqs. (15) and (20), or, under the slack hold (``hold``, :func:`slack_hold`), the steady
    thrust without adaptation.

    Parameters
    ----------
    u : float
        Pre-saturation command (N).
    hold : bool
        The slack hold is on (:func:`slack_hold`).
    params : (k,) float
        The law's parameters (``U_MIN``, ``U_MAX``, ``F_STEADY`` used).

    Returns
    -------
    force : float
        Thrust (N).
    adapt : bool
        Advance the adaptive parameters.
    """
    if hold:
        return params[F_STEADY], False
    return saturated(u, params), adapting(u, params)


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


@njit(cache=True)
def elongation_rate_estimate(params, state, z, z_rate, step):
    """The elongation rate the laws use (m/s): with ``params[RATE_TAU]`` = tau > 0 the band-limited
    difference quotient of the sampled elongation (backward-Euler "dirty derivative",
    :math:`r_k = (\\tau r_{k-1} + z_k - z_{k-1})/(\\tau + h)`: exact for a ramp, first-order low-pass
    of the true rate with corner 1/tau), with tau = 0 the measured ``z_rate`` itself.

    Parameters
    ----------
    params : (k,) float
        The law's parameters (``RATE_TAU`` used).
    state : (j,) float
        The law's state (``Z_LAST``, ``RATE_LAST`` read; :func:`store_rate` writes them).
    z, z_rate : float
        Measured elongation (m) and instantaneous rate (m/s).
    step : float
        Sampling step (s).
    """
    tau = params[RATE_TAU]
    if tau <= 0.0:
        return z_rate
    return (tau * state[RATE_LAST] + (z - state[Z_LAST])) / (tau + step)


@njit(cache=True)
def store_rate(state, z, rate):
    """Keep this sample's elongation (m) and rate estimate (m/s) for the next one.

    Parameters
    ----------
    state : (j,) float
        The law's state, ``Z_LAST`` and ``RATE_LAST`` written.
    z, rate : float
        Elongation (m) and rate estimate (m/s).
    """
    state[Z_LAST] = z
    state[RATE_LAST] = rate


@njit(cache=True)
def breathing_notch(params, state, z, step):
    """The elongation the laws see (m): ``z`` through the notch at ``params[NOTCH_W]``
    (:func:`multibody.control.notch.notch_coefficients`),
    or ``z`` itself with the notch off (``NOTCH_W`` = 0). The notch's past samples are read from ``state``;
    :func:`store_notch` writes this sample's.

    Parameters
    ----------
    params : (k,) float
        The law's parameters (``NOTCH_W``, ``NOTCH_SIGMA`` used).
    state : (j,) float
        The law's state (``NOTCH_X1`` ... ``NOTCH_Y2`` read).
    z : float
        Measured elongation (m).
    step : float
        Sampling step (s).
    """
    if params[NOTCH_W] <= 0.0:
        return z
    return notch_output(params[NOTCH_W], params[NOTCH_SIGMA], state, NOTCH_X1, z, step)


@njit(cache=True)
def store_notch(state, z, z_seen):
    """Shift the notch's memory by one sample: input ``z`` and output ``z_seen`` (m) become the last ones.

    Parameters
    ----------
    state : (j,) float
        The law's state, ``NOTCH_X1`` ... ``NOTCH_Y2`` written.
    z, z_seen : float
        This sample's measured and notched elongation (m).
    """
    shift_notch(state, NOTCH_X1, z, z_seen)


@njit(cache=True)
def law_measurement(params, state, z, z_rate, step, advance):
    """The elongation (m) and elongation rate (m/s) both laws act on: the measured ones, or with the breathing notch
    on (``params[NOTCH_W]`` > 0) the notched elongation (:func:`breathing_notch`) and the band-limited difference
    quotient of it (:func:`elongation_rate_estimate`; the plant's instantaneous rate is not notched, so the case
    check asks for ``mrac.rate_filter_time`` > 0 with the notch). The filters' memories advance when ``advance``.

    Parameters
    ----------
    params : (k,) float
        The law's parameters (``NOTCH_W``, ``NOTCH_SIGMA``, ``RATE_TAU`` used).
    state : (j,) float
        The law's state (notch and rate-estimate memories).
    z, z_rate : float
        Measured elongation (m) and instantaneous rate (m/s).
    step : float
        Sampling step (s).
    advance : bool
        Advance the memories (a new sample).

    Returns
    -------
    z_seen, rate : float
        Elongation (m) and rate (m/s) for the law.
    """
    z_seen = breathing_notch(params, state, z, step)
    rate = elongation_rate_estimate(params, state, z_seen, z_rate, step)
    if advance:
        if params[NOTCH_W] > 0.0:
            store_notch(state, z, z_seen)
        store_rate(state, z_seen, rate)
    return z_seen, rate


@njit(cache=True)
def range_rate_seen(params, state, range_rate, step, advance):
    """The range rate the range damping acts on (m/s): the measured one, or with the range-rate notch on
    (``params[RANGE_NOTCH_W]`` > 0, ``mrac.range_notch``) the measured one through a notch at the spin rate
    (:func:`multibody.control.notch.notch_output`, :func:`~multibody.control.notch.notch_coefficients`): the once-per-turn
    line of the tow point is removed, every
    other frequency passes (unit gain at zero frequency and, within the pole decay rate, far from the notch). The
    notch's memory advances when ``advance``, also before thrust-on, so its start transient (decaying as
    :math:`e^{-\sigma t}`) is over when the range damping comes in.

    .. math:: \dot r_{seen} = H(z)\,\dot r,\qquad H(e^{j\omega_{spin} h}) = 0

    Parameters
    ----------
    params : (k,) float
        The law's parameters (``RANGE_NOTCH_W``, ``RANGE_NOTCH_SIGMA`` used).
    state : (j,) float
        The law's state (``RANGE_X1`` ... ``RANGE_Y2``: the notch's memory).
    range_rate : float
        Measured chaser-debris range rate (m/s), :func:`multibody.control.thrust.range_rate`.
    step : float
        Sampling step (s).
    advance : bool
        A new sample (shift the memory).
    """
    if params[RANGE_NOTCH_W] <= 0.0:
        return range_rate
    seen = notch_output(params[RANGE_NOTCH_W], params[RANGE_NOTCH_SIGMA], state, RANGE_X1, range_rate, step)
    if advance:
        shift_notch(state, RANGE_X1, range_rate, seen)
    return seen
