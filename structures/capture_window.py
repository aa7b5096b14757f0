"""The judged window as the capture: when is a net capture over?

A run that judges a fixed time (or a fixed net travel) can end while the wrapped net still swings through and
around the debris, and a later pass can load a joint more than an earlier one with less energy
(docs/structures.md, "The analogue's low end, and is 48.75 m of travel long enough?"). The capture is over when
the net has stopped moving relative to the debris and no judged demand is still rising:

- the net's kinetic energy relative to the debris' reference body, with the part that moves rigidly with that
  body removed (:func:`multibody.net.net_kinetic_energy_relative_to_body`), has stayed below a threshold for a
  hold time, and
- no judged location's running peak has risen over that hold time (:func:`settle_time`).

:class:`CaptureMonitor` applies the same rule while a run goes on (the recorder calls it at every output sample
and net snapshot) so that the simulation stops once the capture is over; the verdict recomputes it from the
recorded series (:func:`capture_window`) and judges a location that held as indeterminate when the run reached its
end time before the capture was over (:func:`capture_gap`).

The reference is the main body, not each node's nearest body: on the kept whole-capture runs at 1-3 m/s the
part of it an appendage's swing carries (nodes riding on the array) is at most 0.2 mJ of the 0.2-6 J left over the
last 10 s before the cap, the array's own energy relative to the main body at most 4.9 mJ; the rest is the net's and
the bullets' own motion, 80-99 % of it more than 0.5 m from every body (docs/structures.md, "What the
energy left at the cap is", :mod:`multibody.relative_motion`).

All quantities SI; positions and velocities in LVLH (velocities relative to the LVLH axes, as the model integrates
them), the body's angular velocity relative to the LVLH axes (what ``body_omega_body`` holds, expressed in the
body frame; :func:`omega_lvlh` rotates it).
"""
from __future__ import annotations

import numpy as np

from multibody.net import net_kinetic_energy_relative_to_body

from structures.indeterminacy import Indeterminacy
from structures.weak_location import WeakLocation, demands, joint_loads, judged_demands, online_modal_loads

#: Share of the net's kinetic energy relative to the debris at launch below which the net's motion relative to
#: the debris counts as died out (``structures.capture_energy_fraction``'s default). From measured runs,
#: docs/structures.md "The whole capture as the judged window": on envisat_small (the analogue hinge's high end)
#: the late strikes on the array came at 11-32 % of the launch energy and 3.9x the allowable at most (4.5 m/s);
#: the capture keeps the same shape at 2.0, 3.0 and 4.5 m/s in units of net travel, the strike's demand growing
#: about as the launch speed, so as the square root of the energy share: at 0.5 % a strike of the worst seen
#: reads 3.9 x (0.005 / 0.11)^0.5 = 0.83 of the allowable. A scaling argument from three velocities, not a bound.
CAPTURE_ENERGY_FRACTION = 0.005
#: Net travel (m) over which the relative energy must stay below the threshold and no judged running peak may
#: rise (``structures.capture_hold_s``'s default is this over the launch speed): the wrapped net's passes past the
#: body came 6.2 s apart at 4.5 m/s (modes18) and 8.4 s apart at 2.0 m/s (the lead's 67.5 s run), i.e. 17-28 m of
#: travel; 7 s at 4.5 m/s (window19's hold) is 31.5 m and covers one pass at every speed run.
CAPTURE_HOLD_TRAVEL_M = 31.5
#: Simulated time between two settle checks of a running simulation (s): the recorder stops a run at the first
#: check after the capture is over; the verdict's t_s is read from the recorded series (at most this much earlier).
CHECK_INTERVAL_S = 0.1


def energy_threshold(launch_energy_J: float, fraction: float, threshold_J: float | None = None) -> float:
    """The relative energy below which the capture's relative motion counts as died out (J): the case's
    ``structures.capture_energy_J`` when given, else ``fraction`` (``capture_energy_fraction``) of the net's kinetic
    energy relative to the debris at launch (``launch_energy_J``)."""
    return float(threshold_J) if threshold_J is not None else fraction * float(launch_energy_J)


def hold_time(hold_s: float | None, launch_speed: float) -> float:
    """The hold (s): the case's ``structures.capture_hold_s`` when given, else :data:`CAPTURE_HOLD_TRAVEL_M` of net
    travel at the launch speed (m/s)."""
    return float(hold_s) if hold_s is not None else CAPTURE_HOLD_TRAVEL_M / launch_speed


