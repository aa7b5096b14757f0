"""What a coupled impact run records, sampled at the case's output rates.

Time series (``Recorder.series``, all SI, frames in the names):

======================================  =========================================================
key                                     meaning
======================================  =========================================================
time                                    (k,) s
contact_force_lvlh / _body              (k, nb, 3) net contact force on each body (N), averaged
                                        over the output interval (impulse / interval)
contact_moment_lvlh / _body             (k, nb, 3) contact moment about the body CoM (N m)
body_com_lvlh, body_velocity_lvlh       (k, nb, 3) m, m/s
body_omega_body                         (k, nb, 3) rad/s, body frame
body_to_lvlh                            (k, nb, 3, 3) attitude
debris_com_lvlh, debris_velocity_lvlh   (k, 3) CoM of all debris bodies together
joint_rotation_joint                    (k, nj, 3) relative rotation vector (rad), joint frame;
                                        component 1 is the hinge angle about h2
joint_rate_joint                        (k, nj, 3) relative angular velocity (rad/s), joint frame
joint_force_joint, joint_moment_joint   (k, nj, 3) connector reaction (N, N m), joint frame:
                                        the load the parent exerts on the child at the joint
joint_force_filtered_joint,             (k, nj, 3) the same through each joint's load filter
joint_moment_filtered_joint             (a 2nd-order Butterworth run every step,
                                        :mod:`multibody.load_filter`; only when a joint has
                                        ``load_filter_hz``; a joint without one passes unfiltered)
energy_*                                (k,) J: net_kinetic, net_elastic (threads), net_bending,
                                        contact_elastic, debris_translational, debris_rotational,
                                        joint_elastic, orbital_potential (CW), dissipated_threads,
                                        dissipated_contact, dissipated_joints (the joints'
                                        dampers, booked every step), released_joints (penalty
                                        energy held by joints when a failure released them),
                                        total (mechanical + dissipated + released)
momentum_linear_lvlh                    (k, 3) total of net and debris (kg m/s)
momentum_angular_lvlh                   (k, 3) about the LVLH origin (kg m^2/s)
energy_tether_elastic,                  (k,) J, with the main tether (multibody.net_tether): its spring's
energy_dissipated_tether,               energy, its damper's dissipation so far, minus its reel's work
energy_tether_winch_work                (in the total)
tether_tension, tether_length           (k,) N, m (the length from the anchor to the tethered node)
tether_force_on_chaser_lvlh             (k, 3) N: the pull the chaser's thrusters hold
======================================  =========================================================

Net snapshots (``Recorder.net``): ``time`` (s), ``positions_lvlh`` (k, n, 3) float64,
``velocities_lvlh`` (k, n, 3) float32 and ``contact_force_lvlh`` (k, n, 3) float32, the contact
force of the bodies on each node (N), averaged over the interval since the previous snapshot.
Positions stay double: thread tensions are computed
from them afterwards (VTK export), and a float32 position 40 m from the chaser is only good
to ~5 um, a thread stretch worth ~0.3 N of tension.
"""
from __future__ import annotations

import numpy as np

from multibody.health import HealthWatch
from multibody.recorded_loads import applied_work
from multibody.recorder_kernel import (
    EXTRA_MEAN_MOTION,
    EXTRA_RELEASED_ENERGY,
    N_EXTRAS,
    SampledBodies,
    SampledJoints,
    body_sample_buffers,
    book_joint_dampers,
    damper_work_buffers,
    filter_joint_loads,
    new_recorder_model,
    sample_row,
)
from multibody.load_filter import OUTPUT, filter_bank
from multibody.net_tether import DISSIPATED, ELASTIC, FORCE_ON_CHASER, LENGTH, TENSION

#: Longest simulated time between two finite-state checks when the output rate is lower (s):
#: a NaN spreads through the coupled state within a few steps and stays, so 1 ms loses nothing.
HEALTH_INTERVAL_S = 1e-3

