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
``qt`` (3 n,) velocity (m/s), ``qtt`` (3 n,) acceleration (m/s^2), all LVLH, coordinate-major (all x,
then all y, then all z: the layout of :func:`multibody.kernel.coupled_forces_soa`, so that the passes
over the nodes vectorize and nothing is copied between layouts; :meth:`KernelNet.positions` gives (n, 3)).

Speed: the whole pre-step is one compiled call (:func:`kernel_net_step`) on a numba structref
(:class:`NetStepModel`) that holds the kernel's groups of arrays and the net's state: a call with the
kernel's 40 arrays as arguments cost 5-10 us in numba's dispatcher alone, a structref about 2 us.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from numba.experimental import structref

from multibody.jit_cache import UnliteralStructRef
from multibody.kernel import (
    KernelData,
    coupled_forces_soa,
    verlet_evaluation_state_into,
)
from multibody.net_tether import NetTether, add_tether_force, no_tether


@structref.register
class NetStepModelType(UnliteralStructRef):
    """Numba type of :class:`NetStepModel`."""


#: Fields of :class:`NetStepModel`: the groups and constants of :class:`multibody.kernel.KernelData`
#: (same names, same buffers: what the kernel accumulates there, the recorder reads there), then the
#: net's state and the work vectors of this module.
KERNEL_FIELDS = ("net", "bodies", "shapes", "law", "mounts", "mean_motion", "step", "stage_weight", "buffers")
STATE_FIELDS = ("n_substeps", "q", "qt", "qtt", "qt_eval", "inverse_mass", "reference_soa", "tether")


class NetStepModel(structref.StructRefProxy):
    """Everything :func:`kernel_net_step` reads and writes, as one numba structref.

    Fields: those of :class:`multibody.kernel.KernelData` (:data:`KERNEL_FIELDS`, the same arrays)
    and ``n_substeps`` (int, contact sub-steps per step), ``q``, ``qt``, ``qtt`` ((3 n,) the net's
    state, coordinate-major, module doc; inside a step ``q`` holds the step's end, the evaluation state's
    positions), ``qt_eval`` ((3 n + 6 nb,) work space: the net's mid-step velocities (first 3 n), the bodies'
    (last 6 nb)), ``inverse_mass`` ((3 n,) 1 / node mass per coordinate (1/kg)), ``reference_soa`` ((3 n,)
    the nodes' reference positions (m), LVLH), both coordinate-major, and ``tether``
    (:class:`multibody.net_tether.NetTether`, the main tether to the chaser; node -1: none).
    """


structref.define_proxy(NetStepModel, NetStepModelType, KERNEL_FIELDS + STATE_FIELDS)


def net_step_model(kernel: KernelData, net_velocity, tether: NetTether | None = None) -> tuple:
    """The structref for ``kernel`` with the net in its reference position; returns it and its ``q``,
    ``qt`` arrays (a structref proxy has no Python attributes: its fields are read in compiled code).

    Parameters
    ----------
    kernel : KernelData
    net_velocity : (n, 3) float
        Initial node velocities (m/s), LVLH.
    tether : NetTether or None
        The main tether (:mod:`multibody.net_tether`); None: none.
    """
    n, nb = kernel.n_nodes, kernel.n_bodies
    n_substeps = max(1, int(np.ceil(kernel.step / kernel.contact_substep - 1e-9))) if np.isfinite(
        kernel.contact_substep) else 1
    values = [getattr(kernel, name) for name in KERNEL_FIELDS]
    values = [float(v) if isinstance(v, (float, np.floating, int)) else v for v in values]
    coordinate_major = np.ascontiguousarray(np.asarray(net_velocity, float).reshape(n, 3).T).reshape(3 * n)
    state = [n_substeps, np.zeros(3 * n), coordinate_major, np.zeros(3 * n), np.zeros(3 * n + 6 * nb),
             np.tile(1.0 / np.asarray(kernel.net.mass, float), 3),
             np.ascontiguousarray(np.asarray(kernel.net.reference_lvlh, float).T).reshape(3 * n),
             no_tether() if tether is None else tether]
    return _new_net_step_model(*values, *state), state[1], state[2]