def omega_lvlh(body_to_lvlh, omega_body):
    """Angular velocity expressed in LVLH.

    Parameters
    ----------
    body_to_lvlh : (..., 3, 3) float
        Attitude, body -> LVLH.
    omega_body : (..., 3) float
        Angular velocity relative to the LVLH axes (rad/s), body frame.

    Returns
    -------
    (..., 3) float
        The same angular velocity (rad/s), LVLH.
    """
    return np.einsum("...ij,...j->...i", np.asarray(body_to_lvlh, float), np.asarray(omega_body, float))


def rise_times(time, demands_judged, judged_from_s: float = 0.0):
    """Times at which a judged running peak rose: a sample after ``judged_from_s`` whose demand exceeds every
    earlier judged sample of the same demand (the first judged sample counts as a rise).

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    demands_judged : (k, m) float
        m demand series (any SI unit each), sampled at ``time``.
    judged_from_s : float
        Samples before this time are not judged (s; ``structures.skip_initial``).

    Returns
    -------
    (r,) float
        The rise times (s), sorted, each once.
    """
    t = np.asarray(time, float)
    d = np.asarray(demands_judged, float).reshape(t.size, -1)
    judged = t >= judged_from_s
    t, d = t[judged], np.where(np.isfinite(d[judged]), d[judged], np.inf)
    if t.size == 0:
        return np.zeros(0)
    previous = np.vstack([np.full((1, d.shape[1]), -np.inf), np.maximum.accumulate(d, axis=0)[:-1]])
    return t[np.any(d > previous, axis=1)]


def settle_time(energy_time, energy_J, rise_time, energy_threshold_J: float, hold_s: float,
                judged_from_s: float = 0.0):
    """The first check time t_s at which the capture is over: every relative energy in [t_s - hold, t_s] is
    below the threshold and no judged running peak rose in (t_s - hold, t_s]; None when no check time
    qualifies.

    Parameters
    ----------
    energy_time : (k,) float
        Times of the relative-energy values (s), increasing: the check instants.
    energy_J : (k,) float
        The net's kinetic energy relative to the debris (J,
        :func:`multibody.net.net_kinetic_energy_relative_to_body`); a value that is not finite counts as above the
        threshold.
    rise_time : (r,) float
        Times at which a judged running peak rose (s, :func:`rise_times`).
    energy_threshold_J : float
        The energy below which the relative motion has died out (J).
    hold_s : float
        How long both conditions must hold (s).
    judged_from_s : float
        The judged window's start (s): t_s - hold is never before it.

    Returns
    -------
    float or None
        t_s (s).
    """
    t = np.asarray(energy_time, float)
    start = max(judged_from_s, t[0]) if t.size else judged_from_s
    t_s, _ = first_settled(t, np.asarray(energy_J, float), rise_time, energy_threshold_J, hold_s, start)
    return t_s


def first_settled(t, energy_J, rise_time, energy_threshold_J: float, hold_s: float, start: float,
                  last_above_before: float = -np.inf) -> tuple:
    """:func:`settle_time`'s rule on the check instants ``t`` ((k,) s, increasing) that follow earlier ones whose
    latest time with the energy at or above the threshold was ``last_above_before`` (s; -inf: none, or no earlier
    instants); ``start`` is the judged window's start or the first instant ever, whichever is later (s).

    Returns the first of ``t`` at which the capture is over (s; None when none is) and the latest time at or above
    the threshold up to the last of ``t`` (s), for the next call. Evaluated on a history in pieces, it answers what
    one call on the whole history answers, to the bit: the running maximum is exact, and an instant of an earlier
    piece that did not qualify cannot qualify later (a later rise or energy only adds conditions on later times).
    """
    t = np.asarray(t, float)
    e = np.asarray(energy_J, float)
    above = ~(e < energy_threshold_J)
    # the latest time at or before each t_j with the energy at or above the threshold (-inf if none)
    last_above = (np.maximum(np.maximum.accumulate(np.where(above, t, -np.inf)), last_above_before) if t.size
                  else t)
    rises = np.sort(np.asarray(rise_time, float))
    count = np.searchsorted(rises, t, side="right")
    last_rise = np.where(count > 0, rises[np.maximum(count - 1, 0)] if rises.size else -np.inf, -np.inf)
    ok = (t - hold_s >= start) & (last_above < t - hold_s) & (last_rise <= t - hold_s)
    t_s = float(t[np.argmax(ok)]) if ok.any() else None
    return t_s, (float(last_above[-1]) if t.size else last_above_before)