#: The energy terms of every run, in the order the total adds them (then ``chaser_kinetic`` with a chaser,
#: ``applied_loads_work`` with recorded loads, and ``total``).
ENERGY_TERMS = ("net_kinetic", "net_elastic", "net_bending", "contact_elastic", "debris_translational",
                "debris_rotational", "joint_elastic", "released_joints", "orbital_potential", "dissipated_threads",
                "dissipated_contact", "dissipated_joints")


#: The series of the joints' filtered loads (:mod:`multibody.load_filter`): force (N), moment (N m), joint frame.
FILTERED_LOADS = ("joint_force_filtered_joint", "joint_moment_filtered_joint")

#: The main tether's energy terms (:mod:`multibody.net_tether`), before the total: elastic, dissipated by its damper,
#: minus its reel's work (J).
TETHER_ENERGIES = ("tether_elastic", "dissipated_tether", "tether_winch_work")


def series_layout(n_bodies: int, n_joints: int, chaser: bool, applied_loads: bool,
                  filtered_loads: bool = False, winch: bool = False, tether: bool = False) -> list:
    """The time series' keys and the shape of one sample of each, in the order of :attr:`Recorder.series`.

    Parameters
    ----------
    n_bodies, n_joints : int
    chaser : bool
        The run has a chaser (``energy_chaser_kinetic``).
    applied_loads : bool
        The run has recorded loads (``energy_applied_loads_work``).
    filtered_loads : bool
        The joints' loads are filtered every step (``joint_force_filtered_joint``, ``joint_moment_filtered_joint``,
        after the existing columns, so a run without them records the same row).
    winch : bool
        The net has a closing winch (``energy_winch_work``: minus the work it did on the net, J, before the total).
    tether : bool
        The net has the main tether (:mod:`multibody.net_tether`): ``energy_tether_elastic``,
        ``energy_dissipated_tether``, ``energy_tether_winch_work`` (minus its reel's work, J) before the total, and
        ``tether_tension`` (N), ``tether_length`` (m), ``tether_force_on_chaser_lvlh`` ((3,) N) last.

    Returns
    -------
    list of (str, tuple)
    """
    nb, nj = n_bodies, n_joints
    energies = (list(ENERGY_TERMS) + ["chaser_kinetic"] * chaser + ["applied_loads_work"] * applied_loads
                + ["winch_work"] * winch + list(TETHER_ENERGIES) * tether + ["total"])
    return ([("time", ())]
            + [(key, (nb, 3)) for key in ("contact_force_lvlh", "contact_moment_lvlh", "contact_force_body",
                                          "contact_moment_body", "body_com_lvlh", "body_velocity_lvlh",
                                          "body_omega_body")]
            + [("body_to_lvlh", (nb, 3, 3)), ("debris_com_lvlh", (3,)), ("debris_velocity_lvlh", (3,))]
            + [(key, (nj, 3)) for key in ("joint_rotation_joint", "joint_rate_joint", "joint_force_joint",
                                          "joint_moment_joint")]
            + [("energy_" + key, ()) for key in energies]
            + [("momentum_linear_lvlh", (3,)), ("momentum_angular_lvlh", (3,))]
            + [(key, (nj, 3)) for key in FILTERED_LOADS] * filtered_loads
            + [("tether_tension", ()), ("tether_length", ()), ("tether_force_on_chaser_lvlh", (3,))] * tether)


