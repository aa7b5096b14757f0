"""The net integrated inside the compiled kernel; Exudyn integrates the bodies and joints.

Exudyn's VelocityVerlet step from (q, v, a) is: v += h/2 a; q += h v; a = M^-1 f(q, v);
v += h/2 a. For the net's lumped masses M is diagonal, so the same step costs a handful of
flops per coordinate, while Exudyn spends about 170 ns per object and a sparse LU solve on
all 3 n coordinates every step (EXUDYN-NOTES). Here the kernel holds the net's state and
takes exactly Exudyn's step for it, inside the bodies' step: the pre-step function

1. predicts the state at which Verlet evaluates the forces, for the net (here) and for the
   bodies (from Exudyn's coordinates, :func:`multibody.kernel.verlet_evaluation_state`);
2. evaluates the coupled forces there with the same kernel as the all-Exudyn path
   (:meth:`multibody.kernel.KernelData.evaluate`: threads, contact with its sub-cycled
   impulses, friction, Clohessy-Wiltshire, mounts);
3. completes the net's step (a = f / m, v += h/2 a) and hands the bodies their part of the
   force vector, which Exudyn applies in its own step together with the joints.

So the net follows the same trajectory as when Exudyn integrates it (to round-off: the
all-Exudyn path solves f / m through a sparse LU), and every node-body impulse still goes
to the bodies within the step it acts in. ``tests/multibody/test_kernel_net.py`` runs both
paths on a small case and compares them.

Layout of the net state: ``q`` (3 n,) node displacement from the reference position (m),
``qt`` (3 n,) velocity (m/s), ``qtt`` (3 n,) acceleration (m/s^2), all LVLH, node-major.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.kernel import KernelData, verlet_evaluation_state


@njit(cache=True)
def verlet_predict(q, qt, qtt, step, q_eval, qt_eval):
    """Evaluation state of Verlet's step for the net: ``qt_eval = qt + h/2 qtt`` (m/s) and
    ``q_eval = q + h qt_eval`` (m) into the first 3 n entries of the work vectors."""
    half = 0.5 * step
    for k in range(q.shape[0]):
        v_half = qt[k] + half * qtt[k]
        qt_eval[k] = v_half
        q_eval[k] = q[k] + step * v_half


@njit(cache=True)
def verlet_complete(q, qt, qtt, q_eval, qt_eval, force, mass, step):
    """End of Verlet's step for the net: ``qtt = f / m``, ``qt = v_half + h/2 qtt``, ``q = q_eval``."""
    half = 0.5 * step
    for i in range(mass.shape[0]):
        inverse = 1.0 / mass[i]
        for d in range(3):
            k = 3 * i + d
            a = force[k] * inverse
            qtt[k] = a
            qt[k] = qt_eval[k] + half * a
            q[k] = q_eval[k]


class KernelNet:
    """The net's state held by the kernel, and the Exudyn pre-step function that advances it.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    coupled_object : int
        The ``ObjectGenericODE2`` spanning the rigid-body nodes, whose force vector carries
        the net's (and the orbit's) forces on the bodies.
    kernel : KernelData
    net_velocity : (n, 3) float
        Initial node velocities (m/s), LVLH.
    step : float
        Integrator step (s).
    state_index : (6 nb,) int or None
        Where the bodies' coordinates sit in Exudyn's system vectors (None: the whole vector).
    """

    def __init__(self, mbs, coupled_object, kernel: KernelData, net_velocity, step, state_index):
        n, nb = kernel.n_nodes, kernel.n_bodies
        self.mbs = mbs
        self.coupled_object = coupled_object
        self.kernel = kernel
        self.step = step
        self.n_bodies = nb
        self.state_index = state_index
        self.reference = kernel.net_reference
        self.q = np.zeros(3 * n)
        self.qt = np.ascontiguousarray(net_velocity, float).reshape(3 * n).copy()
        self.qtt = np.zeros(3 * n)
        # the kernel's coordinate layout: net first, then 6 per body (multibody.kernel)
        self._q_eval = np.zeros(3 * n + 6 * nb)
        self._qt_eval = np.zeros(3 * n + 6 * nb)
        self._n3 = 3 * n
        # The solver's initial acceleration uses the force at the initial state.
        qb, vb = self._bodies(mbs.systemData.GetODE2Coordinates(), mbs.systemData.GetODE2Coordinates_t())
        self._q_eval[self._n3:], self._qt_eval[self._n3:] = qb, vb
        self._qt_eval[:self._n3] = self.qt
        force = kernel.evaluate(self._q_eval, self._qt_eval, 0.0)
        self.qtt[:] = force[:self._n3] / np.repeat(kernel.net_mass, 3)
        self._set_body_force(force)

    def _bodies(self, *system_vectors):
        if self.state_index is None:
            return tuple(np.asarray(v) for v in system_vectors)
        return tuple(np.asarray(v)[self.state_index] for v in system_vectors)

    def _set_body_force(self, force):
        self.mbs.SetObjectParameter(self.coupled_object, "forceVector", force[self._n3:])

    def __call__(self, mbs, t):
        data = mbs.systemData
        qb, vb, ab = self._bodies(data.GetODE2Coordinates(), data.GetODE2Coordinates_t(), data.GetODE2Coordinates_tt())
        qb_eval, vb_half = verlet_evaluation_state(qb, vb, ab, self.step, 0, self.n_bodies)
        verlet_predict(self.q, self.qt, self.qtt, self.step, self._q_eval, self._qt_eval)
        self._q_eval[self._n3:] = qb_eval
        self._qt_eval[self._n3:] = vb_half
        # t is the time of the evaluation state (see multibody.impact.VerletForces)
        force = self.kernel.evaluate(self._q_eval, self._qt_eval, t)
        verlet_complete(self.q, self.qt, self.qtt, self._q_eval, self._qt_eval, force, self.kernel.net_mass, self.step)
        self._set_body_force(force)
        return True

    def positions(self) -> np.ndarray:
        """(n, 3) node positions (m), LVLH, at the end of the last step."""
        return self.reference + self.q.reshape(-1, 3)

    def velocities(self) -> np.ndarray:
        """(n, 3) node velocities (m/s), LVLH, at the end of the last step (a view)."""
        return self.qt.reshape(-1, 3)
