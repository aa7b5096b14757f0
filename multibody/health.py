"""Numerical health of a running simulation: a diverged or failed run must never pass for a result.

Pure checks on SI arrays, used by every simulation loop of the tool (impact, tows, replays):

* every state coordinate finite (a NaN or an infinity means the integration is lost);
* the energy balance closed: the drift of (mechanical + dissipated + released) energy against
  its value at the start stays below a stated fraction of the run's reference energy (for an
  impact, the net's kinetic energy at launch: an explicit integrator that is unstable for the
  contact or thread stiffness pumps energy in long before the state turns NaN);
* the integrator's own success flag (``exudyn.SolveDynamic`` returns False when it stops).

A failed check raises :class:`SimulationFailed`, whose message names the time, the quantity and
the likely cause with the stable step estimated; callers record the run as ``failed`` and its
verdict as ``indeterminate``, never as "no secondary debris".
"""
from __future__ import annotations

import math

import numpy as np

#: Allowed drift of the energy balance, as a fraction of the reference energy. The step study
#: of docs/model.md keeps the reference case within 1 %; a run past 5 % has stopped being the
#: physics it claims to be (an unstable explicit step grows the energy without bound).
ENERGY_DRIFT_LIMIT = 0.05

#: How long the drift may stay above the limit before the run fails (s). A step that holds a whole
#: sub-cycled contact books the contact's work with up to one step's delay (a node striking a
#: plane at 20 m/s with 5e-5 s steps reads 20 % of its energy off for one sample,
#: tests/multibody/test_contact.py); an unstable integration only grows.
ENERGY_PERSISTENCE_S = 2e-3
#: A drift this large fails at once: the balance is off by more than the whole reference energy.
ENERGY_DRIFT_HARD_LIMIT = 1.0

#: An explicit central-difference (Verlet) step is stable for h < 2 / omega_max; the factor
#: keeps a margin for the nonlinear (stiffening Hertz) contact and the coupled modes.
STABLE_STEP_FACTOR = 0.5


class SimulationFailed(RuntimeError):
    """A simulation stopped because its numerics failed; the message says when, what and why.

    Attributes
    ----------
    time : float
        Simulated time of the failed check (s).
    quantity : str
        What failed ("state", "energy balance", "integrator").
    cause : str
        The likely cause in words, with the stable step where one is known.
    """

    exit_code = 5

    def __init__(self, time: float, quantity: str, cause: str):
        self.time = float(time)
        self.quantity = quantity
        self.cause = cause
        super().__init__(f"simulation failed at t = {self.time:.6g} s: {quantity}; {cause}")

    def __reduce__(self):
        # sent back from sweep worker processes: rebuild from the three fields, not from the message
        return type(self), (self.time, self.quantity, self.cause)


def stable_step_estimate(stiffness: float, mass: float) -> float:
    """Largest explicit step (s) that resolves a spring ``stiffness`` (N/m) on a ``mass`` (kg).

    .. math:: h_{max} = 0.5 \\cdot 2 / \\omega, \\quad \\omega = \\sqrt{k / m}

    (central-difference stability, Bathe 2014, Sec. 9.2.1, with the margin of
    :data:`STABLE_STEP_FACTOR`). Returns ``inf`` for a zero stiffness.

    Parameters
    ----------
    stiffness : float
        Spring stiffness (N/m).
    mass : float
        Mass the spring acts on (kg).
    """
    if not (stiffness > 0 and mass > 0):
        return math.inf
    return STABLE_STEP_FACTOR * 2.0 / math.sqrt(stiffness / mass)


def first_non_finite(values) -> int | None:
    """Index of the first non-finite entry of ``values`` (any shape, flattened), or None.

    Parameters
    ----------
    values : array_like of float
        Any shape and unit (state coordinates, forces, ...).
    """
    flat = np.asarray(values, float).ravel()
    finite = np.isfinite(flat)
    if finite.all():
        return None
    return int(np.argmin(finite))


def check_finite(time: float, values, quantity: str, cause: str) -> None:
    """Raise :class:`SimulationFailed` when ``values`` holds a NaN or an infinity.

    Parameters
    ----------
    time : float
        Simulated time of the check (s).
    values : array_like of float
        Values to check, any shape and unit.
    quantity : str
        What ``values`` are, for the message ("state", ...).
    cause : str
        The likely cause in words, added to the failure message.
    """
    k = first_non_finite(values)
    if k is not None:
        raise SimulationFailed(time, f"{quantity} is not finite (entry {k})", cause)


def energy_drift(total_energy: float, initial_energy: float, reference_energy: float) -> float:
    """Drift of the energy balance relative to ``reference_energy``; ``inf`` when the total is not finite.

    Parameters
    ----------
    total_energy : float
        Mechanical + dissipated + released energy now (J).
    initial_energy : float
        The same balance at the start (J).
    reference_energy : float
        Energy the drift is measured against (J).

    Returns
    -------
    float
        ``|total - initial| / reference`` (-).
    """
    if not math.isfinite(total_energy):
        return math.inf
    return abs(total_energy - initial_energy) / max(abs(reference_energy), 1e-300)