@njit(cache=True)
def _new_net_step_model(net, bodies, shapes, law, mounts, mean_motion, step, stage_weight, buffers, n_substeps, q, qt,
                        qtt, qt_eval, inverse_mass, reference_soa, tether):
    """``NetStepModel(...)`` (the fields of :data:`KERNEL_FIELDS` and :data:`STATE_FIELDS`, in order), compiled once
    into numba's on-disk cache: the proxy class's own constructor is compiled afresh in every process, 2.3-2.6 s CPU
    before a run's first step (helper speed20: 0.17 s through this function from the cache)."""
    return NetStepModel(net, bodies, shapes, law, mounts, mean_motion, step, stage_weight, buffers, n_substeps, q, qt,
                        qtt, qt_eval, inverse_mass, reference_soa, tether)


# inlined (numba IR), with the buffers its caller already read: each read of the structref's buffers counts their
# 40 arrays in and out (reference counts; the force pass itself counts none, multibody.jit_cache.NO_REFCOUNTS)
@njit(cache=True, inline="always")
def _forces(m, buffers, q_bodies, qt_bodies, n_substeps):
    """The coupled forces at the net's evaluation state (positions in ``buffers.work_soa[0]``, written by the
    caller; velocities ``m.qt_eval``, coordinate-major) and the bodies' (``q_bodies``, ``qt_bodies``):
    :func:`multibody.kernel.coupled_forces_soa` on the structref ``m`` and its ``buffers`` (``m.buffers``). Writes
    the nodes' forces into ``buffers.work_soa[2]`` ((3, n) coordinate-major, N, LVLH) and the bodies' generalized
    forces into the last 6 nb entries of ``buffers.force`` (:func:`_body_forces`)."""
    n3 = m.q.shape[0]
    n = n3 // 3
    x_soa, force_soa = buffers.work_soa[0], buffers.work_soa[2]
    v_soa = m.qt_eval[:n3].reshape(3, n)
    body_force = _body_forces(buffers.force, q_bodies.shape[0])
    coupled_forces_soa(x_soa, v_soa, q_bodies, qt_bodies, m.net, m.bodies, m.shapes, m.law, m.mounts,
                       m.mean_motion, m.step, n_substeps, m.stage_weight, buffers, force_soa, body_force)


@njit(cache=True, inline="always")
def _body_forces(force, n_body_coordinates):
    """The bodies' generalized forces (6 nb,): the tail of the kernel's force buffer ``force``."""
    return force[force.shape[0] - n_body_coordinates:]


@njit(cache=True)
def kernel_net_start(m, q_bodies, qt_bodies):
    """The forces at the initial state (the solver's initial acceleration; no sub-cycling, as
    :meth:`~multibody.kernel.KernelData.evaluate` at time 0): sets the net's acceleration and
    returns the bodies' generalized forces (6 nb,).

    Parameters
    ----------
    m : NetStepModel
    q_bodies, qt_bodies : (6 nb,) float
        The bodies' initial coordinates and velocities (Exudyn's layout, :mod:`multibody.kernel`).
    """
    n3 = m.q.shape[0]
    n = n3 // 3
    x_flat, q, reference = m.buffers.work_soa[0].reshape(n3), m.q, m.reference_soa
    for k in range(n3):
        x_flat[k] = reference[k] + q[k]
    m.qt_eval[:n3] = m.qt
    buffers = m.buffers
    _forces(m, buffers, q_bodies, qt_bodies, 1)
    if m.tether.node[0] >= 0:   # the main tether (multibody.net_tether); nothing booked at the initial state
        add_tether_force(buffers.work_soa[0], m.qt_eval[:n3].reshape(3, n), m.tether, buffers.work_soa[2], 0.0)
    force = buffers.work_soa[2].reshape(n3)
    for k in range(n3):
        m.qtt[k] = force[k] / m.net.mass[k % n]
    return _body_forces(buffers.force, q_bodies.shape[0]).copy()