def reference_body(bodies, joints, debris_indices) -> int:
    """The debris body the net's relative motion is measured against: the heaviest debris body that is no
    joint's child (the root of the debris' joint tree, e.g. Envisat's main body).

    Parameters
    ----------
    bodies : list
        Rigid bodies with ``mass`` (kg).
    joints : list
        Joints with ``child`` (body index).
    debris_indices : list of int
        The debris bodies.

    Returns
    -------
    int
    """
    children = {j.child for j in joints}
    roots = [k for k in debris_indices if k not in children] or list(debris_indices)
    return max(roots, key=lambda k: bodies[k].mass)


def relative_energy_history(net: dict, masses, series: dict, body: int):
    """(times (s), energies (J)) of the net's kinetic energy relative to ``body`` at every net snapshot of a run.

    Parameters
    ----------
    net : dict
        Net snapshots (:attr:`multibody.recorder.Recorder.net`): ``time`` (s), ``positions_lvlh`` (k, n, 3) m,
        ``velocities_lvlh`` (k, n, 3) m/s.
    masses : (n,) float
        Node masses (kg).
    series : dict
        The run's series: ``time`` (s), ``body_com_lvlh``, ``body_velocity_lvlh`` (m, m/s), ``body_to_lvlh``,
        ``body_omega_body`` (rad/s, body frame). Every snapshot is taken at a series sample.
    body : int
        The reference body (:func:`reference_body`).

    Returns
    -------
    tuple of (k,) float
    """
    t_net, t = np.asarray(net["time"], float), np.asarray(series["time"], float)
    rows = np.clip(np.searchsorted(t, t_net), 0, t.size - 1)
    if t_net.size and np.max(np.abs(t[rows] - t_net)) > 1e-9 * max(1.0, t[-1]):
        raise ValueError("net snapshots must be taken at series samples (the recorder takes them so)")
    omega = omega_lvlh(series["body_to_lvlh"][rows, body], series["body_omega_body"][rows, body])
    energy = net_kinetic_energy_relative_to_body(masses, net["positions_lvlh"], net["velocities_lvlh"],
                                                 series["body_com_lvlh"][rows, body],
                                                 series["body_velocity_lvlh"][rows, body], omega)
    return t_net, np.atleast_1d(energy)


def judged_rise_times(locations: list[WeakLocation], series: dict, judged_from_s: float):
    """(times (s), which (location/criterion per time)) at which any judged location's running peak rose."""
    t = np.asarray(series["time"], float)
    columns, names = [], []
    for loc in locations:
        judged = judged_demands(loc, t, *joint_loads(loc, series))
        for criterion in loc.criteria():
            columns.append(np.asarray(judged[criterion], float))
            names.append(f"{loc.name} {criterion.replace('_', ' ')}")
    if not columns:
        return np.zeros(0), []
    d = np.stack(columns, axis=1)
    times = rise_times(t, d, judged_from_s)
    return times, names


def capture_window(locations: list[WeakLocation], series: dict, net: dict, masses, body: int, body_name: str,
                   judged_from_s: float, energy_threshold_J: float | None, hold_s: float,
                   energy_fraction: float = CAPTURE_ENERGY_FRACTION) -> dict:
    """Whether, and when, a recorded run's capture is over (JSON-ready).

    Parameters
    ----------
    locations : list of WeakLocation
        The judged locations.
    series : dict
        The run's series (body states and joint loads, :mod:`multibody.recorder`).
    net : dict
        The run's net snapshots.
    masses : (n,) float
        Node masses (kg).
    body : int
        Reference body index (:func:`reference_body`); ``body_name`` its name.
    judged_from_s : float
        ``structures.skip_initial`` (s).
    energy_threshold_J, hold_s : float
        The case's ``structures.capture_energy_J`` (J; None: ``energy_fraction`` of the launch's relative energy,
        :func:`energy_threshold`) and the hold (s, :func:`hold_time`).
    energy_fraction : float
        The case's ``structures.capture_energy_fraction``.

    Returns
    -------
    dict
        ``window`` "capture", ``settled``, ``settled_at_s`` (t_s or None), ``end_time_s``, the keys, the
        ``reference_body``, ``net_energy_relative_end_J``, ``last_rise_s`` (the last time a judged running peak
        rose) and ``last_rise_demand``, and ``net_energy_relative_J`` every 0.5 s as [[t (s), E (J)], ...].
    """
    t_energy, energy = relative_energy_history(net, masses, series, body)
    energy_threshold_J = energy_threshold(energy[0] if energy.size else np.inf, energy_fraction, energy_threshold_J)
    rises, _ = judged_rise_times(locations, series, judged_from_s)
    t_s = settle_time(t_energy, energy, rises, energy_threshold_J, hold_s, judged_from_s)
    last_rise = float(rises[-1]) if rises.size else None
    history = [[round(float(a), 4), round(float(b), 4)] for a, b in zip(t_energy, energy)
               if abs(a / 0.5 - round(a / 0.5)) < 1e-6]
    return {"window": "capture", "settled": t_s is not None, "settled_at_s": t_s,
            "end_time_s": float(series["time"][-1]), "energy_threshold_J": energy_threshold_J, "hold_s": hold_s,
            "reference_body": body_name, "net_energy_relative_end_J": float(energy[-1]) if energy.size else None,
            "last_rise_s": last_rise, "last_rise_demand": _last_rise_demand(locations, series, judged_from_s, last_rise),
            "net_energy_relative_J": history}


