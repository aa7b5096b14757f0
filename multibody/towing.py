"""Lower-order towing model in Exudyn: chaser and debris rigid bodies, the connection point mass,
the main tether and the sub-tethers (Boonrath, Singh & Botta 2024, Sec. 2.2, Fig. 2).

Chaser and debris are Exudyn nodes (``NodeRigidBodyRotVecLG``, Lie-group integration, explicit
VelocityVerlet); every force on them, gravity, thrust and the attitude control torque come from the
compiled :func:`multibody.towing_kernel.towing_forces` through the force user function of one
``ObjectGenericODE2`` spanning both nodes. The light connection point P is stepped implicitly inside
that user function, once per step (:mod:`multibody.connection_point`, BDF2): its stiff, damped
tethers no longer limit the step, so a run costs the same for every s of eq. (24). Frame:
Earth-centred inertial for every position and velocity; angular velocities in the body frames.

:func:`run_twin` integrates the same forces with the same scheme in compiled code, without
Exudyn (2-3x faster: no per-step Python call); the identification uses it and
``tests/multibody/test_towing.py`` checks that both agree.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import NodeRigidBodyRotVecLG, ObjectGenericODE2, ObjectRigidBody
from scipy.spatial.transform import Rotation

from multibody.health import HealthWatch
from multibody.impact import _object_state_index, checked_post_step, explicit_settings, solve_checked
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.control.thrust_laws import LAWS
from multibody.towing_kernel import (N_COORDINATES, ST_TENSION, TowKernel, body_forces, no_load, pack, sampled_state,
                                     tow_kernel, verlet_run)
from multibody.towing_kernel import MT_ELONGATION, MT_ELONGATION_RATE, MT_TENSION, SLIDING, THRUST, TORQUE


@dataclass
class TowedBodies:
    """What every towing run needs besides its tethers: chaser and debris, their controls and the
    times (SI units; inertial frame unless ``_body``). Base of :class:`TowingModel` (lower-order) and
    :class:`multibody.net_towing.FullNetModel` (full net); the subclasses add the masses and tethers.

    Attributes
    ----------
    inertia_body : (2, 3, 3) float  J_C, J_D about the CoMs, body frames (kg m^2).
    attach_chaser_body : (3,) float MT attachment r_A/C, chaser frame (m).
    mu : float                      Gravitational parameter (m^3/s^2).
    attitude : (8,) float           Controller on (1/0), K (1/s), G (3,) (rad/s^2), epsilon (3,) (rad/s).
    thrust_law : str                The thrust law's name (a module of :mod:`multibody.control.thrust_laws`).
    thrust_along_body_z : bool      Thrust along the chaser's body z (MRAC) or against its velocity (ramp).
    thrust_params, thrust_state : (k,) float   The thrust law's constants and initial states.
    positions, velocities : (b, 3) float       Point masses' and CoMs' positions (m, absolute) and velocities
                                               (m/s) at ``start_time``, in the subclass's order.
    body_to_inertial : (2, 3, 3) float         Chaser and debris attitude at ``start_time``.
    omega_body : (2, 3) float                  Chaser and debris angular velocity, body frames (rad/s).
    start_time, end_time, step, output_interval : float   (s)
    """

    inertia_body: np.ndarray
    attach_chaser_body: np.ndarray
    mu: float
    attitude: np.ndarray
    thrust_law: str
    thrust_along_body_z: bool
    thrust_params: np.ndarray
    thrust_state: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    body_to_inertial: np.ndarray
    omega_body: np.ndarray
    start_time: float
    end_time: float
    step: float
    output_interval: float
    inverse_inertia: np.ndarray = field(init=False)   # (2, 3, 3) inverse of inertia_body (1/(kg m^2))

    def __post_init__(self):
        self.inverse_inertia = np.linalg.inv(self.inertia_body)
        LAWS[self.thrust_law]     # an unknown law is refused here, listing the known ones

    @property
    def thrust_command(self):
        """The thrust law's compiled ``command`` (:data:`multibody.control.thrust.THRUST_SIGNATURE`)."""
        return LAWS[self.thrust_law].command

    @property
    def n_steps(self) -> int:
        return int(round((self.end_time - self.start_time) / self.step))

    @property
    def every(self) -> int:
        """Steps between output samples."""
        return max(1, int(round(self.output_interval / self.step)))


