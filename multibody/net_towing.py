"""Full-net towing model in Exudyn: the chaser and the Zenit-2 debris as rigid bodies, the wrapped
net (lumped masses, tension-only threads, closing loop, contact with friction on the debris) and the
main tether from the net's central node to the chaser (Boonrath, Singh & Botta 2024, Sec. 2.1).

As in the lower-order model (:mod:`multibody.towing`), chaser and debris are Exudyn nodes
(``NodeRigidBodyRotVecLG``, explicit VelocityVerlet, Lie-group rotations) and one
``ObjectGenericODE2`` spanning both carries every force through its force user function; the light,
stiff net is the sub-system advanced inside that function, sub-cycled over each step
(:mod:`multibody.net_towing_kernel`: why and how, and the consistency argument). Thrust law and
attitude control are the lower-order model's (:mod:`multibody.control.thrust`, :mod:`multibody.control.attitude`).
Frame: Earth-centred inertial; angular velocities in the body frames.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import NodeRigidBodyRotVecLG, ObjectGenericODE2, ObjectRigidBody
from numba import njit, types
from numba.experimental import structref
from scipy.spatial.transform import Rotation

from multibody.closing import reel_fraction, reeled_rest_lengths
from multibody.health import HealthWatch
from multibody.impact import checked_post_step, explicit_settings, solve_checked
from multibody.control.lateral import L_ON, L_SIZE, lateral_thrust
from multibody.control.thrust import range_rate
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.net_towing_kernel import (ACC_CHASER_F, ACC_CHASER_T, ACC_CLOSING, ACC_CONTACT_F, ACC_CONTACTS,
                                         ACC_DEBRIS_F, ACC_DEBRIS_T, ACC_EXTERNAL, ACC_SIZE, ACC_TENSION, D_CLOSING,
                                         D_CONTACT_F, D_CONTACTS, D_ELONGATION, D_RATE, D_SIZE, D_TENSION, advance_net,
                                         DebrisBody, DebrisMotion, NetThreads, TetherEnd, chaser_actuation,
                                         chaser_control, net_forces)
from multibody.net_wrap import TowingNet
from multibody.towing import HEALTH_EVERY_STEPS, TowedBodies, tow_failure_cause
from multibody.net_towing_kernel import D_LATERAL, D_SLIDING, D_THRUST, D_TORQUE
from multibody.orbit import add_body_gravity
from multibody.health import SimulationFailed
from multibody.net import net_kinetic_energy_relative_to_body
from multibody.tow_switch import QuasiSteadyWatch, SwitchCriterion, net_internal_kinetic_energy

#: Layout of the run state ``clock``: net time (s), external impulse (3, N s) since the start.
CLOCK_TIME, CLOCK_IMPULSE, CLOCK_SIZE = 0, 1, 4


@dataclass
class FullNetModel(TowedBodies):
    """One full-net run: :class:`multibody.towing.TowedBodies` (chaser, debris, controls, times;
    ``positions``, ``velocities`` (2, 3): chaser and debris CoM) plus the net and the main tether.

    Attributes
    ----------
    net : TowingNet                    Topology, closing loop; its thread arrays are the state's (copied).
    node_positions, node_velocities : (n, 3) float  Nodes at ``start_time`` (m, absolute; m/s).
    masses : (2,) float                m_C, m_D (kg).
    main_tether : (3,) float           k_MT (N/m), c_MT (N s/m), l_MT0 (m); zero stiffness before ``closing_time``.
    geometry : (3,) float              Debris cylinder: radius (m), half length (m), axial centre z_body (m).
    contact_law : (6,) float           k_n, n, d_n, mu_s, mu_k, V_t0 (:mod:`multibody.net_towing_kernel`).
    substeps : int                     Net sub-steps per body step.
    net_output_interval, closing_time : float (s)
    closing_duration : float or None   (s) None: the closing loop stays at the topology's natural lengths
                                       (the wrapped start, already closed). Otherwise it starts open and is
                                       reeled in linearly to ``net.closing_rest_closed`` over
                                       [closing_time, closing_time + closing_duration] (capture start, Sec. 2.1).
    switch : SwitchCriterion or None   Stop the run at quasi-steady state (:mod:`multibody.tow_switch`);
                                       the result keeps the state there (``NetTowResult.switch``).
    state_at : float or None           Keep the full state at the first sample at or after this time (s)
                                       without stopping (``NetTowResult.state_at``): the start state of
                                       lower-order runs compared with this one (identification, Sec. 4.1).
    lateral : (L_SIZE,) float          Lateral station-keeping law of the chaser
                                       (:func:`multibody.control.lateral.lateral_params`); zeros: off.
    """

    net: TowingNet
    node_positions: np.ndarray
    node_velocities: np.ndarray
    masses: np.ndarray
    main_tether: np.ndarray
    geometry: np.ndarray
    contact_law: np.ndarray
    substeps: int
    net_output_interval: float
    closing_time: float = 15.0
    closing_duration: float | None = None
    switch: SwitchCriterion | None = None
    state_at: float | None = None
    lateral: np.ndarray = field(default_factory=lambda: np.zeros(L_SIZE))

    @property
    def net_every(self) -> int:
        return max(1, int(round(self.net_output_interval / self.step)))

    @property
    def total_mass(self) -> float:
        return float(self.masses.sum() + self.net.topology.masses.sum())


@njit(cache=True)
def _bodies(q, v, reference_c, reference_d):
    """(2, 12): per body CoM (absolute), rotation vector, CoM velocity, angular velocity (body)."""
    out = np.empty((2, 12))
    for b, ref in ((0, reference_c), (1, reference_d)):
        out[b, 0:3] = ref + q[6 * b:6 * b + 3]
        out[b, 3:6] = q[6 * b + 3:6 * b + 6]
        out[b, 6:12] = v[6 * b:6 * b + 6]
    return out


@structref.register
class NetTowKernelType(types.StructRef):
    """numba type of :class:`NetTowKernel`."""


class NetTowKernel(structref.StructRefProxy):
    """One full-net run as :func:`step_forces` takes it (made by :class:`NetTowState`; arrays shared with it).

    Fields
    ------
    x, xv : (n, 3) float        Net nodes: positions relative to ``reference`` (m) and velocities (m/s), inertial.
    lag : (n, 3) float          Contact velocity lags carried between sub-steps (m/s).
    clock : (CLOCK_SIZE,) float Net time (s) and the external impulse since the start (3, N s, inertial).
    net : NetThreads            Node masses and radii, threads (:class:`multibody.net_towing_kernel.NetThreads`).
    reference : (3,) float      Origin of the node positions, absolute (m).
    mu : float                  Gravitational parameter (m^3/s^2).
    central : int               Node the main tether holds.
    attach_c : (3,) float       Main-tether attachment A, chaser body frame (m).
    body_masses : (2,) float    m_C, m_D (kg).
    inertia : (2, 3, 3) float   Chaser and debris inertia about their CoMs, body frames (kg m^2).
    debris : DebrisBody         The debris cylinder and contact law (:class:`multibody.net_towing_kernel.DebrisBody`).
    n_sub : int                 Net sub-steps per body step.
    step : float                Body step (s).
    control : ChaserControl     Thrust law and attitude control (:class:`multibody.net_towing_kernel.ChaserControl`).
    body_reference : (2, 3) float   Chaser and debris reference CoM positions, absolute (m).
    acc, diag, f, work : float arrays   Per-step impulses (ACC_SIZE), diagnostics (D_SIZE), node forces (n, 3), scratch.
    """


_NET_TOW_FIELDS = ["x", "xv", "lag", "clock", "net", "reference", "mu", "central", "attach_c", "body_masses", "inertia",
                   "debris", "n_sub", "step", "control", "body_reference", "acc", "diag", "f", "work"]
structref.define_proxy(NetTowKernel, NetTowKernelType, _NET_TOW_FIELDS)


@njit(cache=True)
def net_tow_kernel(x, xv, lag, clock, net, reference, mu, central, attach_c, body_masses, inertia, debris, n_sub, step,
                   control, body_reference, acc, diag, f, work):
    """The :class:`NetTowKernel` of these fields (compiled once and cached, unlike the proxy's own
    constructor).

    Parameters
    ----------
    x, xv, lag, clock, net, reference, mu, central, attach_c, body_masses, inertia, debris, n_sub, step, control, body_reference, acc, diag, f, work
        The fields of :class:`NetTowKernel` (shapes, units and frames there).
    """
    return NetTowKernel(x, xv, lag, clock, net, reference, mu, central, attach_c, body_masses, inertia, debris, n_sub,
                        step, control, body_reference, acc, diag, f, work)


@njit(cache=True)
def step_forces(q, v, t, advance, main_tether, tow):
    """Generalized forces (12,) on chaser and debris at time ``t`` (s, absolute) for Exudyn's object,
    from their coordinates ``q`` and velocities ``v`` (12,) (CoM displacement (m) and rotation vector,
    CoM velocity (m/s, inertial) and angular velocity (rad/s, body), per body), the run ``tow``
    (:class:`NetTowKernel`) and the main tether ``main_tether`` = [k_MT (N/m), c_MT (N s/m), l_MT0 (m)].
    If ``advance``, the net (``x`` relative to ``reference``, ``xv``) is first sub-cycled from
    ``clock[CLOCK_TIME]`` to ``t`` (:func:`multibody.net_towing_kernel.advance_net`) and the bodies get
    the step's mean reactions; otherwise (the solver's initial evaluation, output samples) the
    reactions at the current state. Thrust and attitude torque (``control``, a
    :class:`multibody.net_towing_kernel.ChaserControl`) and gravity are evaluated at ``t``.

    Parameters
    ----------
    q, v : (12,) float
        Chaser and debris coordinates and velocities (see above).
    t : float
        Time (s, absolute).
    advance : bool
        Sub-cycle the net to ``t`` and advance the thrust law.
    main_tether : (3,) float
        k_MT (N/m), c_MT (N s/m), l_MT0 (m).
    tow : NetTowKernel
        The run.
    """
    x, xv, lag, clock, net, reference = tow.x, tow.xv, tow.lag, tow.clock, tow.net, tow.reference
    mu, central, attach_c, body_masses, inertia, debris_body = (tow.mu, tow.central, tow.attach_c, tow.body_masses,
                                                                tow.inertia, tow.debris)
    n_sub, step, control, body_reference = tow.n_sub, tow.step, tow.control, tow.body_reference
    acc, diag, f, work = tow.acc, tow.diag, tow.f, tow.work
    bodies = _bodies(q, v, body_reference[0], body_reference[1])
    force = np.zeros(12)
    if advance:
        h_step = t - clock[CLOCK_TIME]
        tension, z, rate = advance_net(x, xv, lag, clock[CLOCK_TIME], t, n_sub, net, reference, mu, central,
                                       main_tether, attach_c, bodies, debris_body, f, acc, work)
        clock[CLOCK_TIME] = t
        clock[CLOCK_IMPULSE:CLOCK_IMPULSE + 3] += acc[ACC_EXTERNAL:ACC_EXTERNAL + 3]
        scale = 1.0 / h_step
    else:
        h_step = step
        h = step / n_sub
        scale = 1.0 / h  # one sub-step's impulses, from a copy of the contact lags (the state is not advanced)
        rot_c = rotation_matrix_from_rotation_vector(bodies[0, 3:6])
        rot_d = rotation_matrix_from_rotation_vector(bodies[1, 3:6])
        arm = rot_c @ attach_c
        a_point = bodies[0, 0:3] + arm
        a_velocity = bodies[0, 6:9] + rot_c @ np.cross(bodies[0, 9:12], attach_c)
        acc[:] = 0.0
        tension, z, rate = net_forces(x, xv, lag.copy(), net, reference, mu, central,
                                      TetherEnd(main_tether, a_point, a_velocity, bodies[0, 0:3]),
                                      DebrisMotion(bodies[1, 0:3] - reference, rot_d, bodies[1, 6:9], rot_d @ bodies[1, 9:12]),
                                      debris_body, h, f, acc, work)
    rot_c = rotation_matrix_from_rotation_vector(bodies[0, 3:6])
    rot_d = rotation_matrix_from_rotation_vector(bodies[1, 3:6])
    force[0:3] = scale * acc[ACC_CHASER_F:ACC_CHASER_F + 3]
    force[3:6] = rot_c.T @ (scale * acc[ACC_CHASER_T:ACC_CHASER_T + 3])
    force[6:9] = scale * acc[ACC_DEBRIS_F:ACC_DEBRIS_F + 3]
    force[9:12] = rot_d.T @ (scale * acc[ACC_DEBRIS_T:ACC_DEBRIS_T + 3])
    diag[D_TENSION] = scale * acc[ACC_TENSION]
    diag[D_ELONGATION], diag[D_RATE] = z, rate
    diag[D_CONTACTS] = scale * acc[ACC_CONTACTS]
    diag[D_CONTACT_F] = scale * acc[ACC_CONTACT_F]
    diag[D_CLOSING] = acc[ACC_CLOSING]
    a_point = bodies[0, 0:3] + rot_c @ attach_c
    u = reference + x[central] - a_point
    u /= np.sqrt(u @ u)
    chaser = force[0:6]
    before = chaser[0:3].copy()
    separation, relative = bodies[1, 0:3] - bodies[0, 0:3], bodies[1, 6:9] - bodies[0, 6:9]
    chaser_actuation(t, z, rate, range_rate(separation[0], separation[1], separation[2], relative[0], relative[1],
                                            relative[2]),
                     u, rot_c, bodies[0, 0:3], bodies[0, 6:9], bodies[0, 9:12], inertia[0], control, step, advance,
                     chaser, diag)
    if control.lateral[L_ON] != 0.0:   # off: not even a + 0.0, so the default path stays bit-identical
        side = lateral_thrust(t, control.lateral, bodies[0, 0:3], bodies[0, 6:9], rot_c, bodies[1, 0:3],
                              bodies[1, 6:9], reference + x[central], xv[central], rot_d @ (inertia[1] @ bodies[1, 9:12]))
        chaser[0:3] += side
        diag[D_LATERAL:D_LATERAL + 3] = side
    debris = force[6:12]
    add_body_gravity(chaser, 0, bodies[0, 0], bodies[0, 1], bodies[0, 2], body_masses[0], mu)
    add_body_gravity(debris, 0, bodies[1, 0], bodies[1, 1], bodies[1, 2], body_masses[1], mu)
    if advance:
        clock[CLOCK_IMPULSE:CLOCK_IMPULSE + 3] += h_step * (chaser[0:3] - before) + h_step * (
            debris[0:3] - scale * acc[ACC_DEBRIS_F:ACC_DEBRIS_F + 3])
    return force


class NetTowState:
    """The net's state and work arrays of one run, and the call into :func:`step_forces`."""

    def __init__(self, model: FullNetModel):
        top = model.net.topology
        self.model = model
        self.reference = np.array(model.positions[1], float)
        self.x = np.ascontiguousarray(model.node_positions - self.reference)
        self.v = np.array(model.node_velocities, float)  # a copy: a run must not change its model
        self.clock = np.zeros(CLOCK_SIZE)
        self.clock[CLOCK_TIME] = model.start_time
        self.rest = top.rest_lengths.copy()
        self.stiffness = top.stiffness.copy()
        self.thrust_state = np.array(model.thrust_state, float)
        self.control = chaser_control(np.ascontiguousarray(model.attitude, float), model.thrust_command,
                                      bool(model.thrust_along_body_z), np.ascontiguousarray(model.thrust_params, float),
                                      self.thrust_state, np.ascontiguousarray(model.lateral, float))
        self.acc, self.diag = np.zeros(ACC_SIZE), np.zeros(D_SIZE)
        self.f, self.work, self.lag = np.zeros_like(self.x), np.zeros(21), np.zeros_like(self.x)
        self.tether_on = np.array(model.main_tether, float)
        self.tether_off = np.array([0.0, 0.0, model.main_tether[2]])
        self.reeling = model.closing_duration is not None
        self.rest_rate = np.zeros(len(self.rest))
        self.net = NetThreads(top.masses, top.radii, top.threads, self.rest, self.stiffness, top.damping,
                              self.rest_rate)
        self.debris = DebrisBody(float(model.masses[1]), model.inverse_inertia[1], model.geometry, model.contact_law)
        m = model
        self.kernel = net_tow_kernel(self.x, self.v, self.lag, self.clock, self.net, self.reference, float(m.mu),
                                     int(m.net.central), np.ascontiguousarray(m.attach_chaser_body, float), m.masses,
                                     m.inertia_body, self.debris, int(m.substeps), float(m.step), self.control,
                                     m.positions, self.acc, self.diag, self.f, self.work)
        self.rest_open = top.rest_lengths[-len(model.net.closing_rest_closed):].copy()

    def reel(self, t):
        """Closing loop's natural lengths (m) and stiffnesses EA/l0 (N/m) at time ``t`` (s): open
        before ``closing_time``, linear to closed over ``closing_duration``, closed after.

        Parameters
        ----------
        t : float
            Time (s, absolute), at or after ``model.closing_time``.

        Updates ``rest``, ``stiffness`` and ``rest_rate`` (m/s: the ramp's, so the loop's dampers act on the
        stretch's rate, not on the reel-in itself) of the closing threads in place (the kernel holds views).
        """
        m = self.model
        ramp = reel_fraction(t, m.closing_time, m.closing_duration)
        k = len(self.rest_open)
        self.rest[-k:] = reeled_rest_lengths(self.rest_open, m.net.closing_rest_closed, ramp)
        self.stiffness[-k:] = m.net.closing_stiffness(self.rest[-k:])
        self.reeling = ramp < 1.0
        self.rest_rate[-k:] = (m.net.closing_rest_closed - self.rest_open) / m.closing_duration if self.reeling else 0.0

    def forces(self, q, v, t, advance):
        """Generalized forces (12,) on chaser and debris (:func:`step_forces`), the closing loop
        reeled and the main tether switched on from ``closing_time``.

        Parameters
        ----------
        q, v : (12,) float
            Chaser and debris CoM displacements from their reference positions (m, inertial) and
            rotation vectors body -> inertial (rad); CoM velocities (m/s, inertial) and angular
            velocities (rad/s, body frames).
        t : float
            Time (s, absolute).
        advance : bool
            Sub-cycle the net to ``t`` and advance the thrust law (a new step time).

        Returns
        -------
        (12,) float
            Forces (N, inertial) and torques (N m, body frames), per body.
        """
        m = self.model
        if self.reeling and t >= m.closing_time:
            self.reel(t)
        tether = self.tether_on if t >= m.closing_time else self.tether_off
        return step_forces(q, v, t, advance, tether, self.kernel)

    def momentum(self, v_bodies) -> np.ndarray:
        """Total linear momentum (N s, inertial) of chaser, debris and net.

        Parameters
        ----------
        v_bodies : (12,) float
            Chaser and debris velocities: CoM velocity (m/s, inertial), angular velocity (rad/s,
            body frame), per body (the net's velocities are the state's).

        Returns
        -------
        (3,) float
            Linear momentum (N s), inertial frame.
        """
        m = self.model
        return (m.masses[0] * v_bodies[0:3] + m.masses[1] * v_bodies[6:9]
                + (m.net.topology.masses[:, None] * self.v).sum(axis=0))