def _last_rise_demand(locations, series, judged_from_s, last_rise):
    """"location criterion" whose running peak rose last (None without a rise)."""
    if last_rise is None:
        return None
    t = np.asarray(series["time"], float)
    for loc in locations:
        judged = judged_demands(loc, t, *joint_loads(loc, series))
        for criterion in loc.criteria():
            if np.any(np.isclose(rise_times(t, judged[criterion][:, None], judged_from_s), last_rise, rtol=0, atol=1e-12)):
                return f"{loc.name} {criterion.replace('_', ' ')}"
    return None


def capture_gap(window: dict) -> Indeterminacy | None:
    """Why a location that held cannot say so under the capture window (rule ``capture_not_over``): the run reached
    its end time before the capture was over; None when it was over.

    Parameters
    ----------
    window : dict
        :func:`capture_window` of the run.

    Returns
    -------
    Indeterminacy or None
    """
    if window["settled"]:
        return None
    energy = window["net_energy_relative_end_J"]
    rising = (f"demand rising at {window['last_rise_s']:.3f} s ({window['last_rise_demand']})"
              if window["last_rise_s"] is not None else "no judged demand")
    energy_text = "not recorded" if energy is None else f"{energy:.3g} J"
    return Indeterminacy("capture_not_over",
                         f"capture not over at end_time = {window['end_time_s']:.3f} s (relative energy {energy_text}, "
                         f"threshold {window['energy_threshold_J']:g} J; {rising}; hold {window['hold_s']:g} s)")


