"""``hinge_coulomb_friction``: dry friction in the hinge that slides AND sticks (issue 24 item 4).

Coulomb's law with stiction: while the hinge slides the friction torque is :math:`-T_c\\,
\\mathrm{sign}(\\dot\\theta)`; once the hinge stops it stays stuck as long as the torque that
holds it there is within the break-away limit :math:`T_c` (static = kinetic limit here), and
breaks away when that torque exceeds it. The switch is written as one continuous law, a
saturated "stick" controller:

.. math:: \\tau_f = \\mathrm{clip}\\big(k\\,\\theta - c_s\\,\\dot\\theta - k_s(\\theta - \\theta_a),\\; -T_c,\\; T_c\\big)

* sliding (the clipped argument beyond :math:`\\pm T_c`): :math:`\\tau_f = \\mp T_c`, Coulomb's law;
* sticking: :math:`\\tau_f` cancels the hinge spring :math:`-k\\theta` exactly (the torque that
  holds the panel, within the limit) and adds a stiff, critically damped hold (:math:`c_s`,
  :math:`k_s` about the stick anchor :math:`\\theta_a`) that brings the rate to zero in :math:`1/\\lambda_s` and keeps it there (see below). The stuck hinge does not
  creep under its spring, unlike a tanh regularisation (the former law, tanh(rate / 0.01 rad/s),
  crept at rates comparable to a slowly moving panel's and could not stick).

The stick rate :math:`\\lambda_s = c_s / J_{eff}` is ``STICK_RATE_PER_MOTION_RATE`` times the
plant's fastest motion rate, so the transition from sliding to sticking lasts about a
thousandth of a period; the fit's RK4 step is shortened by :meth:`stiffness_rate` so that the stiff term is
integrated stably (the Exudyn reference's explicit RK4 step, 4 ms, keeps lambda_s h < 2.78 for motion rates up
to 7 rad/s).
Torques on the hinge other than the spring (coupling to the main body's rotation) are held by a
critically damped hold about a stick anchor (the effect's own state ``ANCHOR``, one slot of the
fast model starting at the initial hinge angle, that follows the hinge while it slides and stays
where it stopped), up to the break-away limit; without the anchor the stuck panel crept under the tumble's coupling torques by ~3e-3 rad in 50 s. Checked against the analytic stick-slip
ring-down in tests/riskassess/diagnosis/test_stiction.py.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE, E_K, L_TH, X_TH, X_THD
from riskassess.diagnosis.effects.base import Effect, Parameter, torque_scale
from riskassess.diagnosis.plants.plant import Plant

#: The effect's own state (fast model): the stick anchor theta_a (rad).
ANCHOR, STATES = 0, 1

#: Stick rate lambda_s (1/s) per fastest motion rate (rad/s) of the plant: the stick transient lasts
#: 1/(100 omega), 1/600 of a period. Measured against an independent elasto-plastic (bristle) stiction
#: law on the sample hinged case (60 s, tumbling body): 30 leaves 1.0 sigma RMS in omega_x and the
#: residual is not white, 100 leaves 0.57 sigma, 300 0.55 (the reference's own bristle dynamics), so
#: 100 is converged. Cost: the fit's RK4 step is 1.5/lambda_s = 0.015/omega instead of 0.1/omega.
STICK_RATE_PER_MOTION_RATE = 100.0


@njit(cache=True)
def holding_torque(angle, rate, anchor, stiffness, stick_damping, stick_stiffness):
    """Torque (N m) that would hold the hinge at its stick ``anchor`` (rad): it cancels the hinge
    spring ``stiffness`` (N m/rad) at ``angle`` (rad) and adds a critically damped hold, the
    ``stick_damping`` (N m s/rad) on the ``rate`` (rad/s) and the ``stick_stiffness`` (N m/rad)
    towards the anchor.

    Parameters
    ----------
    angle : float
        Hinge angle theta (rad).
    rate : float
        Hinge rate theta' (rad/s).
    anchor : float
        Stick anchor theta_a (rad).
    stiffness : float
        The case's torsional spring k (N m/rad).
    stick_damping : float
        c_s (N m s/rad).
    stick_stiffness : float
        k_s (N m/rad).

    Returns
    -------
    hold : float
        k theta - c_s theta' - k_s (theta - theta_a), about the hinge axis (N m).
    """
    return stiffness * angle - stick_damping * rate - stick_stiffness * (angle - anchor)


@njit(cache=True)
def friction_torque(hold, friction):
    """Friction torque (N m): the holding torque ``hold`` (N m) within the Coulomb limit ``friction``
    (N m); at the limit the hinge slides with -+T_c.

    Parameters
    ----------
    hold : float
        Holding torque (N m), :func:`holding_torque`.
    friction : float
        Coulomb limit T_c (N m), >= 0.

    Returns
    -------
    torque : float
        clip(hold, -T_c, T_c), on the appendage about the hinge axis (N m).
    """
    return min(max(hold, -friction), friction)


@njit(cache=True)
def anchor_rate(angle, anchor, hold, friction, follow_rate):
    """d anchor / dt (rad/s): fixed while the hinge sticks (|hold| < T_c), following the sliding hinge
    at ``follow_rate`` (1/s) so that it is at the angle where the hinge stops.

    Parameters
    ----------
    angle : float
        Hinge angle (rad).
    anchor : float
        Stick anchor (rad).
    hold : float
        Holding torque (N m), :func:`holding_torque`.
    friction : float
        Coulomb limit T_c (N m).
    follow_rate : float
        Rate at which the anchor follows a sliding hinge (1/s).

    Returns
    -------
    rate : float
        (rad/s).
    """
    return 0.0 if abs(hold) < friction else follow_rate * (angle - anchor)


def stick_rate(plant: Plant) -> float:
    """lambda_s (1/s): the stuck hinge's double decay rate x 2 and the anchor's follow rate.

    Parameters
    ----------
    plant : Plant
        A hinged plant; its fastest motion rate (rad/s) sets lambda_s.

    Returns
    -------
    rate : float
        ``STICK_RATE_PER_MOTION_RATE`` times the plant's rate scale (1/s).
    """
    return STICK_RATE_PER_MOTION_RATE * plant.rate_scale()


def stick_gains(plant: Plant) -> tuple[float, float]:
    """(c_s (N m s/rad), k_s (N m/rad)): the stuck hinge J theta'' = -c_s theta' - k_s (theta - anchor)
    is critically damped with its double root at -lambda_s / 2 (J: hinge mode with the body free).

    Parameters
    ----------
    plant : Plant
        A hinged plant (effective hinge inertia J, kg m^2).

    Returns
    -------
    stick_damping, stick_stiffness : float
        c_s = lambda_s J (N m s/rad), k_s = lambda_s^2 J / 4 (N m/rad).
    """
    rate, inertia = stick_rate(plant), plant.effective_hinge_inertia()
    return rate * inertia, 0.25 * rate ** 2 * inertia


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load, xe, xe_rate):
    """Coulomb friction with stiction on the hinge, and the stick anchor's rate.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (4,) float
        [T_c (N m), c_s (N m s/rad), k_s (N m/rad), anchor follow rate (1/s)]
        (:meth:`HingeCoulombFriction.law_parameters`).
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: the hinge torque (``L_TH``, N m, about the axis).
    xe : (1,) float
        The stick anchor theta_a (``ANCHOR``, rad).
    xe_rate : (1,) float
        The anchor's rate (rad/s), added to in place.
    """
    hold = holding_torque(x[X_TH], x[X_THD], xe[ANCHOR], env[E_K], p[1], p[2])
    load[L_TH] += friction_torque(hold, p[0])
    xe_rate[ANCHOR] += anchor_rate(x[X_TH], xe[ANCHOR], hold, p[0], p[3])


class _StickAnchor:
    """The anchor state on the Exudyn path: a hinge-torque user function that integrates
    :func:`anchor_rate` (explicit Euler over the solver's successive call times; the solver's 4 ms
    step is 1/20 of 1/lambda_s or less for rates up to 0.6 rad/s)."""

    def __init__(self, friction, plant: Plant):
        self.friction, self.stiffness = friction, plant.stiffness
        self.damping, self.hold_stiffness = stick_gains(plant)
        self.follow = stick_rate(plant)
        self.anchor, self.time = plant.hinge_angle0, 0.0

    def __call__(self, t, angle, rate):
        hold = holding_torque(angle, rate, self.anchor, self.stiffness, self.damping, self.hold_stiffness)
        if t > self.time:
            self.anchor += (t - self.time) * anchor_rate(angle, self.anchor, hold, self.friction, self.follow)
            self.time = t
        return friction_torque(hold, self.friction)


class HingeCoulombFriction(Effect):
    id = "hinge_coulomb_friction"
    extra_states = STATES
    title = "Coulomb (dry) friction in the hinge, sliding and sticking"
    scenarios = ("hinged_appendage",)
    channels = ("hinge_angle", "hinge_rate", "omega_x", "omega_y", "omega_z", "q_w")
    law = staticmethod(law)

    def parameter_specs(self, case, channels=None):
        """The Coulomb torque T_c (N m), up to twice the hinge's torque scale.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; a hinged appendage; its hinge torque scale sizes T_c.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        scale = torque_scale(Plant.from_case(case))
        return [Parameter("friction_torque", "N m", "Coulomb friction torque magnitude (sliding and break-away)",
                          0.1 * scale, 0.0, 2.0 * scale)]

    def initial_extra_states(self, plant):
        """The stick anchor starts at the initial hinge angle.

        Parameters
        ----------
        plant : Plant
            A hinged plant (its hinge angle at t = 0, rad).

        Returns
        -------
        xe0 : (1,) float
            [theta_a (rad)].
        """
        return np.array([plant.hinge_angle0], float)

    def law_parameters(self, plant, values):
        """[T_c, c_s, k_s, lambda_s]: the friction limit and the plant's stick gains.

        Parameters
        ----------
        plant : Plant
            A hinged plant (sets the stick gains).
        values : (m,) float
            [T_c (N m)].

        Returns
        -------
        p : (4,) float
            [T_c (N m), c_s (N m s/rad), k_s (N m/rad), lambda_s (1/s)].
        """
        return np.array([float(values[0]), *stick_gains(plant), stick_rate(plant)])

    def parameter_free_stiffness_rate(self, plant):
        """lambda_s plus the hinge damper's rate c / J (1/s): the stuck hinge's hold, whatever T_c.

        Parameters
        ----------
        plant : Plant
            A hinged plant.

        Returns
        -------
        rate : float
            (1/s).
        """
        return stick_rate(plant) + plant.damping / plant.effective_hinge_inertia()

    def stiffness_rate(self, plant, specs):
        """The parameter-free rate (the hold does not depend on T_c).

        Parameters
        ----------
        plant : Plant
            A hinged plant.
        specs : list of Parameter
            Not used.

        Returns
        -------
        rate : float
            (1/s).
        """
        return self.parameter_free_stiffness_rate(plant)

    def add_to_exudyn(self, builder, values, names):
        """The stick-slip friction on the hinge, with its anchor as a stateful user function.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder; a hinge torque (N m, about the axis).
        values : (m,) float
            [T_c (N m)].
        names : sequence of str
            Parameter names (not used).
        """
        builder.add_hinge_torque(_StickAnchor(float(values[0]), builder.plant))