class Recorder:
    """Samples the running system from Exudyn's post-step hook (when the kernel integrates the net, from its
    pre-step hook for the step before: :meth:`multibody.kernel_net.KernelNet.set_after_step`)."""

    def __init__(self, assembly, system, progress=None, monitor=None, health=None, capture=None):
        self.assembly = assembly
        self.system = system
        self.progress = progress
        #: optional ``check(t, force_joint, moment_joint, joint_energies)`` called after each
        #: sample (structures.release.ReleaseMonitor switches failed joints off there)
        self.monitor = monitor
        #: optional settle test of the capture (structures.capture_window.CaptureMonitor): ``sample(t, force_joint,
        #: moment_joint)`` after each sample, ``snapshot(t, positions_lvlh, velocities_lvlh, com_lvlh, velocity_lvlh,
        #: body_to_lvlh, omega_body) -> bool`` at each net snapshot; True stops the run (:attr:`stopped_early`)
        self.capture = capture
        #: :class:`~multibody.health.HealthWatch`: finite state at every sample and at least every
        #: HEALTH_INTERVAL_S, energy balance at every sample; a failed check stops the solver
        self.health = health or HealthWatch(cause="")
        self.joint_active = np.ones(len(assembly.joints), bool)
        self._released_energy = 0.0
        self._applied_work = 0.0        # J, by recorded loads (sequential method), since t = 0
        self._previous_body_state = None
        solver = assembly.solver
        self.step = solver.step
        self.output_interval = 1.0 / solver.output_rate
        self.net_interval = 1.0 / solver.net_output_rate
        self._next_output = self.output_interval
        self._end_time = solver.n_steps * solver.step
        self._health_every = max(1, int(HEALTH_INTERVAL_S / solver.step))
        self._previous_call = np.inf  # time of the last post-step call (s): a solve's first call books no step
        self._steps_unchecked = 0   # steps since the state was last checked (by a sample or on its own)
        self._next_net = self.net_interval
        self._last_output_time = 0.0
        mbs = system.mbs
        self._body_index = [mbs.GetNodeODE2Index(nd) for nd in system.body_nodes]
        self._joint_stiffness = [np.diag(mbs.GetObjectParameter(obj, "stiffness")) for obj in system.joint_objects]
        self._joint_damping = [np.diag(mbs.GetObjectParameter(obj, "damping")) for obj in system.joint_objects]
        self._preallocate(assembly, system)
        self.series: dict[str, np.ndarray] = {}
        self.net: dict[str, np.ndarray] = {}
        self.wall_time = None
        self.stopped_early = False

    def _preallocate(self, assembly, system):
        """Series and snapshot arrays for every sample the run can take, and the recorder kernel's inputs.

        A sample is written into one flat row (:attr:`_row`; the body kernel's outputs are views of it, so it
        writes there directly) and stored with one copy into a (capacity, row) table; :meth:`finish` cuts the
        table into the series (storing some 35 arrays one by one was about 20 us of every sample)."""
        self._capacity = int(np.ceil(self._end_time / self.output_interval)) + 3
        nb, nj = len(assembly.bodies), len(assembly.joints)
        cutoffs_hz = [j.load_filter_hz for j in assembly.joints]
        #: the joints' load filters ((nj, 6, S, 8), multibody.load_filter), None when no joint has a cut-off
        self._load_filter = (filter_bank(cutoffs_hz, assembly.solver.step, [j.load_filter_order for j in assembly.joints])
                             if any(cutoffs_hz) else None)
        self._filter_started = False
        self._filter_scratch = np.zeros((6, 3))
        self._unfiltered = np.array([not c for c in cutoffs_hz], bool)
        #: the net's closing winch (multibody.closing_winch), None for an open net
        self._winch = system.closing
        #: the main tether's spool (multibody.tether_spool), None without a tether
        self._spool = getattr(system, "tether", None)
        self._launch_reference = self.health.reference_energy   # the energy check's reference before any winch work
        self._layout = series_layout(nb, nj, assembly.chaser is not None, assembly.body_loads is not None,
                                     self._load_filter is not None, self._winch is not None, self._spool is not None)
        self._columns = {}
        width = 0
        for key, shape in self._layout:
            size = int(np.prod(shape, dtype=np.int64))
            self._columns[key] = (width, width + size, shape)
            width += size
        self._row = np.zeros(width)
        self._rows = np.zeros((self._capacity, width))
        self._n_rows = 0
        self._row_view = {key: self._row[first:last].reshape(shape) for key, (first, last, shape) in self._columns.items()}
        energy_keys = [key for key, _ in self._layout if key.startswith("energy_")]
        self._energy_slice = slice(self._columns[energy_keys[0]][0], self._columns[energy_keys[-1]][1])
        self._time_column = self._columns["time"][0]
        n_net = int(np.ceil(self._end_time / self.net_interval)) + 3
        n = assembly.net.n_nodes
        self._net_time = np.zeros(n_net)
        self._net_positions = np.zeros((n_net, n, 3))
        self._net_velocities = np.zeros((n_net, n, 3), np.float32)
        self._net_contact_force = np.zeros((n_net, n, 3), np.float32)
        self._last_net_time = 0.0
        self._n_net = 0
        bodies, joints = assembly.bodies, assembly.joints
        self._bodies = SampledBodies(
            index=np.array(self._body_index, np.int64),
            reference_com_lvlh=np.array([b.com_lvlh for b in bodies], float).reshape(nb, 3),
            mass=np.array([b.mass for b in bodies], float),
            inertia_body=np.array([b.inertia_body for b in bodies], float).reshape(nb, 3, 3),
            debris_mask=np.isin(np.arange(nb), np.array(assembly.debris_indices, np.int64)).astype(np.int64),
            chaser=-1 if assembly.chaser is None else int(assembly.chaser),
            node_to_body=system.kernel.bodies.node_to_body)
        self._net_masses = np.asarray(assembly.net.masses, float)
        self._joints = SampledJoints(
            parent=np.array([j.parent for j in joints], np.int64), child=np.array([j.child for j in joints], np.int64),
            joint_to_parent=np.array(system.joint_to_parent, float).reshape(nj, 3, 3),
            joint_to_child=np.array(system.joint_to_child, float).reshape(nj, 3, 3),
            point_parent=np.array(system.joint_point_parent_body, float).reshape(nj, 3),
            point_child=np.array(system.joint_point_child_body, float).reshape(nj, 3),
            stiffness=np.array(self._joint_stiffness, float).reshape(nj, 6),
            damping=np.array(self._joint_damping, float).reshape(nj, 6))
        view = self._row_view
        self._body_out = body_sample_buffers(nb, nj)._replace(
            com_lvlh=view["body_com_lvlh"], velocity_lvlh=view["body_velocity_lvlh"],
            body_to_lvlh=view["body_to_lvlh"], omega_body=view["body_omega_body"],
            force_lvlh=view["contact_force_lvlh"], moment_lvlh=view["contact_moment_lvlh"],
            force_body=view["contact_force_body"], moment_body=view["contact_moment_body"],
            joint_rotation=view["joint_rotation_joint"], joint_rate=view["joint_rate_joint"],
            joint_force=view["joint_force_joint"], joint_moment=view["joint_moment_joint"])
        self._joint_active_float = np.ones(nj)
        self._net_totals = np.zeros(8)
        data = system.mbs.systemData
        _, _, *net_layout = system.net_state_layout(data.GetODE2Coordinates(copy=False),
                                                    data.GetODE2Coordinates_t(copy=False))
        # the energy total's column follows the energy terms (the recorded loads' work, if any, is the last term)
        columns = [self._columns[key][0] for key in ("time", "debris_com_lvlh", "debris_velocity_lvlh")]
        columns += [self._energy_slice.start, self._energy_slice.stop - 1]
        columns += [self._columns[key][0] for key in ("momentum_linear_lvlh", "momentum_angular_lvlh")]
        self._extras = np.zeros(N_EXTRAS)  # recorder_kernel.EXTRA_*
        self._extras[EXTRA_MEAN_MOTION] = float(assembly.mean_motion)
        # the joints' dampers booked every step (book_joint_dampers), when a joint has one
        self._book_dampers = bool(nj) and bool(np.any(self._joints.damping != 0.0))
        self._half_kick = 0.5 * assembly.solver.step if assembly.solver.integrator == "VelocityVerlet" else 0.0
        n_coordinates = len(data.GetODE2Coordinates_t(copy=False))
        self._model = new_recorder_model(self._bodies, self._joints, self._joint_active_float,
                                         system.kernel.buffers.body_impulse_lvlh, self._body_out, self._net_masses,
                                         np.ascontiguousarray(system.kernel.net.reference_lvlh, float),
                                         np.array(net_layout, np.int64), self._net_totals, system.kernel.buffers.scalars,
                                         self._row, np.array(columns, np.int64), self._extras,
                                         damper_work_buffers(n_coordinates, nb))
        self._net_in_kernel = system.kernel_net is not None

    # -- Exudyn hook -----------------------------------------------------------------
    def post_step(self, mbs, t):
        """Exudyn post-step function: sample at the output times, check the state in between.

        Parameters
        ----------
        mbs : exudyn.MainSystem
            The running system.
        t : float
            Time at the end of the step (s).

        Returns
        -------
        bool
            False stops the solver (a failed health check).
        """
        half = 0.5 * self.step
        self._steps_unchecked += 1
        if t > self._previous_call + half:   # not at a solve's start, where Exudyn calls once before any step
            if self._book_dampers:
                self._book_joint_dampers()
            if self._load_filter is not None:
                self._filter_joint_loads()
        self._previous_call = t
        if t >= self._next_output - half or t >= self._end_time - half:
            # the last step is always sampled, so a run's series ends at its end time whatever the rate
            self.sample(t)
            self._steps_unchecked = 0   # a sample checks the state
            while self._next_output - half <= t:
                self._next_output += self.output_interval
        elif self._steps_unchecked >= self._health_every:
            self._steps_unchecked = 0
            self.health.state(t, *self.system.state_arrays())
        return self.health.ok and not self.stopped_early

    def _book_joint_dampers(self):
        """The joints' dampers' work over the step that just ended, into the balance's ``dissipated_joints``
        (:func:`multibody.recorder_kernel.book_joint_dampers`); every step, not every sample: the penalty modes
        ring at 15-800 Hz."""
        views = self.system.kernel_net.step_views if self._net_in_kernel else None
        if views is None:
            data = self.system.mbs.systemData
            views = (data.GetODE2Coordinates(copy=False), data.GetODE2Coordinates_t(copy=False),
                     data.GetODE2Coordinates_tt(copy=False))
        book_joint_dampers(self._model, views[0], views[1], views[2], self._half_kick, self.step)

    def _filter_joint_loads(self):
        """The joints' load filters advanced by the step that just ended (:func:`multibody.recorder_kernel.filter_joint_loads`):
        every step, before the output's decimation, so the penalty modes above the output's Nyquist frequency do
        not alias into the filtered loads."""
        views = self.system.kernel_net.step_views if self._net_in_kernel else None
        if views is None:
            data = self.system.mbs.systemData
            views = (data.GetODE2Coordinates(copy=False), data.GetODE2Coordinates_t(copy=False),
                     data.GetODE2Coordinates_tt(copy=False))
        filter_joint_loads(self._model, self._load_filter, self._filter_scratch, views[0], views[1], views[2],
                           self._half_kick, not self._filter_started)
        self._filter_started = True

    # -- sampling --------------------------------------------------------------------
    def sample(self, t):
        """Record one row of the time series at ``t`` (and a net snapshot when one is due).

        Nothing is recorded from a non-finite state or past a failed energy check (the run stops).

        Parameters
        ----------
        t : float
            Current simulated time (s).
        """
        if not self.health.ok:
            return  # the run has stopped
        # views (nothing here writes them; the row keeps what it needs): the kernel's, when it calls from its pre-step
        views = self.system.kernel_net.step_views if self._net_in_kernel else None
        if views is None:
            data = self.system.mbs.systemData
            q, qt = data.GetODE2Coordinates(copy=False), data.GetODE2Coordinates_t(copy=False)
        else:
            q, qt = views[0], views[1]
        net_q, net_qt = (self.system.kernel_net.q, self.system.kernel_net.qt) if self._net_in_kernel else (q, qt)
        # the whole row in one compiled call; nothing is recorded from a lost state
        finite, total_energy = sample_row(self._model, q, qt, net_q, net_qt, t, t - self._last_output_time)
        if not finite:
            self.health.state(t, *self.system.state_arrays())  # the full check, with its message
            return  # the run stops at this step
        self._last_output_time = t
        # the joints' loads: written by sample_row (recorder_kernel.connector_load_into, Exudyn's connector law)
        forces_joint, moments_joint = self._body_out.joint_force, self._body_out.joint_moment
        if self._load_filter is not None:
            # the filtered loads beside the raw ones; the release monitor judges them, as the verdict does
            forces_joint, moments_joint = self._row_view[FILTERED_LOADS[0]], self._row_view[FILTERED_LOADS[1]]
            forces_joint[:] = self._load_filter[:, :3, -1, OUTPUT]
            moments_joint[:] = self._load_filter[:, 3:, -1, OUTPUT]
            raw = self._unfiltered       # a joint without a cut-off records its raw load there too
            forces_joint[raw] = self._body_out.joint_force[raw]
            moments_joint[raw] = self._body_out.joint_moment[raw]
        if self.assembly.body_loads is not None:
            w = self._body_out
            work_term = -self._work_of_applied_loads(t, w.com_lvlh, w.velocity_lvlh, w.omega_body)
            total_column = self._energy_slice.stop - 1
            self._row[total_column - 1] = work_term
            total_energy = total_energy + work_term  # the sum's last term, in the order ENERGY_TERMS adds them
            self._row[total_column] = total_energy
        if self._winch is not None:
            total_energy = self._book_winch(total_energy)
        if self._spool is not None:
            total_energy = self._book_tether(total_energy)
        if not self.health.energy(t, total_energy):
            return
        self._store()
        if self.monitor is not None:
            self._check_monitor(t, forces_joint.copy(), moments_joint.copy())
        if self.capture is not None:
            self.capture.sample(t, forces_joint, moments_joint)
        if t == 0.0 or t >= self._next_net - 0.5 * self.step:
            x_lvlh, v_lvlh = self.system.net_state(q, qt)
            k = self._n_net
            self._net_time[k] = t
            self._net_positions[k] = x_lvlh
            self._net_velocities[k] = v_lvlh
            self._net_contact_force[k] = self._node_contact_force(t)
            self._n_net += 1
            if t > 0.0:
                self._next_net += self.net_interval
            if self.capture is not None:
                self._check_capture(t, k)
        if self.progress is not None:
            self.progress(t)

    def _book_winch(self, total_energy: float) -> float:
        """The closing winch's work into the row (``energy_winch_work``: minus the work it did on the net, so that
        the total stays closed while the loop pulls) and the total with it (J)."""
        self._row[self._columns["energy_winch_work"][0]] = -self._winch.work
        total_energy = total_energy - self._winch.work
        self._row[self._energy_slice.stop - 1] = total_energy
        self._raise_reference()
        return total_energy

    def _book_tether(self, total_energy: float) -> float:
        """The main tether into the row: its elastic energy, its damper's dissipation and minus its reel's work
        (J), the total with them; its tension (N), length (m) and force on the chaser (N, LVLH)."""
        state, column = self._spool.state, self._columns
        terms = (state[ELASTIC], state[DISSIPATED], -self._spool.work)
        for key, value in zip(TETHER_ENERGIES, terms):
            self._row[column["energy_" + key][0]] = value
            total_energy = total_energy + value
        self._row[self._energy_slice.stop - 1] = total_energy
        self._row[column["tether_tension"][0]] = state[TENSION]
        self._row[column["tether_length"][0]] = state[LENGTH]
        first = column["tether_force_on_chaser_lvlh"][0]
        self._row[first:first + 3] = state[FORCE_ON_CHASER:FORCE_ON_CHASER + 3]
        self._raise_reference()
        return total_energy

    def _raise_reference(self) -> None:
        """The energy balance's scale is the energy brought in: the launch's and what the closing winch and the
        tether's reel have put in since."""
        if self.health.reference_energy is not None:
            work = sum(w.work for w in (self._winch, self._spool) if w is not None)
            self.health.reference_energy = max(self.health.reference_energy, self._launch_reference + work)

    def _node_contact_force(self, t):
        """Contact force on each net node (N, LVLH), averaged since the previous net snapshot."""
        impulse_lvlh = self.system.kernel.buffers.node_impulse_lvlh
        interval = t - self._last_net_time
        force_lvlh = impulse_lvlh / interval if interval > 0.0 else np.zeros_like(impulse_lvlh)
        impulse_lvlh[:] = 0.0
        self._last_net_time = t
        return force_lvlh

    def _check_capture(self, t, k):
        """The capture's settle test at net snapshot ``k`` (the velocities as stored, float32, so that the verdict's
        recomputation from the snapshots reads the same values); a capture that is over stops the run."""
        w = self._body_out
        if self.capture.snapshot(t, self._net_positions[k], self._net_velocities[k], w.com_lvlh, w.velocity_lvlh,
                                 w.body_to_lvlh, w.omega_body):
            self.stopped_early = True

    def _check_monitor(self, t, force_joint, moment_joint):
        before = len(self.monitor.events)
        self.monitor.check(t, force_joint, moment_joint, self._body_out.joint_energy)
        for event in self.monitor.events[before:]:
            # The connector is off from the next step on: its loads read zero and the elastic
            # energy it held leaves the balance as "released" energy, so the total stays closed.
            self.joint_active[event.joint] = False
            self._joint_active_float[event.joint] = 0.0
            self._released_energy += event.stored_energy
            self._extras[EXTRA_RELEASED_ENERGY] = self._released_energy

    def _work_of_applied_loads(self, t, com_lvlh, velocity_lvlh, omega_body) -> float:
        """Work (J) done by the recorded loads since t = 0: the energy they bring in, which the
        balance subtracts so that it stays closed."""
        if self._previous_body_state is not None:
            t0, com0_lvlh, velocity0_lvlh, omega0_body = self._previous_body_state
            self._applied_work += applied_work(self.assembly.body_loads, self.step, t0, t, com0_lvlh, com_lvlh,
                                               velocity0_lvlh, omega0_body, omega_body)
        self._previous_body_state = (t, com_lvlh.copy(), velocity_lvlh.copy(), omega_body.copy())
        return self._applied_work

    def _store(self):
        """Copy the sample's row (:attr:`_row`) into the preallocated table."""
        self._rows[self._n_rows] = self._row
        self._n_rows += 1

    def finish(self, wall_time):
        """Trim the preallocated arrays to the samples taken into :attr:`series` and :attr:`net`.

        Parameters
        ----------
        wall_time : float
            Wall-clock duration of the run (s).
        """
        self.wall_time = wall_time
        k = self._n_rows
        self.series = {key: self._rows[:k, first:last].reshape((k,) + shape).copy() for key, (first, last, shape)
                       in self._columns.items()} if k else {}
        self.net = {"time": self._net_time[:self._n_net].copy(), "positions_lvlh": self._net_positions[:self._n_net].copy(),
                    "velocities_lvlh": self._net_velocities[:self._n_net].copy(),
                    "contact_force_lvlh": self._net_contact_force[:self._n_net].copy()}
