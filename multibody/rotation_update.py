"""The rigid bodies' attitudes advanced exactly: Exudyn's explicit Lie-group update loses small turns.

Measured (Exudyn 1.13.6; ``NodeRigidBodyRotVecLG`` with ``explicit.useLieGroupIntegration``, VelocityVerlet
and RK44 alike; ``tests/multibody/test_rotation_update.py``; docs/model.md): from its reference attitude a
free body spinning at a constant rate does not turn at all while its increment per step ``omega h`` is
below about 2e-8 rad (at the shipped step 1e-4 s: every rate below about 2e-4 rad/s, 0.01 deg/s). The
floor sits where ``cos(omega h) = 1 - (omega h)^2 / 2`` rounds to 1 in double precision (2.1e-8 rad), the
signature of a log map read through the cosine of the angle; away from the identity the update regains
its precision (2 % of a 1e-9 rad increment wrong at 1e-6 rad off it, exact to round-off from 0.1 rad). Angular velocities are integrated
correctly; only the attitude stays put. So a structure that vibrates by micro-radians, or a debris that
starts at rest and turns slowly, sees no elastic rotation in its joints until its rate crosses the floor,
and the step at which that happens decides its loads (the Ka-band boom and dish of envisat_small:
docs/structures.md, "Are the judged peaks converged?").

VelocityVerlet's end-of-step attitude is known before the step
(:func:`multibody.kernel.verlet_evaluation_state`: the rotation vector composed with the mid-step angular
velocity through quaternions, accurate at every angle). :class:`ExactRotations` keeps it from the
pre-step function and writes it over Exudyn's after the step, so every attitude the run carries, records
and starts its next step from is exact to round-off. Inside a step Exudyn evaluates its joint springs at
its own end attitude; near the identity that attitude has a dead zone (a total rotation vector below about
2e-8 rad comes out as zero), which the restore cannot reach: :mod:`multibody.node_frame` keeps every
node's rotation vector about 2 rad from zero, where Exudyn's update is exact to round-off, so the restore
is now a second guard (a body that turned back near its node's identity). The Runge-Kutta integrators are
not restored (their stages' attitudes are not known outside Exudyn); the node frames serve them too.
"""
from __future__ import annotations

import numpy as np


def body_rotation_index(n_net_coordinates: int, n_bodies: int, state_index=None) -> np.ndarray:
    """Where the bodies' rotation vectors sit in Exudyn's ODE2 vector.

    Parameters
    ----------
    n_net_coordinates : int
        Net coordinates ahead of the bodies' in the coupled object (3 n; 0 when the kernel holds the net).
    n_bodies : int
        Rigid bodies (6 coordinates each: displacement (m, LVLH), rotation vector (rad)).
    state_index : (N,) int or None
        The coupled object's coordinates in Exudyn's system vector (None: the whole vector, in order).

    Returns
    -------
    (3 n_bodies,) int
        Indices into Exudyn's ODE2 coordinates of each body's three rotation-vector components.
    """
    local = np.array([n_net_coordinates + 6 * b + 3 + k for b in range(n_bodies) for k in range(3)], np.int64)
    return local if state_index is None else np.asarray(state_index, np.int64)[local]


class ExactRotations:
    """The end-of-step rotation vectors of every body, kept before the step and restored after it.

    Parameters
    ----------
    n_net_coordinates : int
        Net coordinates ahead of the bodies' in the coupled object (3 n; 0 when the kernel holds the net).
    n_bodies : int
        Rigid bodies.
    state_index : (N,) int or None
        The coupled object's coordinates in Exudyn's system vector (None: the whole vector, in order).
    """

    def __init__(self, n_net_coordinates: int, n_bodies: int, state_index=None):
        self._local = body_rotation_index(n_net_coordinates, n_bodies)
        self.rotation_index = body_rotation_index(n_net_coordinates, n_bodies, state_index)
        self._next = None

    def keep(self, q_next: np.ndarray) -> None:
        """Keep the step's exact end rotation vectors.

        Parameters
        ----------
        q_next : (N,) float
            The coupled object's end-of-step coordinates (m, rad) (:func:`multibody.kernel.verlet_evaluation_state`).
        """
        self._next = np.asarray(q_next)[self._local]  # a gather: a new array

    def restore(self, mbs) -> None:
        """Write the kept rotation vectors over Exudyn's current coordinates (after the step).

        Parameters
        ----------
        mbs : exudyn.MainSystem
            The running system.
        """
        if self._next is None:
            return
        # a view of Exudyn's current coordinates: written in place (checked: the next step starts from it),
        # about 1 us against 8 for a copy set back with SetODE2Coordinates
        self.restore_into(mbs.systemData.GetODE2Coordinates(copy=False))

    def restore_into(self, q) -> None:
        """:meth:`restore` through a view of Exudyn's current coordinates the caller holds.

        Parameters
        ----------
        q : (N,) float
            Exudyn's ODE2 coordinates, a view (``GetODE2Coordinates(copy=False)``), written in place.
        """
        if self._next is None:
            return
        q[self.rotation_index] = self._next
        self._next = None

    def restoring(self, post_step):
        """A post-step function that restores the rotations, then calls ``post_step``.

        Parameters
        ----------
        post_step : callable ``(mbs, t) -> bool``
            The run's own post-step function (the recorder's).

        Returns
        -------
        callable ``(mbs, t) -> bool``
        """
        def hook(mbs, t):
            self.restore(mbs)
            return post_step(mbs, t)
        return hook