EFFECT = HingeCoulombFriction()


# ------------------------------------------------------------------ references for the stick-slip check
def analytic_turning_points(theta0, stiffness, inertia, torque):
    """Turning points of the analytic Coulomb ring-down J theta'' = -k theta - T sign(theta') released
    from rest at ``theta0`` (rad), up to and including the one where it sticks: each half cycle is a
    harmonic half period pi/omega about the centre +-T/k, so theta_n = (-1)^n (theta0 - 2 n T/k) at
    t_n = n pi/omega, until |k theta_n| <= T.

    Parameters
    ----------
    theta0 : float
        Release angle (rad), at rest.
    stiffness, inertia, torque : float
        k (N m/rad), J (kg m^2) and the Coulomb torque T (N m).

    Returns
    -------
    times, angles : ndarray, shape (n,)
        Times (s) and hinge angles (rad) of the turning points; the last is the stop.
    """
    omega = np.sqrt(stiffness / inertia)
    times, angles = [], []
    n = 1
    while True:
        times.append(n * np.pi / omega)
        angles.append((-1) ** n * (theta0 - 2 * n * torque / stiffness))
        if abs(stiffness * angles[-1]) <= torque:
            return np.array(times), np.array(angles)
        n += 1


def turning_points(times, angle):
    """Sampled turning points of a swing: local maxima of |angle| (``times`` (s) and ``angle`` (rad),
    shape (k,)); returns their times (s) and angles (rad).

    Parameters
    ----------
    times : (k,) float
        Sample times (s).
    angle : (k,) float
        Hinge angle (rad).

    Returns
    -------
    times, angles : (n,) float
        Times (s) and hinge angles (rad) at the interior local maxima of |angle|.
    """
    a = np.abs(angle)
    k = np.nonzero((a[1:-1] >= a[:-2]) & (a[1:-1] > a[2:]))[0] + 1
    return times[k], angle[k]


class ElastoPlasticFriction:
    """An independent stiction law for the record (not the catalog's): the elasto-plastic bristle model
    (Dahl / Dupont et al. 2002, without presliding creep): the friction is a stiff damped spring to an
    anchor that is dragged along once the spring's torque reaches T, so the hinge sticks wherever the
    held torque stays below T. Stateful hinge-torque user function of the Exudyn builder
    (``ExudynScenario.add_hinge_torque``); used to make records the catalog's law did not make
    (tests/riskassess/diagnosis/test_stiction.py, bench/bench_stick_slip.py)."""

    def __init__(self, torque, inertia, anchor, bristle_frequency=15.0):
        self.torque, self.anchor = torque, anchor
        self.stiffness = inertia * bristle_frequency ** 2                    # N m/rad
        self.damping = 2 * 0.7 * inertia * bristle_frequency                  # N m s/rad

    def __call__(self, t, angle, rate):
        reach = self.torque / self.stiffness
        self.anchor = min(max(self.anchor, angle - reach), angle + reach)
        held = self.stiffness * (angle - self.anchor) + self.damping * rate
        return -min(max(held, -self.torque), self.torque)
