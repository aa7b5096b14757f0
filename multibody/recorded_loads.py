"""Recorded contact loads applied to the debris bodies: the second step of the seed paper's
sequential method (Cuadrat-Grzybowski & Gill 2024, Sec. 2.1 and 3.3: the net's contact forces on a
fixed target, recorded, then fed to the free multibody debris).

The loads are a zero-order hold of interval averages, as the impact recorder writes them: value
``k`` acts on (time[k-1], time[k]], so the impulse of every interval is the recorded one whatever
the debris does. Forces act in LVLH (the paper's Fig. 6 frame), moments about each body's CoM in
its body frame (Fig. 7), both at the CoM.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from exudyn.itemInterface import LoadForceVector, LoadTorqueVector, MarkerBodyRigid


@dataclass
class RecordedBodyLoads:
    """Contact loads recorded on each body, held over each output interval.

    Attributes
    ----------
    time : (k,) float               End of each interval (s); the first interval starts at 0.
    force_lvlh : (k, nb, 3) float   Mean force on each body over the interval (N), LVLH.
    moment_body : (k, nb, 3) float  Mean moment about each body's CoM (N m), body frame.
    reference_energy : float        Energy (J) the run's energy balance is judged against (the
                                    recording run's reference: the net's launch energy).
    """

    time: np.ndarray
    force_lvlh: np.ndarray
    moment_body: np.ndarray
    reference_energy: float

    def interval(self, t: float) -> int:
        """Index of the interval holding ``t``; the last one past the end (then the load is 0).

        Parameters
        ----------
        t : float
            Time (s).
        """
        return int(np.searchsorted(self.time, t - 1e-9 * (self.time[1] - self.time[0] if len(self.time) > 1 else 1.0)))

    def held(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Loads held at ``t`` on every body; zero outside the record.

        Parameters
        ----------
        t : float
            Time (s).

        Returns
        -------
        force_lvlh : (nb, 3) float
            Forces at the CoMs (N), LVLH.
        moment_body : (nb, 3) float
            Moments about the CoMs (N m), each body's frame.
        """
        k = self.interval(t)
        if t <= 0.0 or k >= len(self.time):
            return np.zeros_like(self.force_lvlh[0]), np.zeros_like(self.moment_body[0])
        return self.force_lvlh[k], self.moment_body[k]

    def at(self, t: float, body: int) -> tuple[np.ndarray, np.ndarray]:
        """Loads on one body at ``t``; zero outside the record.

        Parameters
        ----------
        t : float
            Time (s).
        body : int
            Body index.

        Returns
        -------
        force_lvlh : (3,) float
            Force at the CoM (N), LVLH.
        moment_body : (3,) float
            Moment about the CoM (N m), body frame.
        """
        force_lvlh, moment_body = self.held(t)
        return force_lvlh[body], moment_body[body]


def applied_work(loads: RecordedBodyLoads, step: float, t0: float, t1: float, com_start_lvlh, com_end_lvlh,
                 velocity_start_lvlh, omega_start_body, omega_end_body) -> float:
    """Work (J) the loads do on all bodies over (t0, t1], one interval of the record.

    The solver reads the record half a step back (:class:`_HeldLoad`), so the interval's load acts
    from t0 + h/2 and the previous one up to it: the force's work is F_k . (x1 - x0) plus
    (F_{k-1} - F_k) . v0 h/2; the moment's uses the mean body rate the same way.

    Parameters
    ----------
    loads : RecordedBodyLoads                         The record (forces LVLH, moments body frames).
    step : float                                      The solver's step h (s).
    t0, t1 : float                                    Start and end of the interval (s).
    com_start_lvlh, com_end_lvlh : (nb, 3) float      Body CoMs at t0 and t1 (m), LVLH.
    velocity_start_lvlh : (nb, 3) float               Body CoM velocities at t0 (m/s), LVLH.
    omega_start_body, omega_end_body : (nb, 3) float  Body rates at t0 and t1 (rad/s), body frames.
    """
    (force_lvlh, moment_body), (force_before_lvlh, moment_before_body) = loads.held(t1), loads.held(t0)
    displacement_lvlh = np.asarray(com_end_lvlh) - np.asarray(com_start_lvlh)
    omega0_body = np.asarray(omega_start_body)
    mean_omega_body = 0.5 * (omega0_body + np.asarray(omega_end_body))
    work = np.sum(force_lvlh * displacement_lvlh) + (t1 - t0) * np.sum(moment_body * mean_omega_body)
    handover = 0.5 * step * (np.sum((force_before_lvlh - force_lvlh) * np.asarray(velocity_start_lvlh))
                             + np.sum((moment_before_body - moment_body) * omega0_body))
    return float(work + handover)


class _HeldLoad:
    """Exudyn load user function: one body's recorded force or moment at the solver's time.

    VelocityVerlet applies the force evaluated at the end of a step half in that step and half in
    the next, so an evaluation at t stands for (t - h/2, t + h/2]; reading the record at t - h/2
    puts each evaluation's impulse in the interval it was recorded in (exact impulses; reading it
    at t gave one half step too many at each switch-on, 1e-3 of a 500-step hold).
    """

    def __init__(self, loads: RecordedBodyLoads, body: int, moment: bool, step: float, body_to_node=None):
        self.loads, self.body, self.part, self.lag = loads, body, int(moment), 0.5 * step
        # a moment is recorded in the body frame and applied in the node's (multibody.node_frame)
        self.body_to_node = body_to_node if moment and body_to_node is not None else None

    def __call__(self, mbs, t, load_vector):
        value = self.loads.at(t - self.lag, self.body)[self.part]
        return (value if self.body_to_node is None else self.body_to_node @ value).tolist()


def add_recorded_loads(mbs, body_objects, loads: RecordedBodyLoads, step: float, node_to_body=None) -> None:
    """Add, for every body, the recorded force (LVLH) and moment (body frame) at its CoM, read for
    a VelocityVerlet step of ``step``.

    Parameters
    ----------
    mbs : exudyn.MainSystem
        System to add the loads to.
    body_objects : list of int
        Exudyn object numbers of the bodies, in the record's body order.
    loads : RecordedBodyLoads
        The record (forces LVLH, moments body frame).
    step : float
        The solver's (VelocityVerlet) step (s).
    node_to_body : (nb, 3, 3) float, optional
        Each body's Exudyn node frame in its body frame (:mod:`multibody.node_frame`); None: the same.
    """
    for k, body in enumerate(body_objects):
        body_to_node = None if node_to_body is None else np.asarray(node_to_body[k], float).T
        marker = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
        mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVector=[0.0] * 3, bodyFixed=False,
                                    loadVectorUserFunction=_HeldLoad(loads, k, False, step)))
        mbs.AddLoad(LoadTorqueVector(markerNumber=marker, loadVector=[0.0] * 3, bodyFixed=True,
                                     loadVectorUserFunction=_HeldLoad(loads, k, True, step, body_to_node)))
