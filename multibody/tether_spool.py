"""The main tether's spool in the impact model: pays the line out freely while the net flies, brakes at its trigger,
then optionally reels in at a constant rate, and books the work the reel does.

Paying out, the line's natural length follows the node's distance from the anchor: no tension, no energy, no work
(:data:`multibody.net_tether.ON` = 0: the force pass returns at once). At the trigger (the closing's vocabulary and
function, :class:`multibody.closing_winch.ContactTrigger`: a time, or the net's first contact plus a delay) the
spool brakes: the natural length freezes at the node's distance then plus ``slack``; a line given by its axial
rigidity EA gets the stiffness EA / l0 of that length. With a reel-in rate, the natural length then shortens by
``rate`` a second, by ``reel_in`` in all.

:meth:`TetherSpool.after_step` runs after each step (from the kernel's pre-step hook, like the closing winch,
:mod:`multibody.closing_winch`) and sets the natural length for the next step's evaluation, at the next step's end
time, and the natural length's rate (the schedule's mean over that step, :data:`multibody.net_tether.REST_RATE`) that
the tether's damper subtracts from the length's rate. The reel's work is, as the closing winch's
(:class:`multibody.closing_winch.TrapezoidWork`), the change of the tether's elastic energy across each update at
fixed positions (:mod:`multibody.closing`, module doc), the mean of the change at the node's position before and
after the step that first uses the new length (the trapezoid rule: second order in the step), plus the damper's
share of the tension against the reel, :math:`-(T - k s)\,\dot l_0` a step (:func:`multibody.net.reel_damper_power`),
summed in :attr:`TetherSpool.work`; the recorder books it (``energy_tether_winch_work``) with the tether's elastic energy and
its damper's dissipation (``energy_tether_elastic``, ``energy_dissipated_tether``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multibody.closing_winch import ContactTrigger, TrapezoidWork
from multibody.net_tether import (
    DISSIPATED,
    ELASTIC,
    FORCE_ON_CHASER,
    ON,
    REST,
    REST_RATE,
    STIFFNESS,
    TENSION,
    NetTether,
    net_tether,
    reeled_rest_length,
    tether_elastic_energy,
)


@dataclass(frozen=True)
class TetherSpec:
    """The main tether of an impact run (SI; :mod:`multibody.net_tether`).

    Attributes
    ----------
    node : int                  The tethered net node.
    anchor_lvlh : (3,) float    The chaser's anchor (m), LVLH.
    stiffness : float or None   k (N/m); None: EA / l0 at the brake.
    axial_rigidity : float or None  EA (N) when ``stiffness`` is None.
    damping : float             c (N s/m).
    start : float or None       Brake time (s); None: at the first contact plus ``delay``.
    delay : float               Time after the first contact (s) when ``start`` is None.
    slack : float               Added to the node's distance when the spool brakes (m).
    reel_rate : float           Reel-in rate after the brake (m/s); 0: the brake only.
    reel_in : float             Length the spool reels in after the brake, then holds (m).
    """

    node: int
    anchor_lvlh: np.ndarray
    stiffness: float | None
    axial_rigidity: float | None
    damping: float
    start: float | None
    delay: float
    slack: float = 0.0
    reel_rate: float = 0.0
    reel_in: float = 0.0

    def kernel_tether(self) -> NetTether:
        """The compiled step's :class:`~multibody.net_tether.NetTether`, paying out."""
        return net_tether(self.node, self.anchor_lvlh, self.damping)