class _Forces:
    """Force user function of the coupled object (see :class:`multibody.towing._TowForces`)."""

    def __init__(self, state: NetTowState):
        self.state = state
        self.last_time = -np.inf

    def __call__(self, mbs, t, item, q, q_t):
        advance = t > self.last_time and t > 0.0
        self.last_time = max(t, self.last_time)
        return self.state.forces(np.asarray(q), np.asarray(q_t), self.state.model.start_time + t, advance)


@dataclass
class NetTowResult:
    """Samples of one full-net run: body states (k, 12), central node (k, 6), diagnostics (k, D_SIZE),
    momentum and external impulse (k, 3) each, the net's internal kinetic energy (k,) (J); net snapshots
    (j, n, 3) at ``net_time``; wall time (s); ``switch``: None, or the full state where the run stopped at
    quasi-steady state (``model.switch``): ``time`` (s), ``q``, ``v`` (12,) (the Exudyn coordinates),
    ``node_positions``, ``node_velocities`` (n, 3) (m, m/s, inertial), ``thrust_state`` (the law's);
    ``state_at``: the same at ``model.state_at``."""

    model: FullNetModel
    time: np.ndarray
    q: np.ndarray
    v: np.ndarray
    node: np.ndarray
    diag: np.ndarray
    momentum: np.ndarray
    external_impulse: np.ndarray
    net_time: np.ndarray
    net_positions: np.ndarray
    wall_time: float
    kinetic: np.ndarray = None
    switch: dict | None = None
    state_at: dict | None = None
    kinetic_relative: np.ndarray = None

    def series(self) -> dict:
        """The lower-order model's series names (:meth:`multibody.towing.TowResult.series`; the
        connection point is the central node), plus the net's own (SI; frames in the names)."""
        m = self.model
        rot = np.array([[rotation_matrix_from_rotation_vector(self.q[k, b + 3:b + 6]) for b in (0, 6)]
                        for k in range(len(self.time))]).reshape(-1, 2, 3, 3)
        return {
            "time": self.time,
            "connection_point_inertial": self.node[:, 0:3], "connection_point_velocity_inertial": self.node[:, 3:6],
            "chaser_com_inertial": m.positions[0] + self.q[:, 0:3], "debris_com_inertial": m.positions[1] + self.q[:, 6:9],
            "chaser_velocity_inertial": self.v[:, 0:3], "debris_velocity_inertial": self.v[:, 6:9],
            "chaser_to_inertial": rot[:, 0], "debris_to_inertial": rot[:, 1],
            "chaser_omega_body": self.v[:, 3:6], "debris_omega_body": self.v[:, 9:12],
            "main_tether_tension": self.diag[:, D_TENSION], "main_tether_elongation": self.diag[:, D_ELONGATION],
            "main_tether_elongation_rate": self.diag[:, D_RATE],
            "thrust": self.diag[:, D_THRUST], "control_torque_body": self.diag[:, D_TORQUE:D_TORQUE + 3],
            "lateral_thrust_inertial": self.diag[:, D_LATERAL:D_LATERAL + 3],
            "sliding_variable": self.diag[:, D_SLIDING:D_SLIDING + 3],
            "net_contacts": self.diag[:, D_CONTACTS], "net_contact_force": self.diag[:, D_CONTACT_F],
            "closing_thread_peak_tension": self.diag[:, D_CLOSING],
            "total_momentum_inertial": self.momentum, "external_impulse_inertial": self.external_impulse,
            "net_internal_kinetic_energy": self.kinetic,
            "net_kinetic_energy_relative_to_debris": self.kinetic_relative,
            "net_time": self.net_time, "net_nodes_inertial": self.net_positions,
        }


