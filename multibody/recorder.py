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
energy_*                                (k,) J: net_kinetic, net_elastic (threads), net_bending,
                                        contact_elastic, debris_translational, debris_rotational,
                                        joint_elastic, orbital_potential (CW), dissipated_threads,
                                        dissipated_contact, released_joints (penalty energy held
                                        by joints when a failure released them), total
                                        (mechanical + dissipated + released)
momentum_linear_lvlh                    (k, 3) total of net and debris (kg m/s)
momentum_angular_lvlh                   (k, 3) about the LVLH origin (kg m^2/s)
======================================  =========================================================

Net snapshots (``Recorder.net``): ``time`` (s), ``positions_lvlh`` (k, n, 3) float64 and
``velocities_lvlh`` (k, n, 3) float32. Positions stay double: thread tensions are computed
from them afterwards (VTK export), and a float32 position 40 m from the chaser is only good
to ~5 um, a thread stretch worth ~0.3 N of tension.
"""
from __future__ import annotations

import numpy as np
import exudyn as exu

from multibody.health import HealthWatch
from multibody.hinge import relative_rotation_vector_joint_frame
from multibody.kernel import (BENDING_ELASTIC, rotation_matrix_from_rotation_vector, CONTACT_DISSIPATED, CONTACT_ELASTIC, THREAD_DISSIPATED,
                              THREAD_ELASTIC)
from multibody.orbit import clohessy_wiltshire_potential


#: Longest simulated time between two finite-state checks when the output rate is lower (s):
#: a NaN spreads through the coupled state within a few steps and stays, so 1 ms loses nothing.
HEALTH_INTERVAL_S = 1e-3


def _sum_of_cross_products(a, b):
    """sum_i a_i x b_i for (k, 3) arrays; written out because np.cross costs ~80 us a call."""
    return np.array([a[:, 1] @ b[:, 2] - a[:, 2] @ b[:, 1],
                     a[:, 2] @ b[:, 0] - a[:, 0] @ b[:, 2],
                     a[:, 0] @ b[:, 1] - a[:, 1] @ b[:, 0]])


class Recorder:
    """Samples the running system from Exudyn's post-step hook."""

    def __init__(self, assembly, system, progress=None, monitor=None, health=None):
        self.assembly = assembly
        self.system = system
        self.progress = progress
        #: optional ``check(t, force_joint, moment_joint, joint_energies)`` called after each
        #: sample (structures.release.ReleaseMonitor switches failed joints off there)
        self.monitor = monitor
        #: :class:`~multibody.health.HealthWatch`: finite state at every sample and at least every
        #: HEALTH_INTERVAL_S, energy balance at every sample; a failed check stops the solver
        self.health = health or HealthWatch(cause="")
        self.joint_active = np.ones(len(assembly.joints), bool)
        self._released_energy = 0.0
        solver = assembly.solver
        self.step = solver.step
        self.output_interval = 1.0 / solver.output_rate
        self.net_interval = 1.0 / solver.net_output_rate
        self._next_output = self.output_interval
        self._end_time = solver.n_steps * solver.step
        self._health_every = max(1, int(HEALTH_INTERVAL_S / solver.step))
        self._steps = 0
        self._next_net = self.net_interval
        self._last_output_time = 0.0
        mbs = system.mbs
        self._body_index = [mbs.GetNodeODE2Index(nd) for nd in system.body_nodes]
        self._joint_stiffness = [np.diag(mbs.GetObjectParameter(obj, "stiffness")) for obj in system.joint_objects]
        self._rows: dict[str, list] = {}
        self._net_rows: dict[str, list] = {"time": [], "positions_lvlh": [], "velocities_lvlh": []}
        self.series: dict[str, np.ndarray] = {}
        self.net: dict[str, np.ndarray] = {}
        self.wall_time = None
        self.stopped_early = False

    # -- Exudyn hook -----------------------------------------------------------------
    def post_step(self, mbs, t):
        half = 0.5 * self.step
        self._steps += 1
        if t >= self._next_output - half or t >= self._end_time - half:
            # the last step is always sampled, so a run's series ends at its end time whatever the rate
            self.sample(t)
            while self._next_output - half <= t:
                self._next_output += self.output_interval
        elif self._steps % self._health_every == 0:
            self.health.state(t, *self.system.state_arrays())
        return self.health.ok

    # -- sampling --------------------------------------------------------------------
    def sample(self, t):
        arrays = self.system.state_arrays()
        q, qt = arrays[:2]
        if not self.health.state(t, *arrays):
            return  # nothing recorded from a lost state; the run stops at this step
        row = {"time": t}
        x, v = self.system.net_state(q, qt)
        self._body_rows(row, q, qt, t)
        self._joint_rows(row)
        self._energy_rows(row, x, v)
        self._momentum_rows(row, x, v)
        if not self.health.energy(t, row["energy_total"]):
            return
        for key, value in row.items():
            self._rows.setdefault(key, []).append(np.asarray(value, float))
        if self.monitor is not None:
            self._check_monitor(t, row)
        if t == 0.0 or t >= self._next_net - 0.5 * self.step:
            self._net_rows["time"].append(t)
            self._net_rows["positions_lvlh"].append(np.array(x, dtype=np.float64))
            self._net_rows["velocities_lvlh"].append(v.astype(np.float32))
            if t > 0.0:
                self._next_net += self.net_interval
        if self.progress is not None:
            self.progress(t)

    def _check_monitor(self, t, row):
        before = len(self.monitor.events)
        self.monitor.check(t, row["joint_force_joint"], row["joint_moment_joint"], self._joint_energies)
        for event in self.monitor.events[before:]:
            # The connector is off from the next step on: its loads read zero and the elastic
            # energy it held leaves the balance as "released" energy, so the total stays closed.
            self.joint_active[event.joint] = False
            self._released_energy += event.stored_energy

    def body_states(self, q, qt):
        """Per body: CoM (m), velocity (m/s), body->LVLH matrix, omega (rad/s, body frame)."""
        com, vel, rot, omega = [], [], [], []
        for body, i in zip(self.assembly.bodies, self._body_index):
            com.append(body.com_lvlh + q[i:i + 3])
            vel.append(np.array(qt[i:i + 3]))
            rot.append(rotation_matrix_from_rotation_vector(np.array(q[i + 3:i + 6])))
            omega.append(np.array(qt[i + 3:i + 6]))
        return np.array(com), np.array(vel), np.array(rot), np.array(omega)

    def _body_rows(self, row, q, qt, t):
        com, vel, rot, omega = self.body_states(q, qt)
        self._bodies_now = (com, vel, rot, omega)
        interval = t - self._last_output_time
        impulse = self.system.kernel.body_impulse
        if interval > 0.0:
            force = impulse[:, :3] / interval
            moment = impulse[:, 3:] / interval
        else:
            force = np.zeros_like(impulse[:, :3])
            moment = np.zeros_like(force)
        impulse[:] = 0.0
        self._last_output_time = t
        debris = self.assembly.debris_indices
        masses = np.array([self.assembly.bodies[k].mass for k in debris])
        row["contact_force_lvlh"] = force
        row["contact_moment_lvlh"] = moment
        row["contact_force_body"] = np.einsum("bji,bj->bi", rot, force)
        row["contact_moment_body"] = np.einsum("bji,bj->bi", rot, moment)
        row["body_com_lvlh"] = com
        row["body_velocity_lvlh"] = vel
        row["body_omega_body"] = omega
        row["body_to_lvlh"] = rot
        row["debris_com_lvlh"] = masses @ com[debris] / masses.sum() if len(masses) else np.zeros(3)
        row["debris_velocity_lvlh"] = masses @ vel[debris] / masses.sum() if len(masses) else np.zeros(3)

    def _joint_rows(self, row):
        mbs = self.system.mbs
        com, vel, rot, omega = self._bodies_now
        rotations, rates, forces, moments, energies = [], [], [], [], []
        for j, joint in enumerate(self.assembly.joints):
            obj = self.system.joint_objects[j]
            rv = relative_rotation_vector_joint_frame(rot[joint.parent], rot[joint.child],
                                                      self.system.joint_to_parent[j], self.system.joint_to_child[j])
            frame = rot[joint.parent] @ self.system.joint_to_parent[j]
            omega_rel = rot[joint.child] @ omega[joint.child] - rot[joint.parent] @ omega[joint.parent]
            rotations.append(rv)
            rates.append(frame.T @ omega_rel)
            # Exudyn's connector force is the spring force acting on marker 1 (child) with
            # reversed sign; the parent's load on the child is its negative.
            active = self.joint_active[j]
            forces.append(-np.asarray(mbs.GetObjectOutput(obj, exu.OutputVariableType.ForceLocal)) * active)
            moments.append(-np.asarray(mbs.GetObjectOutput(obj, exu.OutputVariableType.TorqueLocal)) * active)
            offset = (rot[joint.child] @ self.system.joint_point_child[j] + com[joint.child]
                      - rot[joint.parent] @ self.system.joint_point_parent[j] - com[joint.parent])
            offset_joint = frame.T @ offset
            k = self._joint_stiffness[j]
            energies.append(0.5 * (k[:3] @ offset_joint**2 + k[3:] @ rv**2) * active)
        nj = len(self.assembly.joints)
        row["joint_rotation_joint"] = np.reshape(rotations, (nj, 3))
        row["joint_rate_joint"] = np.reshape(rates, (nj, 3))
        row["joint_force_joint"] = np.reshape(forces, (nj, 3))
        row["joint_moment_joint"] = np.reshape(moments, (nj, 3))
        self._joint_energies = np.array(energies, float)

    def _energy_rows(self, row, x, v):
        scalars = self.system.kernel.scalars
        net = self.assembly.net
        com, vel, rot, omega = self._bodies_now
        bodies = self.assembly.bodies
        n_orbit = self.assembly.mean_motion
        debris = self.assembly.debris_indices
        chaser = self.assembly.chaser
        e = {
            "net_kinetic": 0.5 * np.sum(net.masses * np.sum(v * v, axis=1)),
            "net_elastic": scalars[THREAD_ELASTIC],
            "net_bending": scalars[BENDING_ELASTIC],
            "contact_elastic": scalars[CONTACT_ELASTIC],
            "debris_translational": sum(0.5 * bodies[k].mass * vel[k] @ vel[k] for k in debris),
            "debris_rotational": sum(0.5 * omega[k] @ bodies[k].inertia_body @ omega[k] for k in debris),
            "joint_elastic": float(self._joint_energies.sum()),
            "released_joints": self._released_energy,
            "orbital_potential": (np.sum(net.masses * clohessy_wiltshire_potential(x, n_orbit))
                                  + sum(b.mass * clohessy_wiltshire_potential(com[k], n_orbit)[0]
                                        for k, b in enumerate(bodies))) if n_orbit else 0.0,
            "dissipated_threads": scalars[THREAD_DISSIPATED],
            "dissipated_contact": scalars[CONTACT_DISSIPATED],
        }
        if chaser is not None:
            b = bodies[chaser]
            e["chaser_kinetic"] = 0.5 * b.mass * vel[chaser] @ vel[chaser] + 0.5 * omega[chaser] @ b.inertia_body @ omega[chaser]
        e["total"] = sum(e.values())
        for key, value in e.items():
            row["energy_" + key] = value

    def _momentum_rows(self, row, x, v):
        net = self.assembly.net
        com, vel, rot, omega = self._bodies_now
        p_net = net.masses[:, None] * v
        linear = p_net.sum(axis=0)
        angular = _sum_of_cross_products(x, p_net)
        for k, b in enumerate(self.assembly.bodies):
            linear = linear + b.mass * vel[k]
            angular = angular + b.mass * _sum_of_cross_products(com[k:k + 1], vel[k:k + 1]) + rot[k] @ (
                b.inertia_body @ omega[k])
        row["momentum_linear_lvlh"] = linear
        row["momentum_angular_lvlh"] = angular

    def finish(self, wall_time):
        self.wall_time = wall_time
        self.series = {k: np.array(v) for k, v in self._rows.items()}
        self.net = {k: np.array(v) for k, v in self._net_rows.items()}