@dataclass
class TowingModel(TowedBodies):
    """One lower-order run: :class:`TowedBodies` plus the connection point P and the tethers.

    Attributes
    ----------
    masses : (3,) float             m_P, m_C, m_D (kg).
    attach_debris_body : (n, 3) float  ST attachments r_i/D, debris frame (m).
    tether : (6,) float             k_MT (N/m), c_MT (N s/m), l_MT0 (m), k_ST, c_ST, l_ST0.
    positions, velocities : (3, 3) float       P, chaser CoM, debris CoM at ``start_time`` (m, m/s).
    """

    masses: np.ndarray
    attach_debris_body: np.ndarray
    tether: np.ndarray

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Coordinates and velocities (15,) each at ``start_time`` (layout of :mod:`multibody.towing_kernel`)."""
        q, v = np.zeros(N_COORDINATES), np.zeros(N_COORDINATES)
        v[0:3] = self.velocities[0]
        for b, base in enumerate((3, 9)):
            q[base + 3:base + 6] = Rotation.from_matrix(self.body_to_inertial[b]).as_rotvec()
            v[base:base + 3] = self.velocities[b + 1]
            v[base + 3:base + 6] = self.omega_body[b]
        return q, v


def packed(model: TowingModel) -> TowKernel:
    """The model for the compiled kernels: one float array (:func:`multibody.towing_kernel.pack`,
    ``.work``) and the thrust law's compiled command (``.thrust``); the array also carries the
    thrust law's state, so each run needs its own.

    Parameters
    ----------
    model : TowingModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).
    """
    work = pack(model.positions, model.masses, model.inertia_body, model.attach_chaser_body,
                model.attach_debris_body, model.tether, model.mu, model.attitude, model.thrust_along_body_z,
                model.thrust_params, model.thrust_state, model.step, model.velocities[0], model.start_time)
    return tow_kernel(work, model.thrust_command)


@dataclass
class TowResult:
    """Samples of one run: ``time`` (k,) (s), ``q``/``v`` (k, 15) in the kernel layout, ``diag``
    (k, 10 + n) diagnostics of :func:`~multibody.towing_kernel.towing_forces`, wall time (s)."""

    model: TowingModel
    time: np.ndarray
    q: np.ndarray
    v: np.ndarray
    diag: np.ndarray
    wall_time: float

    def series(self) -> dict:
        """Named time series (SI; frames in the names), see docs/towing.md."""
        m = self.model
        body_to_inertial = np.array([[rotation_matrix_from_rotation_vector(self.q[k, b + 3:b + 6]) for b in (3, 9)]
                        for k in range(len(self.time))]).reshape(-1, 2, 3, 3)
        return {
            "time": self.time,
            "connection_point_inertial": m.positions[0] + self.q[:, 0:3],
            "chaser_com_inertial": m.positions[1] + self.q[:, 3:6],
            "debris_com_inertial": m.positions[2] + self.q[:, 9:12],
            "connection_point_velocity_inertial": self.v[:, 0:3],
            "chaser_velocity_inertial": self.v[:, 3:6], "debris_velocity_inertial": self.v[:, 9:12],
            "chaser_to_inertial": body_to_inertial[:, 0], "debris_to_inertial": body_to_inertial[:, 1],
            "chaser_omega_body": self.v[:, 6:9], "debris_omega_body": self.v[:, 12:15],
            "main_tether_tension": self.diag[:, MT_TENSION],
            "main_tether_elongation": self.diag[:, MT_ELONGATION],
            "main_tether_elongation_rate": self.diag[:, MT_ELONGATION_RATE],
            "sub_tether_tension": self.diag[:, ST_TENSION:],
            "thrust": self.diag[:, THRUST], "control_torque_body": self.diag[:, TORQUE:TORQUE + 3],
            "sliding_variable": self.diag[:, SLIDING:SLIDING + 3],
        }


def _sample_buffers(model: TowingModel):
    k = model.n_steps // model.every + 1
    return np.zeros((k, N_COORDINATES)), np.zeros((k, N_COORDINATES)), np.zeros((k, ST_TENSION + len(model.attach_debris_body)))


def run_twin(model: TowingModel) -> TowResult:
    """Integrate ``model`` with the compiled twin of Exudyn's scheme (:func:`~multibody.towing_kernel.verlet_run`
    with no further loads).

    Parameters
    ----------
    model : TowingModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).

    Returns
    -------
    TowResult
        Samples every ``model.every`` steps from ``start_time``.
    """
    q, v = model.initial_state()
    out_q, out_v, out_diag = _sample_buffers(model)
    record = model.every * np.arange(len(out_q), dtype=np.int64)
    tow = packed(model)
    start = time.perf_counter()
    verlet_run(tow, no_load, np.zeros(1), q, v, model.start_time, model.n_steps, np.zeros(1), record, out_q, out_v,
               out_diag, np.zeros((len(out_q), 1)))
    wall = time.perf_counter() - start
    times = model.start_time + model.step * model.every * np.arange(len(out_q))
    return TowResult(model, times, out_q, out_v, out_diag, wall)


class _TowForces:
    """Force user function of the coupled object: Exudyn's VelocityVerlet calls it once per step, at
    the step's end time with the state where the step evaluates its force (new position, half-step
    velocity), and once at the start. The thrust law's state and the connection point P (implicit,
    :mod:`multibody.connection_point`; not an Exudyn node) advance once per new time.

    (The impact model sets the force from a pre-step function instead, because converting its
    thousands of coordinates to and from Python costs more than predicting the evaluation state;
    for these 12 coordinates the user function is the cheaper route: ~6 us per step against ~15.)
    """

    def __init__(self, model: TowingModel):
        self.model = model
        self.tow = packed(model)
        self.last_time = -np.inf

    def __call__(self, mbs, t, item, q, q_t):
        advance = t > self.last_time
        self.last_time = max(t, self.last_time)
        return body_forces(np.asarray(q), np.asarray(q_t), self.model.start_time + t, self.tow, advance)


class _Sampler:
    """Post-step function: records state and diagnostics every ``model.every`` steps (Exudyn also
    calls it once at the initial time)."""

    def __init__(self, forces: _TowForces, index, buffers):
        self.forces, self.index = forces, index
        self.out_q, self.out_v, self.out_diag = buffers
        self.every, self.count, self.sample = forces.model.every, 0, 0

    def record(self, sample, mbs, t):
        data = mbs.systemData
        q, v = data.GetODE2Coordinates(), data.GetODE2Coordinates_t()
        if self.index is not None:
            q, v = q[self.index], v[self.index]
        self.out_q[sample], self.out_v[sample], self.out_diag[sample] = sampled_state(
            np.asarray(q), np.asarray(v), self.forces.model.start_time + t, self.forces.tow)

    def __call__(self, mbs, t):
        if self.count % self.every == 0 and self.sample < len(self.out_q):
            self.record(self.sample, mbs, t)
            self.sample += 1
        self.count += 1
        return True


def build_towing_system(model: TowingModel, forces: _TowForces):
    """The Exudyn system: chaser and debris rigid bodies and one coupled generic object whose force
    is ``forces`` (the connection point P is advanced inside it, implicitly).

    Parameters
    ----------
    model : TowingModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).
    forces : _TowForces
        Force user function of the coupled object.

    Returns
    -------
    tuple
        (system container, main system, node list [chaser, debris]).
    """
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    q0, v0 = model.initial_state()
    nodes = []
    for b, base in enumerate((3, 9)):
        node = mbs.AddNode(NodeRigidBodyRotVecLG(referenceCoordinates=list(model.positions[b + 1]) + [0.0] * 3,
                                                 initialCoordinates=list(q0[base:base + 6]),
                                                 initialVelocities=list(v0[base:base + 6])))
        inertia_body = model.inertia_body[b]
        mbs.AddObject(ObjectRigidBody(nodeNumber=node, mass=float(model.masses[b + 1]),
                                      inertia=[inertia_body[0, 0], inertia_body[1, 1], inertia_body[2, 2], inertia_body[1, 2], inertia_body[0, 2], inertia_body[0, 1]]))
        nodes.append(node)
    mbs.AddObject(ObjectGenericODE2(nodeNumbers=nodes, forceUserFunction=forces))
    mbs.Assemble()
    return sc, mbs, nodes


def run_exudyn(model: TowingModel) -> TowResult:
    """Build and integrate ``model`` in Exudyn (VelocityVerlet, fixed step, Lie-group rotations).

    Parameters
    ----------
    model : TowingModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).

    Returns
    -------
    TowResult
        Samples every ``model.every`` steps from ``start_time``.
    """
    forces = _TowForces(model)
    sc, mbs, nodes = build_towing_system(model, forces)
    sampler = _Sampler(forces, _object_state_index(mbs, nodes, [6, 6]), _sample_buffers(model))
    watch = HealthWatch(tow_failure_cause(model.step))
    mbs.SetPostStepUserFunction(checked_post_step(watch, sampler, HEALTH_EVERY_STEPS))
    settings = explicit_settings(model.step, model.n_steps)
    start = time.perf_counter()
    solve_checked(mbs, settings, exu.DynamicSolverType.VelocityVerlet, watch)
    wall = time.perf_counter() - start
    times = model.start_time + model.step * model.every * np.arange(len(sampler.out_q))
    return TowResult(model, times, sampler.out_q, sampler.out_v, sampler.out_diag, wall)


#: Steps between two finite-state checks of a tow: a NaN stays once it appears, and 10 steps
#: keep the check below 1 % of a lower-order step (bench/bench_towing.py).
HEALTH_EVERY_STEPS = 10


def tow_failure_cause(step: float) -> str:
    """Words for a failed tow (the connection point is implicit, so no single explicit limit applies).

    Parameters
    ----------
    step : float
        The run's step (s).
    """
    return (f"at the step {step:g} s the bodies' rotation or the tethers lost stability: reduce simulation.step "
            f"and check the tether stiffness and damping, the thrust and the initial rates for extreme values")


def stable_step(model: TowingModel, safety: float = 0.5) -> float:
    """Largest VelocityVerlet step (s) an explicit connection point would allow, times ``safety``
    (P is implicit now; kept to report what the implicit update saves, bench/bench_towing.py).

    P (mass m_P) hangs on all tethers at once: :math:`\\ddot x = -\\omega^2 x - \\gamma\\dot x` with
    :math:`\\omega^2 = k_\\Sigma/m_P`, :math:`\\gamma = c_\\Sigma/m_P` (summed tether stiffness and damping).
    Verlet applies the damper with the half-step velocity; its one-step matrix has trace
    :math:`2 - h^2\\omega^2 - h\\gamma` and determinant :math:`1 - h\\gamma`, and the Jury conditions give
    stability for :math:`h^2\\omega^2 + 2h\\gamma < 4`, i.e.
    :math:`h < (\\sqrt{\\gamma^2 + 4\\omega^2} - \\gamma)/\\omega^2`. With ``safety`` 0.5,
    :math:`h\\gamma < 1`: the damped mode does not oscillate from step to step.

    Parameters
    ----------
    model : TowingModel
        The run (SI; positions and velocities inertial, rates and inertias in the body frames).
    safety : float
        Fraction of the stability limit (-).
    """
    n = len(model.attach_debris_body)
    omega2 = (model.tether[0] + n * model.tether[3]) / model.masses[0]
    gamma = (model.tether[1] + n * model.tether[4]) / model.masses[0]
    return safety * (np.sqrt(gamma * gamma + 4.0 * omega2) - gamma) / omega2