class _Sampler:
    """Post-step function: samples every ``model.every`` steps, net snapshots every ``model.net_every``."""

    def __init__(self, state: NetTowState):
        m = state.model
        self.state, self.count = state, 0
        k, j = m.n_steps // m.every + 1, m.n_steps // m.net_every + 1
        self.time, self.q, self.v, self.node = np.zeros(k), np.zeros((k, 12)), np.zeros((k, 12)), np.zeros((k, 6))
        self.diag, self.momentum, self.impulse = np.zeros((k, D_SIZE)), np.zeros((k, 3)), np.zeros((k, 3))
        self.net_time, self.net = np.zeros(j), np.zeros((j, len(state.x), 3))
        self.kinetic, self.kinetic_relative = np.zeros(k), np.zeros(k)
        self.sample = self.net_sample = 0
        self.watch = QuasiSteadyWatch(m.switch) if m.switch is not None else None
        self.switch = self.state_at = None

    def full_state(self, t, q, v) -> dict:
        """The whole state at ``t`` (s): time, body coordinates and velocities, nodes, thrust-law state."""
        s = self.state
        return {"time": s.model.start_time + t, "q": q.copy(), "v": v.copy(), "node_positions": s.reference + s.x,
                "node_velocities": s.v.copy(), "thrust_state": s.thrust_state.copy()}

    def record(self, mbs, t):
        s = self.state
        m = s.model
        data = mbs.systemData
        q, v = np.asarray(data.GetODE2Coordinates()), np.asarray(data.GetODE2Coordinates_t())
        k = self.sample
        if self.count % m.every == 0 and k < len(self.time):
            self.time[k], self.q[k], self.v[k] = m.start_time + t, q, v
            self.diag[k] = s.diag  # of the last force evaluation: this step's (Exudyn's initial one at t = 0)
            self.node[k] = np.r_[s.reference + s.x[m.net.central], s.v[m.net.central]]
            self.momentum[k], self.impulse[k] = s.momentum(v), s.clock[CLOCK_IMPULSE:CLOCK_IMPULSE + 3]
            self.kinetic[k] = net_internal_kinetic_energy(m.net.topology.masses, s.v)
            self.kinetic_relative[k] = net_kinetic_energy_relative_to_body(
                m.net.topology.masses, s.reference + s.x, s.v, m.positions[1] + q[6:9], v[6:9],
                rotation_matrix_from_rotation_vector(q[9:12]) @ v[9:12])
            self.sample += 1
            if self.state_at is None and m.state_at is not None and m.start_time + t >= m.state_at - 1e-9:
                self.state_at = self.full_state(t, q, v)
            if self.watch is not None and self.watch.update(m.start_time + t, self.kinetic_relative[k],
                                                            s.diag[D_TENSION]):
                self.switch = self.full_state(t, q, v)
                self.count += 1
                return False  # quasi-steady: the lower-order model takes over (multibody.tow_switch)
        if self.count % m.net_every == 0 and self.net_sample < len(self.net_time):
            self.net_time[self.net_sample] = m.start_time + t
            self.net[self.net_sample] = s.reference + s.x
            self.net_sample += 1
        self.count += 1
        return True

    def __call__(self, mbs, t):
        return self.record(mbs, t)