class CaptureMonitor:
    """The settle test while a run goes on: the recorder hands it every output sample's joint loads
    (:meth:`sample`) and every net snapshot (:meth:`snapshot`); :meth:`snapshot` answers True once the capture is
    over, and the recorder then stops the run. The rule is :func:`settle_time`'s, on the same values the verdict
    recomputes from the recorded series (:func:`capture_window`).

    Parameters
    ----------
    locations : list of WeakLocation
        The judged locations.
    masses : (n,) float
        Net node masses (kg).
    body : int
        Reference body index.
    judged_from_s, energy_threshold_J, hold_s : float
        ``structures.skip_initial`` (s), ``capture_energy_J`` (J; None: ``energy_fraction`` of the relative energy
        at the first snapshot, :func:`energy_threshold`), the hold (s, :func:`hold_time`).
    interval_s : float
        The run's output interval (s; the modal filters of locations read through structural modes).
    check_interval_s : float
        Simulated time between two settle checks (s).
    """

    def __init__(self, locations: list[WeakLocation], masses, body: int, judged_from_s: float,
                 energy_threshold_J: float | None, hold_s: float, interval_s: float,
                 check_interval_s: float = CHECK_INTERVAL_S, energy_fraction: float = CAPTURE_ENERGY_FRACTION):
        self.locations = locations
        self.masses = np.asarray(masses, float)
        self.body = body
        self.judged_from_s, self.energy_threshold_J, self.hold_s = judged_from_s, energy_threshold_J, hold_s
        self.check_interval_s = check_interval_s
        self.energy_fraction = energy_fraction
        self._modal = {loc.name: online_modal_loads(loc, interval_s) for loc in locations}
        # joint loads since the last check, as [force, moment] (nj, 2, 3) rows of a table that grows when full (a
        # new stacked array a sample and a list of them cost some 10 us a sample, about 1 us of every step)
        self._loads = np.zeros((int(np.ceil(check_interval_s / interval_s)) + 2, 0, 2, 3))
        self._times = []
        self._modal_loads = {loc.name: [] for loc in locations}
        self._peaks = None                       # running peak of every judged demand
        self.rises: list[float] = []
        self.energy_time: list[float] = []
        self.energy_J: list[float] = []
        self._next_check = 0.0
        self._checked = 0                        # snapshots whose instants a settle check has ruled out
        self._last_above = -np.inf               # the latest of them with the energy at or above the threshold (s)
        self.settled_at_s: float | None = None

    def sample(self, t: float, force_joint, moment_joint) -> None:
        """One output sample's joint loads ((nj, 3) each: N, N m, joint frame); the demands are computed in batches
        at the settle checks (one array copy a sample; the modal filters of locations read through structural
        modes are fed here, as they must see every sample)."""
        k = len(self._times)
        if k == self._loads.shape[0] or self._loads.shape[1] != force_joint.shape[0]:
            self._loads = _grown(self._loads, k, force_joint.shape[0])
        self._loads[k, :, 0] = force_joint
        self._loads[k, :, 1] = moment_joint
        self._times.append(t)
        for loc in self.locations:
            modal = self._modal[loc.name]
            if modal is not None:
                self._modal_loads[loc.name].append(modal.update(np.stack([force_joint[loc.joint],
                                                                          moment_joint[loc.joint]])))

    def _update_rises(self) -> None:
        """Fold the buffered samples' demands into the running peaks (the rises after ``judged_from_s``)."""
        if not self._times:
            return
        loads_all = self._loads[:len(self._times)]                               # (k, nj, 2, 3)
        columns = []
        for loc in self.locations:
            if self._modal[loc.name] is not None:
                loads = np.asarray(self._modal_loads[loc.name], float)          # (k, modes, 2, 3)
                self._modal_loads[loc.name] = []
            else:
                loads = loads_all[:, loc.joint][:, None]                        # (k, 1, 2, 3)
            n_modes = loads.shape[1]
            stacked = loads.reshape(-1, 2, 3)
            values = demands(loc, stacked[:, 0], stacked[:, 1])
            for criterion in loc.criteria():
                columns.append(np.asarray(values[criterion], float).reshape(-1, n_modes).max(axis=1))
        t = np.asarray(self._times)
        self._times = []
        if not columns:
            return
        d = np.stack(columns, axis=1)
        judged = t >= self.judged_from_s
        t, d = t[judged], np.where(np.isfinite(d[judged]), d[judged], np.inf)
        for k in range(t.size):
            if self._peaks is None or np.any(d[k] > self._peaks):
                self.rises.append(float(t[k]))
                self._peaks = d[k].copy() if self._peaks is None else np.maximum(self._peaks, d[k])

    def snapshot(self, t: float, positions_lvlh, velocities_lvlh, com_lvlh, velocity_lvlh, body_to_lvlh,
                 omega_body) -> bool:
        """One net snapshot (the nodes' positions (m) and velocities (m/s), LVLH; every body's com (m), velocity
        (m/s), attitude and body-frame angular velocity (rad/s)); True once the capture is over."""
        b = self.body
        energy = net_kinetic_energy_relative_to_body(self.masses, positions_lvlh, velocities_lvlh, com_lvlh[b],
                                                     velocity_lvlh[b], omega_lvlh(body_to_lvlh[b], omega_body[b]))
        if self.energy_threshold_J is None:          # the first snapshot: the launch's relative energy
            self.energy_threshold_J = energy_threshold(energy, self.energy_fraction)
        self.energy_time.append(float(t))
        self.energy_J.append(energy)
        if t + 1e-12 < self._next_check or self.settled_at_s is not None:
            return self.settled_at_s is not None
        self._next_check = t + self.check_interval_s
        self._update_rises()
        # settle_time's rule on the instants since the last check only (first_settled: the same answer as on the
        # whole history; over the whole history every 0.1 s, a check cost in proportion to the simulated time)
        start = max(self.judged_from_s, self.energy_time[0])
        self.settled_at_s, self._last_above = first_settled(
            self.energy_time[self._checked:], self.energy_J[self._checked:], self.rises, self.energy_threshold_J,
            self.hold_s, start, self._last_above)
        self._checked = len(self.energy_time)
        return self.settled_at_s is not None


def _grown(loads, k: int, n_joints: int):
    """The monitor's load table ``loads`` ((rows, nj, 2, 3)) with its first ``k`` rows kept and twice the rows
    (the first sample's joint count when it had none)."""
    if loads.shape[1] != n_joints:
        return np.zeros((loads.shape[0], n_joints, 2, 3))
    grown = np.zeros((2 * loads.shape[0], n_joints, 2, 3))
    grown[:k] = loads[:k]
    return grown