@njit(cache=True)
def kernel_net_step(m, q_bodies, qt_bodies, qtt_bodies, time, q_next_bodies, force_bodies):
    """One VelocityVerlet step of the net inside the bodies' step (module doc); writes the bodies'
    generalized forces (6 nb,) at the evaluation state, for Exudyn's coupled object, into ``force_bodies``.

    Parameters
    ----------
    m : NetStepModel
    q_bodies, qt_bodies, qtt_bodies : (6 nb,) float
        The bodies' coordinates, velocities and accelerations at the start of the step (Exudyn's
        layout, :mod:`multibody.kernel`).
    time : float
        Time of the evaluation state, the step's end (s); 0 evaluates without sub-cycling.
    q_next_bodies : (6 nb,) float
        Filled with the bodies' evaluation state, the step's end coordinates (m, rad; the rotation vectors
        exact, :func:`multibody.kernel.verlet_evaluation_state`), for :class:`multibody.rotation_update.ExactRotations`.
    force_bodies : (6 nb,) float
        Output: the bodies' generalized forces (a preallocated array: returning a new one cost its
        allocation and a Python object every step).
    """
    # the structref's arrays as locals: a field read inside a loop is not hoisted (stores through the
    # other arrays may alias it), which cost about 5 ns per coordinate, 18 us a step for the reference net
    q, qt, qtt, qt_eval, reference = m.q, m.qt, m.qtt, m.qt_eval, m.reference_soa
    n3 = q.shape[0]
    nb = q_bodies.shape[0] // 6
    step = m.step
    half = 0.5 * step
    # the buffers read once (each read of the group counts its 40 arrays here, where counting is on)
    buffers = m.buffers
    work_soa, force_buffer = buffers.work_soa, buffers.force
    x_flat = work_soa[0].reshape(n3)
    # Verlet's half kick and drift, and the positions the forces take: q is the step's end position from here
    # on (nothing in the force evaluation reads the start's), so it is advanced in place, with no copy back.
    # One loop per array written: fused, these loops took longer (offline, 3675 coordinates: 8.6-9.5 us
    # against 6.7-7.6 us for the five passes a step, and 8.2-8.4 us with the copy)
    for k in range(n3):
        qt_eval[k] = qt[k] + half * qtt[k]
    for k in range(n3):
        q[k] = q[k] + step * qt_eval[k]
    for k in range(n3):
        x_flat[k] = reference[k] + q[k]
    # the bodies' evaluation state straight into the output and the tail of qt_eval (work space)
    v_half_bodies = qt_eval[n3:]
    verlet_evaluation_state_into(q_bodies, qt_bodies, qtt_bodies, step, 0, nb, q_next_bodies, v_half_bodies)
    _forces(m, buffers, q_next_bodies, v_half_bodies, m.n_substeps if time > 0.0 else 1)
    tether = m.tether
    if tether.node[0] >= 0:   # the main tether to the chaser (multibody.net_tether), at the same evaluation state
        add_tether_force(work_soa[0], qt_eval[:n3].reshape(3, n3 // 3), tether, work_soa[2], step)
    force = work_soa[2].reshape(n3)
    # flat loops over the coordinates with few arrays each: the compiler vectorizes them (with more
    # arrays in one loop its run-time overlap checks give up and the loop stays scalar)
    inverse_mass = m.inverse_mass
    for k in range(n3):
        qtt[k] = force[k] * inverse_mass[k]
    for k in range(n3):
        qt[k] = qt_eval[k] + half * qtt[k]
    force_bodies[:] = _body_forces(force_buffer, q_bodies.shape[0])


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
    state_index : (6 nb,) int or None
        Where the bodies' coordinates sit in Exudyn's system vectors (None: the whole vector).
    rotations : multibody.rotation_update.ExactRotations or None
        Keeps each step's exact end attitudes; they are written over Exudyn's at the start of the next
        pre-step, before :attr:`after_step` reads the state (and by :meth:`finish_steps` after the last step).
    tether : NetTether or None
        The main tether to the chaser (:mod:`multibody.net_tether`); None: none.
    """

    def __init__(self, mbs, coupled_object, kernel: KernelData, net_velocity, state_index, rotations=None,
                 tether: NetTether | None = None):
        self.mbs = mbs
        self.rotations = rotations
        self.coupled_object = coupled_object
        self.kernel = kernel
        self.state_index = state_index
        self.model, self.q, self.qt = net_step_model(kernel, net_velocity, tether)
        self._q_next_bodies = np.zeros(6 * kernel.n_bodies)  # the step's end coordinates of the bodies (m, rad)
        self._force_bodies = np.zeros(6 * kernel.n_bodies)   # the bodies' generalized forces of the step
        self._views = None
        #: Exudyn's (q, qt, qtt) views while :attr:`after_step` runs from the pre-step function, else None
        self.step_views = None
        self._last_time = -np.inf
        self._view_window = 1.5 * kernel.step   # a time further on than this starts a new solve (_state_views)
        #: optional ``after_step(mbs, t) -> bool``, the work of a post-step function for the step that ended at
        #: ``t`` (s), run at the start of the next step's pre-step instead (one Python call a step from Exudyn
        #: instead of two); False stops the solver. The last step's is left to :meth:`finish_steps`.
        self.after_step = None
        self._previous_end = 0.0    # Exudyn calls the post-step function once at t = 0 too
        # The solver's initial acceleration uses the force at the initial state.
        data = mbs.systemData
        q, qt = self._bodies(data.GetODE2Coordinates()), self._bodies(data.GetODE2Coordinates_t())
        mbs.SetObjectParameter(coupled_object, "forceVector", kernel_net_start(self.model, q, qt))

    def _bodies(self, vector):
        return vector if self.state_index is None else np.asarray(vector)[self.state_index]

    def _state_views(self, mbs, t):
        """Views of Exudyn's current coordinates, velocities and accelerations (no copies: three copying
        calls were about 2 us of every step). Exudyn keeps these vectors in place through a solve (checked
        against copies at every step of a run while this was built); they are taken again at the first step
        of a solve, recognised by a time that does not follow the previous step's."""
        if self._views is None or not (self._last_time < t <= self._last_time + self._view_window):
            data = mbs.systemData
            self._views = (data.GetODE2Coordinates(copy=False), data.GetODE2Coordinates_t(copy=False),
                           data.GetODE2Coordinates_tt(copy=False))
        self._last_time = t
        return self._views

    def __call__(self, mbs, t):
        # the views of _state_views, its test written out (a method call is a few tenths of a us of every step)
        if self._views is None or not (self._last_time < t <= self._last_time + self._view_window):
            self._state_views(mbs, t)
        self._last_time = t
        q, qt, qtt = self._views
        rotations = self.rotations
        if rotations is not None:
            # the previous step's exact attitudes, before anything reads the state (multibody.rotation_update);
            # through the view already at hand (fetching one was about 1 us of every step)
            rotations.restore_into(q)
        if self.after_step is not None:
            # the views at hand for the post-step work (the recorder's sample: fetching them again was about 2 us
            # of every step in the run, 20 us a sample); valid only inside this call
            self.step_views = self._views
            keep = self.after_step(mbs, self._previous_end)
            self.step_views = None
            self._previous_end = t
            if not keep:
                return False
        if self.state_index is not None:
            q, qt, qtt = self._bodies(q), self._bodies(qt), self._bodies(qtt)
        # t is the time of the evaluation state (see multibody.impact.VerletForces)
        kernel_net_step(self.model, q, qt, qtt, t, self._q_next_bodies, self._force_bodies)
        if rotations is not None:
            rotations.keep(self._q_next_bodies)
        mbs.SetObjectParameter(self.coupled_object, "forceVector", self._force_bodies)
        return True

    def set_after_step(self, after_step, start_time: float = 0.0):
        """Run ``after_step(mbs, t) -> bool`` for every step of the next solve (:attr:`after_step`), after
        the step's attitudes are restored.

        Parameters
        ----------
        after_step : callable or None
        start_time : float
            The solve's start time (s): Exudyn calls a post-step function once there too.
        """
        self.after_step = after_step
        self._previous_end = start_time

    def finish_steps(self, mbs) -> bool:
        """Restore the last step's attitudes and run :attr:`after_step` for it (after the solve); returns its
        answer (True without one).

        Parameters
        ----------
        mbs : exudyn.MainSystem
        """
        if self.rotations is not None:
            self.rotations.restore(mbs)
        if self.after_step is None:
            return True
        return bool(self.after_step(mbs, self._previous_end))

    def positions(self) -> np.ndarray:
        """(n, 3) node positions (m), LVLH, at the end of the last step."""
        return self.kernel.net.reference_lvlh + self.q.reshape(3, -1).T

    def velocities(self) -> np.ndarray:
        """(n, 3) node velocities (m/s), LVLH, at the end of the last step (a copy: the state is
        coordinate-major)."""
        return np.ascontiguousarray(self.qt.reshape(3, -1).T)