def build_system(model: FullNetModel, forces: _Forces):
    """Exudyn system: chaser and debris rigid bodies, one generic object carrying all forces.

    Parameters
    ----------
    model : FullNetModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).
    forces : _Forces
        The generic object's force user function (net, tethers, contact, thrust, gravity).

    Returns
    -------
    sc : exudyn.SystemContainer
    mbs : exudyn.MainSystem
        Assembled system (nodes: chaser 0, debris 1).
    """
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    nodes = []
    for b in range(2):
        node = mbs.AddNode(NodeRigidBodyRotVecLG(
            referenceCoordinates=list(model.positions[b]) + [0.0] * 3,
            initialCoordinates=[0.0] * 3 + list(Rotation.from_matrix(model.body_to_inertial[b]).as_rotvec()),
            initialVelocities=list(model.velocities[b]) + list(model.omega_body[b])))
        j = model.inertia_body[b]
        mbs.AddObject(ObjectRigidBody(nodeNumber=node, mass=float(model.masses[b]),
                                      inertia=[j[0, 0], j[1, 1], j[2, 2], j[1, 2], j[0, 2], j[0, 1]]))
        nodes.append(node)
    mbs.AddObject(ObjectGenericODE2(nodeNumbers=nodes, forceUserFunction=forces))
    mbs.Assemble()
    return sc, mbs