class TetherSpool(TrapezoidWork):
    """Brakes and reels the main tether inside a running impact (module doc).

    Parameters
    ----------
    spec : TetherSpec
    tether : NetTether
        The compiled step's tether (its ``state`` written in place).
    scalars : (N_SCALARS,) float
        The kernel's scalars, for the contact trigger.
    reference_lvlh : (n, 3) float
        The nodes' reference positions (m), LVLH.
    net_q : (3 n,) float
        The kernel's net displacements (m, LVLH, coordinate-major), read at each update.
    step : float
        The integrator's step (s).

    Attributes
    ----------
    work : float                The reel's work on the net so far (J); positive while it reels in against tension.
    braked_at : float or None   When the spool braked (s).
    rest_braked : float or None The natural length at the brake (m).
    peak_tension, peak_tension_at : float  The largest tension over the steps (N) and its time (s).
    taut_at : float or None     First step with tension (s); ``taut_node_lvlh`` the node's position then (m, LVLH).
    """

    def __init__(self, spec: TetherSpec, tether: NetTether, scalars, reference_lvlh, net_q, step: float):
        self.spec, self.tether, self.state = spec, tether, tether.state
        self.trigger = ContactTrigger(spec.start, spec.delay, scalars)
        self.node_reference_lvlh = np.asarray(reference_lvlh[spec.node], float).copy()
        self.n_nodes = len(reference_lvlh)
        self.net_q, self.step = net_q, float(step)
        self.work = 0.0
        self.braked_at = self.rest_braked = self.taut_at = self.taut_node_lvlh = None
        self.peak_tension, self.peak_tension_at = 0.0, None
        self.peak_chaser_force = 0.0
        self._pending = None   # (before, after) natural lengths of the last reel update, half its work still to book
        self._reeling = False  # the last evaluation had the natural length moving (REST_RATE set)

    def node_lvlh(self) -> np.ndarray:
        """(3,) The tethered node's position (m, LVLH) at the end of the last step."""
        q = self.net_q.reshape(3, self.n_nodes)
        return self.node_reference_lvlh + q[:, self.spec.node]

    def distance(self) -> float:
        """The node's distance from the anchor (m) at the end of the last step."""
        return float(np.linalg.norm(self.node_lvlh() - self.spec.anchor_lvlh))

    def stiffness(self, rest: float) -> float:
        """k (N/m) of the line at natural length ``rest`` (m): the case's, or EA / l0."""
        return self.spec.stiffness if self.spec.stiffness is not None else self.spec.axial_rigidity / rest

    def _energy_change(self, rest_from: float, rest_to: float) -> float:
        """Change of the elastic energy (J) at the node's current position when the natural length goes from
        ``rest_from`` to ``rest_to`` (m), the stiffness with it."""
        length = self.distance()
        return (tether_elastic_energy(length, rest_to, self.stiffness(rest_to))
                - tether_elastic_energy(length, rest_from, self.stiffness(rest_from)))

    def _watch(self, t: float) -> None:
        """The step that ended at ``t`` (s): its tension's peak and the first taut step."""
        tension = self.state[TENSION]
        if tension > 0.0 and self.taut_at is None:
            self.taut_at, self.taut_node_lvlh = t, self.node_lvlh()
        if tension > self.peak_tension:
            self.peak_tension, self.peak_tension_at = float(tension), t
            self.peak_chaser_force = float(np.linalg.norm(self.state[FORCE_ON_CHASER:FORCE_ON_CHASER + 3]))

    def _brake(self) -> None:
        """Freeze the natural length at the node's distance now plus the slack (a slack line holds no energy:
        no work)."""
        self.rest_braked = self.distance() + self.spec.slack
        self.state[REST] = self.rest_braked
        self.state[STIFFNESS] = self.stiffness(self.rest_braked)
        self.state[ON] = 1.0

    def after_step(self, t: float) -> None:
        """After the step that ended at ``t`` (s): watch the tension, the trigger, then set the natural length for
        the next step's evaluation (at ``t + step``) and book half the reel's work at the current position."""
        self._watch(t)
        activated_at = self.trigger.activation(t)
        t_next = t + self.step
        if activated_at is None or t_next < activated_at:
            return
        if self.braked_at is None:
            self.braked_at = t_next
            self._brake()
            return
        if self.spec.reel_rate == 0.0:
            return
        rest_before = float(self.state[REST])
        rest = reeled_rest_length(self.rest_braked, self.spec.reel_rate, t_next - self.braked_at, self.spec.reel_in)
        self.state[REST_RATE] = (rest - rest_before) / self.step   # the schedule's mean rate over the step
        self._reeling = rest != rest_before
        if not self._reeling:
            return
        self.book_update(rest_before, rest)
        self.state[REST] = rest
        self.state[STIFFNESS] = self.stiffness(rest)

    def _evaluated_threads(self):
        """The tether's tension (N), pulling stretch (m), stiffness (N/m) and natural length's rate (m/s) at the last
        evaluation (the force pass's outputs; the stretch from its elastic energy, 1/2 k s^2)."""
        k = self.state[STIFFNESS]
        return self.state[TENSION], np.sqrt(2.0 * self.state[ELASTIC] / k), k, self.state[REST_RATE]

    @property
    def dissipated(self) -> float:
        """Energy the tether's damper took out of the motion so far (J)."""
        return float(self.state[DISSIPATED])

    def summary(self) -> dict:
        """JSON-ready: the node and anchor, the trigger and brake times (s), the natural lengths (m), the reel's work
        and the damper's dissipation (J), the peak tension (N) and its time (s), the force the chaser's thrusters
        held then (N), when the line first went taut and where the node was (m, LVLH)."""
        return {"node": int(self.spec.node), "anchor_lvlh_m": np.asarray(self.spec.anchor_lvlh).tolist(),
                "first_contact_s": self.trigger.first_contact, "braked_at_s": self.braked_at,
                "rest_length_at_brake_m": self.rest_braked, "rest_length_now_m": float(self.state[REST]),
                "stiffness_N_per_m": float(self.state[STIFFNESS]), "damping_N_s_per_m": float(self.spec.damping),
                "reel_work_J": float(self.work), "dissipated_J": self.dissipated,
                "peak_tension_N": self.peak_tension, "peak_tension_at_s": self.peak_tension_at,
                "peak_chaser_force_N": self.peak_chaser_force, "taut_at_s": self.taut_at,
                "taut_node_lvlh_m": None if self.taut_node_lvlh is None else self.taut_node_lvlh.tolist()}
