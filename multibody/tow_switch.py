"""Switch from the full-net towing model to the lower-order one at quasi-steady state (Boonrath, Singh
& Botta 2024, Sec. 5: the full-net model for the capture and the first transient, the lower-order
model once the towing has settled).

**Criterion** (:class:`QuasiSteadyWatch`, :func:`switch_time`): the run switches at the first output
sample t at which, over the whole window [t - window, t], all after ``earliest``,

* the main tether stayed taut (tension > 0 at every sample), and
* the tension and the net's kinetic energy relative to the debris' rigid motion
  (:func:`multibody.net.net_kinetic_energy_relative_to_body`), each averaged over consecutive blocks of ``averaging``
  seconds ending at t (as many whole blocks as the window holds; ``averaging`` = 0: every sample is a
  block), are stationary: the block means of the tension vary peak-to-peak by at most ``tension_rel_tol``
  of their mean (:func:`multibody.quasi_steady.window_is_steady`, the project's quasi-steady rule), and
  those of the energy either do too or all stay at or below ``kinetic_energy_max`` (J: a calm net).

With blocks of one debris spin period the criterion asks that the tow repeat itself from one revolution to
the next: the net wrapped on a spinning stage pulls on the tether with the revolution (the 15 x 15 net at
17.5 deg/s: 10 s means of 100-250 N, in phase with the spin), which no sample-wise bound accepts, while the
towing force averaged over a revolution, the one the lower-order model has to reproduce, is steady
(docs/towing.md, "Switch to the lower-order model"). The energy is measured relative to the debris
because a net turning with the stage carries kinetic energy about its own CoM that is no flapping (the
closed bag before the pull, there: 2.5-3.9 J about its CoM, 0.9-1.4 J relative to the debris): the
lower-order model lumps that net into the debris.

**Start state of the lower-order model** (:func:`lower_order_state`): chaser and debris attitude and
angular velocities, chaser CoM position and velocity and debris CoM position are copied; the connection
point P sits at the net's central node (the main tether's far end) with that node's velocity, so the
main-tether elongation and its rate, hence the tension, are continuous; the sub-tether elongations follow
from P and the debris attachment points. The lower-order model lumps the net into P (mass s4 m_net) and
the debris (the rest, (1 - s4) m_net): the debris CoM velocity is set so that the system's linear
momentum is the same on both sides of the switch (to round-off); the change of the debris velocity
is the net's momentum relative to the debris that P does not carry, divided by the debris mass.
Frame: Earth-centred inertial; angular velocities in the body frames.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multibody.quasi_steady import window_is_steady


def net_internal_kinetic_energy(masses, velocities) -> float:
    """Kinetic energy of the net's nodes relative to the net's CoM (J).

    Parameters
    ----------
    masses : (n,) float
        Node masses (kg).
    velocities : (n, 3) float
        Node velocities (m/s, inertial).

    Returns
    -------
    float
        sum_i m_i |v_i - v_com|^2 / 2 (J); independent of the frame's translation.
    """
    m = np.asarray(masses, float)
    v = np.asarray(velocities, float)
    v_com = m @ v / m.sum()
    return float(0.5 * np.sum(m * np.sum((v - v_com) ** 2, axis=1)))


@dataclass(frozen=True)
class SwitchCriterion:
    """The quasi-steady criterion (module doc).

    Attributes
    ----------
    earliest : float             No switch before this time (s, absolute; default thrust-on).
    window : float               Time over which the conditions must hold (s).
    kinetic_energy_max : float   Net kinetic energy relative to the debris (block means) below which the net
                                 counts as calm whatever its variation (J).
    tension_rel_tol : float      Largest peak-to-peak of the block means over their mean (-), tension and energy.
    averaging : float            Block length (s); 0: every sample is a block. A positive value must fit at
                                 least twice in the window.
    """

    earliest: float
    window: float
    kinetic_energy_max: float
    tension_rel_tol: float
    averaging: float = 0.0

    def __post_init__(self):
        if self.averaging > 0.0 and self.window < 2.0 * self.averaging - 1e-9:
            raise ValueError(f"switch criterion: the window ({self.window} s) must hold at least two averaging "
                             f"blocks ({self.averaging} s each)")


class QuasiSteadyWatch:
    """Fed one output sample at a time (in time order); says when the criterion has held over the window."""

    def __init__(self, criterion: SwitchCriterion):
        self.criterion = criterion
        self.time, self.kinetic, self.tension = [], [], []

    def update(self, t: float, kinetic: float, tension: float) -> bool:
        """Add the sample at ``t``; True when the samples in [t - window, t] satisfy the criterion.

        Parameters
        ----------
        t : float
            Sample time (s).
        kinetic : float
            Net kinetic energy relative to the debris (J).
        tension : float
            Main-tether tension (N).

        Returns
        -------
        bool
        """
        c = self.criterion
        self.time.append(t)
        self.kinetic.append(kinetic)
        self.tension.append(tension)
        # a hair of slack: sample times are sums of steps, so t - window is a sample time up to round-off
        first = t - c.window - 1e-9
        if first < c.earliest - 1e-9 or self.time[0] > first + 2e-9:
            return False   # the window reaches before the earliest switch or before the first sample
        k = int(np.searchsorted(self.time, first))
        return window_is_quasi_steady(np.asarray(self.time[k:]), np.asarray(self.kinetic[k:]),
                                      np.asarray(self.tension[k:]), c)


def block_means(time, values, end: float, averaging: float, blocks: int) -> np.ndarray:
    """Means of ``values`` over ``blocks`` consecutive blocks of ``averaging`` seconds ending at ``end``
    (block j holds the samples with end - (j+1) averaging < t <= end - j averaging).

    Parameters
    ----------
    time : (k,) float
        Sample times (s), increasing.
    values : (k,) float
        One signal's samples.
    end : float
        End of the last block (s).
    averaging : float
        Block length (s), > 0.
    blocks : int
        Number of blocks.

    Returns
    -------
    (blocks,) float
        Newest block first; NaN for a block without samples.
    """
    age = (end - np.asarray(time, float)) / averaging
    index = np.floor(age + 1e-9).astype(int)   # a hair of slack: sample times are sums of steps
    out = np.full(blocks, np.nan)
    for j in range(blocks):
        inside = index == j
        if inside.any():
            out[j] = float(np.mean(np.asarray(values, float)[inside]))
    return out


def window_is_quasi_steady(time, kinetic, tension, criterion: SwitchCriterion) -> bool:
    """The criterion (module doc) on the samples of one window [t - window, t], t = ``time[-1]``.

    Parameters
    ----------
    time : (k,) float
        Sample times of the window (s), increasing.
    kinetic : (k,) float
        Net kinetic energy relative to the debris (J).
    tension : (k,) float
        Main-tether tension (N).
    criterion : SwitchCriterion
        The thresholds.

    Returns
    -------
    bool
    """
    c = criterion
    tension = np.asarray(tension, float)
    if not tension.min() > 0.0:
        return False    # slack (or NaN) somewhere in the window: the tow still snaps
    if c.averaging > 0.0:
        blocks = int(np.floor(c.window / c.averaging + 1e-9))
        tension = block_means(time, tension, time[-1], c.averaging, blocks)
        kinetic = block_means(time, kinetic, time[-1], c.averaging, blocks)
    kinetic = np.asarray(kinetic, float)
    calm = bool(np.all(np.isfinite(kinetic)) and kinetic.max() <= c.kinetic_energy_max)
    return bool(window_is_steady(tension, c.tension_rel_tol, 0.0)
                and (calm or window_is_steady(kinetic, c.tension_rel_tol, 0.0)))


def switch_time(time, kinetic, tension, criterion: SwitchCriterion) -> float | None:
    """First sample time at which the criterion has held over its window (None: never).

    Parameters
    ----------
    time : (k,) float
        Sample times (s), increasing.
    kinetic : (k,) float
        Net kinetic energy relative to the debris (J).
    tension : (k,) float
        Main-tether tension (N).
    criterion : SwitchCriterion
        The thresholds.

    Returns
    -------
    float or None
        (s).
    """
    watch = QuasiSteadyWatch(criterion)
    for t, e, f in zip(time, kinetic, tension):
        if watch.update(float(t), float(e), float(f)):
            return float(t)
    return None


def lower_order_state(body_masses, net_mass, net_momentum, node_position, node_velocity, chaser_velocity,
                      debris_velocity, mass_fraction):
    """P's position and velocity and the debris CoM velocity of the lower-order model at the switch
    (module doc), and the momentum balance.

    Parameters
    ----------
    body_masses : (2,) float
        m_C, m_D (kg).
    net_mass : float
        m_net (kg).
    net_momentum : (3,) float
        sum_i m_i v_i of the net's nodes (N s, inertial).
    node_position, node_velocity : (3,) float
        The central node (m, m/s; inertial): P's start.
    chaser_velocity, debris_velocity : (3,) float
        CoM velocities (m/s, inertial) in the full-net model.
    mass_fraction : float
        s4 = m_P / m_net (-); the debris of the lower-order model carries (1 - s4) m_net.

    Returns
    -------
    p_position, p_velocity : (3,) float
        P (m, m/s; inertial).
    debris_velocity : (3,) float
        Lower-order debris CoM velocity (m/s, inertial).
    balance : dict
        ``momentum_full_net_Ns`` and ``momentum_lower_order_Ns`` (3,) (N s, inertial),
        ``debris_velocity_change_m_s`` (m/s), ``net_relative_momentum_Ns`` (N s): the net's momentum
        relative to the central node, which P does not carry.
    """
    m_c, m_d = (float(x) for x in body_masses)
    p_net = np.asarray(net_momentum, float)
    p_position, p_velocity = np.array(node_position, float), np.array(node_velocity, float)
    v_c, v_d = np.asarray(chaser_velocity, float), np.asarray(debris_velocity, float)
    m_p, m_debris = mass_fraction * net_mass, m_d + (1.0 - mass_fraction) * net_mass
    debris_v = (m_d * v_d + p_net - m_p * p_velocity) / m_debris
    before = m_c * v_c + m_d * v_d + p_net
    after = m_c * v_c + m_debris * debris_v + m_p * p_velocity
    return p_position, p_velocity, debris_v, {
        "momentum_full_net_Ns": before.tolist(), "momentum_lower_order_Ns": after.tolist(),
        "debris_velocity_change_m_s": float(np.linalg.norm(debris_v - v_d)),
        "net_relative_momentum_Ns": float(np.linalg.norm(p_net - net_mass * p_velocity))}