def run_exudyn(model: FullNetModel) -> NetTowResult:
    """Build and integrate ``model`` (VelocityVerlet at ``model.step``, net sub-cycled).

    Parameters
    ----------
    model : FullNetModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).

    Returns
    -------
    NetTowResult
        Samples up to the end or to a failed health check (:func:`multibody.impact.solve_checked`).
    """
    state = NetTowState(model)
    forces = _Forces(state)
    sc, mbs = build_system(model, forces)
    sampler = _Sampler(state)
    watch = HealthWatch(tow_failure_cause(model.step))
    mbs.SetPostStepUserFunction(checked_post_step(watch, sampler, HEALTH_EVERY_STEPS))
    settings = explicit_settings(model.step, model.n_steps)
    start = time.perf_counter()
    try:
        solve_checked(mbs, settings, exu.DynamicSolverType.VelocityVerlet, watch)
    except SimulationFailed:
        if sampler.switch is None or watch.failure is not None:
            raise
        # stopped by the switch: the solver reports the early end, nothing failed
    wall = time.perf_counter() - start
    k = sampler.sample
    return NetTowResult(model, sampler.time[:k], sampler.q[:k], sampler.v[:k], sampler.node[:k], sampler.diag[:k],
                        sampler.momentum[:k], sampler.impulse[:k], sampler.net_time[:sampler.net_sample],
                        sampler.net[:sampler.net_sample], wall, sampler.kinetic[:k], sampler.switch,
                        sampler.state_at, sampler.kinetic_relative[:k])