def check_energy(time: float, total_energy: float, initial_energy: float, reference_energy: float,
                 cause: str, limit: float = ENERGY_DRIFT_LIMIT) -> float:
    """The relative drift of :func:`energy_drift`; :class:`SimulationFailed` when it exceeds ``limit``.

    Parameters
    ----------
    time : float
        Simulated time of the check (s).
    total_energy, initial_energy, reference_energy : float
        As in :func:`energy_drift` (J).
    cause : str
        The likely cause in words, added to the failure message.
    limit : float
        Allowed drift, fraction of ``reference_energy`` (-).
    """
    drift = energy_drift(total_energy, initial_energy, reference_energy)
    if drift > limit:
        raise SimulationFailed(time, f"energy balance drifted by {100 * drift:.3g} % of the reference energy "
                                     f"{reference_energy:.4g} J (limit {100 * limit:g} %)", cause)
    return drift


def check_solver_flag(success, end_time: float, reached_time: float, cause: str) -> None:
    """Raise :class:`SimulationFailed` when the integrator reported failure (``success`` False).

    Parameters
    ----------
    success : bool
        The integrator's flag.
    end_time : float
        Time the run was to reach (s).
    reached_time : float
        Time it reached (s).
    cause : str
        The likely cause in words, added to the failure message.
    """
    if success is False:
        raise SimulationFailed(reached_time, f"the integrator stopped before the end time {end_time:g} s", cause)


class HealthWatch:
    """Checks a running simulation at the instants its loop chooses; remembers the first failure.

    A solver hook calls :meth:`state` (finite coordinates) and :meth:`energy` (balance drift) and
    stops the integration when either returns False; the caller then raises :attr:`failure`.

    Parameters
    ----------
    cause : str
        The likely cause of a failure in words (for example the step against the stable step),
        added to every failure message.
    reference_energy : float, optional
        Energy (J) the drift is measured against; None turns the energy check off (runs driven by
        thrust or control, whose balance the tool does not close).
    limit : float
        Allowed drift as a fraction of ``reference_energy`` (default :data:`ENERGY_DRIFT_LIMIT`).
    """

    def __init__(self, cause: str, reference_energy: float | None = None, limit: float = ENERGY_DRIFT_LIMIT):
        self.cause = cause
        self.reference_energy = reference_energy
        self.limit = limit
        self.initial_energy: float | None = None
        self.max_drift = 0.0
        self.failure: SimulationFailed | None = None
        self._over_since: float | None = None  # time the drift went above the limit, while it stays there
        self._pending = None                   # (time, energy) of the last sample above the limit

    @property
    def ok(self) -> bool:
        return self.failure is None

    def _guard(self, check, *args) -> bool:
        try:
            check(*args)
        except SimulationFailed as failure:
            self.failure = self.failure or failure
        return self.ok

    def state(self, time: float, *arrays, quantity: str = "state") -> bool:
        """False (and :attr:`failure` set) when any of ``arrays`` holds a NaN or an infinity.

        Parameters
        ----------
        time : float
            Simulated time of the check (s).
        *arrays : array_like of float
            State arrays (coordinates, velocities), any shape and unit.
        quantity : str
            What the arrays are, for the message.
        """
        # Fast path: a sum is finite only when every entry is (a NaN or an infinity propagates; a finite
        # sum that overflows only sends the array to the full check).
        if self.ok and all(math.isfinite(np.add.reduce(a, axis=None)) for a in arrays):
            return True
        return all(self._guard(check_finite, time, a, quantity, self.cause) for a in arrays)

    def energy(self, time: float, total_energy: float) -> bool:
        """False (and :attr:`failure` set) when the balance ``total_energy`` (J) has drifted past the
        limit for :data:`ENERGY_PERSISTENCE_S`, or past :data:`ENERGY_DRIFT_HARD_LIMIT` at once.
        The first call sets the initial energy.

        Parameters
        ----------
        time : float
            Simulated time of the check (s).
        total_energy : float
            Mechanical + dissipated + released energy now (J).
        """
        if self.reference_energy is None or not self.ok:
            return self.ok
        if self.initial_energy is None:
            self.initial_energy = float(total_energy)
        drift = energy_drift(total_energy, self.initial_energy, self.reference_energy)
        if math.isfinite(drift):
            self.max_drift = max(self.max_drift, drift)
        if drift <= self.limit:
            self._over_since = None
            return True
        if self._over_since is None:
            self._over_since = time
        if drift > ENERGY_DRIFT_HARD_LIMIT or time - self._over_since >= ENERGY_PERSISTENCE_S:
            return self._guard(check_energy, time, total_energy, self.initial_energy, self.reference_energy,
                               self.cause, self.limit)
        self._pending = (time, total_energy)
        return True

    def finish(self) -> bool:
        """At the end of a run: a drift still above the limit fails however briefly it lasted."""
        if self.ok and self._over_since is not None:
            time, total = self._pending
            self._guard(check_energy, time, total, self.initial_energy, self.reference_energy, self.cause, self.limit)
        return self.ok

    def summary(self) -> dict:
        """JSON-ready record of the checks (for summary.json and the manifest)."""
        return {"healthy": self.ok, "energy_reference_J": self.reference_energy,
                "energy_drift_limit": self.limit if self.reference_energy is not None else None,
                "energy_max_drift": self.max_drift if self.reference_energy is not None else None,
                "failure": None if self.ok else {"time_s": self.failure.time, "quantity": self.failure.quantity,
                                                 "cause": self.failure.cause}}
