"""The impact model's closing winch: reels the net's closing loop (:mod:`multibody.closing`) in from its trigger,
step by step, in the compiled kernel's thread arrays, and books the work it does.

The loop's threads are the net's last :data:`~multibody.closing.N_CLOSING` threads, so the kernel's tension-only
thread pass (:func:`multibody.net.add_thread_forces_runs`) gives their forces, their elastic energy (in the
threads' elastic energy) and their damper's dissipation (in the threads' dissipated energy) like any thread's. Only
their natural lengths, their stiffnesses and their natural lengths' rates change: :meth:`ClosingWinch.after_step`
runs after each step (from the kernel's pre-step hook, with the recorder's sample of that step,
:meth:`multibody.kernel_net.KernelNet.set_after_step`) and sets them for the next step's force evaluation, at the next
step's end time (the time of Verlet's evaluation state). The rate is the schedule's mean over that step, so the
threads' dampers read the stretch's rate :math:`\dot l - \dot l_0` (:func:`multibody.net.tension_only_kelvin_voigt`):
a thread reeled in at constant stretch takes no damper force and dissipates nothing.

The winch holds the whole tension :math:`T` and hauls in at :math:`-\dot l_0`: it puts :math:`-T \dot l_0 +
\tfrac12 \dot k s^2` into the loop (:func:`multibody.net.reel_damper_power`). Its spring share is the change of the
loop's elastic energy across each update at fixed positions (:mod:`multibody.closing`, module doc; the stiffness
EA / l0 changes with l0 and the change is in it), taken as the mean of the change at the node positions before and
after the step that first uses the new lengths (the trapezoid rule: second order in the step); its damper share,
:math:`-(T - k s)\,\dot l_0`, is booked at each evaluation over the step, as the kernel books the dampers'
dissipation. Both are summed in :attr:`ClosingWinch.work`; the recorder books it (``energy_winch_work``), so the
balance stays closed while the loop pulls (:class:`TrapezoidWork`).

The trigger: a time, or the net's first contact with any body (the kernel's contact count, nodes' and threads')
plus a delay; a mission fires the closing on a sensed arrival of the net, then waits for the wrap (Boonrath,
Singh & Botta 2024 close 7 s after the net reaches the stage, at 2 m/s: Sec. 4.1).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multibody.closing import N_CLOSING, closing_stiffness, loop_elastic_energy, reel_fraction, reeled_rest_lengths
from multibody.kernel import N_CONTACTS, KernelData
from multibody.net import PADDING_REST_LENGTH, reel_damper_power


class ContactTrigger:
    """When a mechanism fires (the closing's winch, the main tether's spool brake): at a time, or at the net's first
    contact with any body (the kernel's contact count, nodes' and threads') plus a delay.

    Parameters
    ----------
    start : float or None
        Activation time (s); None: at the first contact plus ``delay``.
    delay : float
        Time after the first contact (s) when ``start`` is None.
    scalars : (N_SCALARS,) float
        The kernel's scalars (:class:`multibody.kernel.KernelBuffers`), read for the contact count.

    Attributes
    ----------
    activated_at : float or None  Activation time (s), once known.
    first_contact : float or None Time of the net's first contact (s), once seen.
    """

    def __init__(self, start: float | None, delay: float, scalars):
        self.activated_at, self.delay, self.scalars = start, float(delay), scalars
        self.first_contact = None

    def activation(self, t: float) -> float | None:
        """After the step that ended at ``t`` (s): the activation time (s), or None while it is not known."""
        if self.activated_at is None and self.first_contact is None and self.scalars[N_CONTACTS] > 0:
            self.first_contact = t
            self.activated_at = t + self.delay
        return self.activated_at


@dataclass(frozen=True)
class ClosingSpec:
    """The closing mechanism of an impact run (SI).

    Attributes
    ----------
    start : float or None     Activation time (s); None: at the first contact plus ``delay``.
    delay : float             Time after the first contact (s) when ``start`` is None.
    duration : float          Reel-in time from open to closed (s).
    rest_open : (12,) float   The loop's open natural lengths (m): its threads' straight lengths at t = 0.
    rest_closed : (12,) float Its closed natural lengths (m).
    axial_rigidity : float    EA of the closing thread (N).
    """

    start: float | None
    delay: float
    duration: float
    rest_open: np.ndarray
    rest_closed: np.ndarray
    axial_rigidity: float


class TrapezoidWork:
    """The work a reel does on the net by changing natural lengths (:func:`multibody.net.reel_damper_power`).

    The spring's share by the trapezoid rule: half of each update's elastic-energy change at the positions before
    the step that uses it (:meth:`book_update`), half at the positions that step ended in (:meth:`book_pending`);
    second order in the step (either end alone is first order, measured in tests/multibody/test_closing.py). The
    damper's share, :math:`-(T - k s)\,\dot l_0` times the step, at each evaluation (:meth:`book_pending`), as the
    kernel books the dampers' dissipation :math:`(T - k s)\,\dot s` times the step.

    Subclasses give ``_energy_change(rest_from, rest_to)`` (J, at the current positions) and
    ``_evaluated_threads()`` (the reeled threads' tension (N), pulling stretch (m), stiffness (N/m) and natural
    length's rate (m/s) at the last evaluation, arrays or floats), and start with ``work = 0.0``,
    ``_pending = None``, ``_reeling = False`` (True while a rate is set) and ``step`` (s)."""

    def book_update(self, rest_before, rest_after) -> None:
        """Book the first half of the work of the update ``rest_before`` -> ``rest_after`` (m) now."""
        self.work += 0.5 * self._energy_change(rest_before, rest_after)
        self._pending = (rest_before, rest_after)

    def book_pending(self) -> None:
        """Book the second half of the last update's work, at the positions the step that used it ended in, and the
        damper's share of that step's evaluation."""
        if self._pending is not None:
            self.work += 0.5 * self._energy_change(*self._pending)
            self._pending = None
        if self._reeling:
            self.work += self.step * float(np.sum(reel_damper_power(*self._evaluated_threads())))


class ClosingWinch(TrapezoidWork):
    """Reels the closing loop in inside a running impact (module doc).

    Parameters
    ----------
    spec : ClosingSpec
    kernel : KernelData
        The run's kernel; the loop is its net's last 12 threads.
    net_q : (3 n,) float
        The kernel's net displacements (m, LVLH, coordinate-major; :class:`multibody.kernel_net.KernelNet`'s ``q``),
        read at each update for the winch's work.
    step : float
        The integrator's step (s).

    Attributes
    ----------
    work : float              The winch's work on the net so far (J); positive while it reels in against tension.
    activated_at : float or None  Activation time (s), once known.
    rest_start, rest_end : (12,) float or None  Natural lengths (m) at the start and the end of the reel-in.
    first_contact : float or None Time of the net's first contact (s), once seen.
    """

    def __init__(self, spec: ClosingSpec, kernel: KernelData, net_q, step: float):
        runs = kernel.net.thread_runs
        real = np.flatnonzero(runs.rest_lengths != PADDING_REST_LENGTH)   # the thread list's order (net.thread_runs)
        n_threads = len(kernel.net.threads)
        if len(real) != n_threads:
            raise ValueError(f"{len(real)} real threads in the kernel's runs against {n_threads} in the net")
        self.index = real[n_threads - N_CLOSING:]
        self.threads = np.asarray(kernel.net.threads[n_threads - N_CLOSING:], np.int64)
        # the kernel's own arrays: written in place
        self.rest, self.stiffness, self.rest_rate = runs.rest_lengths, runs.stiffness, runs.rest_rates
        self.work_thread = kernel.buffers.work_thread     # the thread pass's last evaluation, per padded thread
        self.spec, self.step = spec, float(step)
        self.scalars = kernel.buffers.scalars
        self.reference_lvlh = kernel.net.reference_lvlh
        self.net_q = net_q
        self.n_nodes = kernel.n_nodes
        self.work = 0.0
        self.trigger = ContactTrigger(spec.start, spec.delay, self.scalars)
        self.closed = False
        self._pending = None   # (before, after) natural lengths of the last update, half its work still to book
        self._reeling = False  # the last evaluation had the loop's natural lengths moving (rest_rate set)
        #: the loop's natural lengths (m) when the reel-in starts (the slack taken up) and when it ends; None before
        self.rest_start = self.rest_end = None

    @property
    def activated_at(self) -> float | None:
        """Activation time (s), once known (:class:`ContactTrigger`)."""
        return self.trigger.activated_at

    @property
    def first_contact(self) -> float | None:
        """Time of the net's first contact (s), once seen (:class:`ContactTrigger`)."""
        return self.trigger.first_contact

    def natural_lengths(self, t: float) -> np.ndarray:
        """The loop's natural lengths (m) at time ``t`` (s) by the schedule: open before the activation, then
        linear from :attr:`rest_start` to :attr:`rest_end` over the duration."""
        if self.rest_start is None:
            return self.spec.rest_open.copy()
        return reeled_rest_lengths(self.rest_start, self.rest_end, reel_fraction(t, self.activated_at, self.spec.duration))

    def _take_up_slack(self) -> None:
        """At the activation: the winch first takes in the slack, without load (each thread's natural length becomes
        the smaller of its open length and its length now, :attr:`rest_start`), then reels in at a constant rate to
        :attr:`rest_end`, the closed lengths (or the start's where already shorter: the winch never pays out). A slack
        thread holds no energy, so taking up its slack does no work. Without this, a wrapped net's loop, much shorter
        than the flat net's perimeter, would be reeled in from slack over most of the duration and then at the full
        rate in its last part."""
        x_lvlh = self._loop_positions()
        length = np.linalg.norm(x_lvlh[self.threads[:, 1]] - x_lvlh[self.threads[:, 0]], axis=1)
        self.rest_start = np.minimum(self.spec.rest_open, length)
        self.rest_end = np.minimum(self.spec.rest_closed, self.rest_start)

    def _loop_positions(self) -> np.ndarray:
        """(n, 3) positions (m, LVLH) of the nodes (only the loop's are filled; the rest are zero)."""
        x_lvlh = np.zeros((self.n_nodes, 3))
        nodes = np.unique(self.threads)
        q = self.net_q.reshape(3, self.n_nodes)
        x_lvlh[nodes] = self.reference_lvlh[nodes] + q[:, nodes].T
        return x_lvlh

    def _energy_change(self, rest_from, rest_to) -> float:
        """Change of the loop's elastic energy (J) at the current node positions when its natural lengths go from
        ``rest_from`` to ``rest_to`` ((12,) float, m)."""
        x_lvlh, a = self._loop_positions(), self.spec.axial_rigidity
        return (loop_elastic_energy(x_lvlh, self.threads, rest_to, a)
                - loop_elastic_energy(x_lvlh, self.threads, rest_from, a))

    def after_step(self, t: float) -> None:
        """After the step that ended at ``t`` (s): watch for the trigger, then set the loop's natural lengths and
        stiffnesses for the next step's evaluation (at ``t + step``) and book half the work of the change at the
        current positions (:meth:`book_pending` books the other half after the step)."""
        if self.closed or self.trigger.activation(t) is None:
            if self._reeling:       # the reel-in ended with the last step: the lengths hold from here on
                self.rest_rate[self.index] = 0.0
                self._reeling = False
            return
        t_next = t + self.step
        if t_next < self.activated_at:
            return
        if self.rest_start is None:
            self._take_up_slack()
        rest_before = self.rest[self.index].copy()
        rest = self.natural_lengths(t_next)
        self.book_update(rest_before, rest)
        self.rest[self.index] = rest
        self.stiffness[self.index] = closing_stiffness(self.spec.axial_rigidity, rest)
        # the schedule's mean rate over the step (the slack taken up at the activation is no rate: it is no motion
        # of the reel against tension, and a slack thread holds no force)
        self.rest_rate[self.index] = (rest - self.natural_lengths(t)) / self.step
        self._reeling = True
        self.closed = reel_fraction(t_next, self.activated_at, self.spec.duration) >= 1.0

    def _evaluated_threads(self):
        """The loop's tension (N), pulling stretch (m), stiffness (N/m) and natural length's rate (m/s) at the last
        evaluation (the thread pass's work rows: the force on node a, T e, and the energy 1/2 k s^2)."""
        work = self.work_thread[:, self.index]
        tension = np.sqrt(work[0] ** 2 + work[1] ** 2 + work[2] ** 2)
        stiffness = self.stiffness[self.index]
        return tension, np.sqrt(2.0 * work[3] / stiffness), stiffness, self.rest_rate[self.index]

    def summary(self) -> dict:
        """JSON-ready: activation and first-contact times (s), the reel-in's end (s), the work booked (J), the loop's
        natural lengths (m): open, at the start of the reel-in, closed (sums, and per thread for the last two)."""
        end = None if self.activated_at is None else self.activated_at + self.spec.duration
        return {"first_contact_s": self.first_contact, "activated_at_s": self.activated_at, "closed_at_s": end,
                "closed": bool(self.closed), "winch_work_J": float(self.work),
                "loop_open_length_m": float(np.sum(self.spec.rest_open)),
                "loop_start_length_m": None if self.rest_start is None else float(np.sum(self.rest_start)),
                "loop_closed_length_m": float(np.sum(self.spec.rest_closed if self.rest_end is None else self.rest_end)),
                "thread_start_lengths_m": None if self.rest_start is None else self.rest_start.tolist(),
                "thread_closed_lengths_m": (self.spec.rest_closed if self.rest_end is None else self.rest_end).tolist()}
