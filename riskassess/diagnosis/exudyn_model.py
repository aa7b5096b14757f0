"""The diagnosis scenarios in Exudyn: rigid body, or main body + appendage on a penalty hinge,
with the effects' laws applied through user-function loads.

The bodies are Exudyn rigid bodies in the inertial frame I (= LVLH at t = 0); the hinge is the
project's penalty revolute joint (:func:`multibody.hinge.add_penalty_joint`) whose connector
user function adds the effects' hinge torques to its springs; every body carries the orbit's
tidal force on its CoM (Clohessy-Wiltshire in inertial axes) and the effects' torques and
accelerations; a nutation damper is a real rotor body coupled by a rotational damper. Sensor
effects act on the recorded channels. This is the reference the fast model
(:mod:`riskassess.diagnosis.plants.dynamics`) is checked against, and the generator of the tests' measured data.
"""
from __future__ import annotations

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (LoadForceVector, LoadTorqueVector, MarkerBodyRigid, MarkerNodeRigid,
                                  ObjectConnectorRigidBodySpringDamper)
from scipy.spatial.transform import Rotation

from riskassess.diagnosis.plants.channels import HINGE, OMEGA, QUATERNION, REL
from riskassess.diagnosis.plants.dynamics import axis_rotation, initial_state, radial_inertial
from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.observation import lvlh_from_inertial
from riskassess.diagnosis.plants.plant import Plant
from riskassess.diagnosis.plants.scenario import plant_of
from riskassess.diagnosis.towing_exudyn import simulate_towing_exudyn
from multibody.assembly import JointSpec, RigidBodySpec
from multibody.hinge import add_penalty_joint, hinge_frame_lvlh
from multibody.impact import add_rigid_bodies, detach_step_functions, explicit_settings
from multibody.solver_output import solver_chatter_captured

#: Exudyn RK44 step (s) with a hinge: the penalty hinge is tuned to it (mode at 0.5 / step = 125
#: rad/s, far above hinge and tumble rates of ~0.01-3 rad/s; its compliance changes the hinge
#: motion by ~1e-5 of its range, tests/diagnosis/test_exudyn_model.py).
HINGED_STEP = 4e-3
#: Exudyn RK44 step (s) of a rigid body: 0.01 rad per step at 1 rad/s.
RIGID_STEP = 1e-2
#: Mass of a nutation damper's rotor (kg): negligible against any debris, it only carries J_d.
DAMPER_MASS = 1e-3


class ExudynScenario:
    """Builder of one scenario; effects register their loads before :meth:`simulate`."""

    def __init__(self, plant: Plant, step: float | None = None):
        self.plant = plant
        self.step = step or (HINGED_STEP if plant.hinged else RIGID_STEP)
        self.body_torques = []        # fn(t, body, body_to_inertial, omega_body) -> torque (N m, body frame)
        self.hinge_torques = []       # fn(t, angle, rate) -> torque on the appendage about the axis (N m)
        self.com_accelerations = []   # fn(t, r_inertial) -> acceleration (m/s^2, I)
        self.damper = None            # (inertia (kg m^2), damping (N m s))
        self.bodies = self._bodies()

    # -- effect hooks ------------------------------------------------------------------
    def add_body_torque(self, fn):
        """Register a torque on the bodies.

        Parameters
        ----------
        fn : callable
            ``fn(t, body, body_to_inertial, omega_body) -> torque_body``: time (s), body index (0 main,
            1 appendage), (3, 3) rotation body -> I, (3,) inertial angular velocity in the body frame
            (rad/s); returns the (3,) torque on that body, body frame (N m).
        """
        self.body_torques.append(fn)

    def add_hinge_torque(self, fn):
        """Register a torque on the appendage about the hinge axis.

        Parameters
        ----------
        fn : callable
            ``fn(t, angle, rate) -> torque``: time (s), hinge angle (rad), hinge rate (rad/s); returns
            the torque on the appendage about the axis (N m).
        """
        self.hinge_torques.append(fn)

    def add_com_acceleration(self, fn):
        """Register an acceleration of every body's CoM.

        Parameters
        ----------
        fn : callable
            ``fn(t, r_inertial) -> a_inertial``: time (s), the body's CoM position (m, I); returns its
            (3,) acceleration (m/s^2, I).
        """
        self.com_accelerations.append(fn)

    def add_damper(self, inertia, damping):
        """Add a nutation damper: a rotor at the main CoM coupled by a rotational damper.

        Parameters
        ----------
        inertia : float
            Rotor inertia J_d, isotropic (kg m^2).
        damping : float
            Rotational damping c (N m s).
        """
        self.damper = (float(inertia), float(damping))

    def inertia_body(self, body: int) -> np.ndarray:
        """A body's inertia about its CoM, its own axes (kg m^2).

        Parameters
        ----------
        body : int
            0 main body, 1 appendage.

        Returns
        -------
        inertia_body : (3, 3) float
        """
        return self.bodies[body].inertia_body

    # -- bodies at t = 0 -----------------------------------------------------------------
    def _bodies(self) -> list[RigidBodySpec]:
        p = self.plant
        x0 = initial_state(p)
        rho, v_sys = x0[9:12], x0[12:15]
        rot = p.attitude0
        omega_i = rot @ p.omega0
        if not p.hinged:
            return [RigidBodySpec("main", p.mass_main, p.inertia_main, rho, rot, v_sys, p.omega0)]
        s = axis_rotation(p.axis, p.hinge_angle0) @ p.appendage_from_hinge
        d = p.hinge_main + s
        d_rate = rot @ (np.cross(p.omega0, d) + p.hinge_rate0 * np.cross(p.axis, s))
        share = p.mass_appendage / p.total_mass
        hinge_rot = axis_rotation(p.axis, p.hinge_angle0)
        main = RigidBodySpec("main", p.mass_main, p.inertia_main, rho - share * rot @ d, rot,
                             v_sys - share * d_rate, p.omega0)
        appendage = RigidBodySpec("appendage", p.mass_appendage, p.inertia_appendage,
                                  rho + (1 - share) * rot @ d, rot @ hinge_rot, v_sys + (1 - share) * d_rate,
                                  hinge_rot.T @ (p.omega0 + p.hinge_rate0 * p.axis))
        assert np.allclose(main.body_to_lvlh @ main.omega_body, omega_i)
        return [main, appendage]

    def _joint(self) -> tuple[JointSpec, np.ndarray, np.ndarray]:
        """The hinge and the appendage's rest attitude and CoM (zero hinge angle)."""
        p, main = self.plant, self.bodies[0]
        point = main.com_lvlh + main.body_to_lvlh @ p.hinge_main
        rest_com = point + main.body_to_lvlh @ p.appendage_from_hinge
        frame = hinge_frame_lvlh(main.body_to_lvlh @ p.axis, point, rest_com)
        joint = JointSpec("hinge", "revolute", 0, 1, point, frame, p.stiffness, p.damping)
        return joint, main.body_to_lvlh, rest_com

    # -- build and run -------------------------------------------------------------------
    def _build(self):
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        nodes, objects = add_rigid_bodies(mbs, self.bodies)
        for k, node in enumerate(nodes):
            self._add_body_loads(mbs, k, node)
        if self.plant.hinged:
            joint, rest_attitude, rest_com = self._joint()
            connector = add_penalty_joint(mbs, joint, self.bodies, objects, rest_attitude, rest_com, self.step)
            if self.hinge_torques:
                mbs.SetObjectParameter(connector, "springForceTorqueUserFunction", self._hinge_user_function())
        if self.damper is not None:
            nodes.append(self._add_damper(mbs, objects[0]))
        mbs.Assemble()
        return sc, mbs, nodes

    def _add_body_loads(self, mbs, k, node):
        marker = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
        body = self.bodies[k]
        n = self.plant.mean_motion
        if n > 0 or self.com_accelerations:
            def force(mbs_, t, load):
                r = np.asarray(mbs_.GetNodeOutput(node, exu.OutputVariableType.Position))
                r_hat = radial_inertial(n, t)
                a = n * n * (3.0 * (r_hat @ r) * r_hat - r)
                for fn in self.com_accelerations:
                    a = a + fn(t, r)
                return list(body.mass * a)
            mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVectorUserFunction=force))
        if self.body_torques:
            def torque(mbs_, t, load):
                rot = np.asarray(mbs_.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
                omega = np.asarray(mbs_.GetNodeOutput(node, exu.OutputVariableType.AngularVelocityLocal))
                return list(sum(fn(t, k, rot, omega) for fn in self.body_torques))
            mbs.AddLoad(LoadTorqueVector(markerNumber=marker, bodyFixed=True, loadVectorUserFunction=torque))

    def _hinge_user_function(self):
        """The penalty connector's own springs plus the effects' hinge torques (about h2, the
        joint frame's second axis: component 4 of the connector's force-torque vector, which
        acts against the child's rotation like the torsional spring)."""
        def force_torque(mbs_, t, item, displacement, rotation, velocity, angular_velocity, stiffness, damping,
                         rot0, rot1, offset):
            u = np.r_[displacement, rotation]
            u_t = np.r_[velocity, angular_velocity]
            f = np.asarray(stiffness) @ u + np.asarray(damping) @ u_t
            f[4] -= sum(fn(t, rotation[1], angular_velocity[1]) for fn in self.hinge_torques)
            return list(f)
        return force_torque

    def _add_damper(self, mbs, main_object):
        inertia, damping = self.damper
        main = self.bodies[0]
        rotor = RigidBodySpec("damper", DAMPER_MASS, inertia * np.eye(3), main.com_lvlh, main.body_to_lvlh,
                              main.velocity_lvlh, main.omega_body)
        nodes, objects = add_rigid_bodies(mbs, [rotor])
        k = DAMPER_MASS * (0.5 / self.step) ** 2
        markers = [mbs.AddMarker(MarkerBodyRigid(bodyNumber=b, localPosition=[0.0, 0.0, 0.0]))
                   for b in (main_object, objects[0])]
        mbs.AddObject(ObjectConnectorRigidBodySpringDamper(
            markerNumbers=markers, stiffness=np.diag([k, k, k, 0.0, 0.0, 0.0]),
            damping=np.diag([2 * 0.5 * np.sqrt(k * DAMPER_MASS)] * 3 + [damping] * 3), useIntrinsicFormulation=True))
        return nodes[0]

    def simulate(self, times) -> dict[str, np.ndarray]:
        """Channels at ``times`` (s, increasing, >= 0), linearly interpolated between steps.

        Parameters
        ----------
        times : (k,) float
            Sample times (s) from t = 0.

        Returns
        -------
        channels : dict of str to (k,) float
            Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
        """
        times = np.asarray(times, float)
        sc, mbs, nodes = self._build()
        recorder = _Recorder(mbs, nodes[:len(self.bodies)], times, self.step)
        recorder.sample(0.0)
        mbs.SetPostStepUserFunction(recorder.post_step)
        n_steps = int(np.ceil(times[-1] / self.step)) + 1
        try:
            with solver_chatter_captured():
                exu.SolveDynamic(mbs, explicit_settings(self.step, n_steps), solverType=exu.DynamicSolverType.RK44)
        finally:
            detach_step_functions(mbs)     # the recorder holds the system (multibody.impact.detach_step_functions)
        return self._channels(times, recorder.states())

    def _channels(self, times, states) -> dict[str, np.ndarray]:
        p = self.plant
        to_lvlh = lvlh_from_inertial(p.mean_motion, times)
        main_rot = Rotation.from_quat(states["quat"][:, 0])
        q = (to_lvlh * main_rot).as_quat()[:, [3, 0, 1, 2]]
        rel = to_lvlh.apply(states["position"][:, 0] + main_rot.apply(p.origin_main))
        out = {c: states["omega"][:, 0, k] for k, c in enumerate(OMEGA)}
        out.update({c: q[:, k] for k, c in enumerate(QUATERNION)})
        out.update({c: rel[:, k] for k, c in enumerate(REL)})
        if p.hinged:
            app_rot = Rotation.from_quat(states["quat"][:, 1])
            relative = (main_rot.inv() * app_rot).as_rotvec()
            omega_i = [r.apply(w) for r, w in ((main_rot, states["omega"][:, 0]), (app_rot, states["omega"][:, 1]))]
            out[HINGE[0]] = relative @ p.axis
            out[HINGE[1]] = np.einsum("ki,ki->k", omega_i[1] - omega_i[0], main_rot.apply(p.axis))
        return out


class _Recorder:
    """Body states at requested times, interpolated linearly between the two steps around each."""

    def __init__(self, mbs, nodes, times, step):
        self.nodes, self.times, self.step = nodes, times, step
        self.rows, self.previous, self.next = [], None, 0
        self.mbs = mbs

    def _state(self):
        out = []
        for node in self.nodes:
            rot = np.asarray(self.mbs.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
            quat = Rotation.from_matrix(rot).as_quat()
            out.append(np.r_[self.mbs.GetNodeOutput(node, exu.OutputVariableType.Position), quat,
                             self.mbs.GetNodeOutput(node, exu.OutputVariableType.AngularVelocityLocal)])
        return np.array(out)

    def sample(self, t):
        state = self._state()
        while self.next < len(self.times) and self.times[self.next] <= t + 1e-12:
            target = self.times[self.next]
            if self.previous is None or t == self.previous[0] or target >= t - 1e-12:
                self.rows.append(state)
            else:
                t0, s0 = self.previous
                s0 = s0.copy()
                flip = np.sum(s0[:, 3:7] * state[:, 3:7], axis=1) < 0
                s0[flip, 3:7] *= -1
                w = (target - t0) / (t - t0)
                self.rows.append((1 - w) * s0 + w * state)
            self.next += 1
        self.previous = (t, state)

    def post_step(self, mbs, t):
        # read the states only on the two steps around a requested time
        if self.next < len(self.times) and self.times[self.next] <= t + 1.5 * self.step:
            self.sample(t)
        else:
            self.previous = None
        return True

    def states(self) -> dict[str, np.ndarray]:
        rows = np.array(self.rows)
        quat = rows[:, :, 3:7] / np.linalg.norm(rows[:, :, 3:7], axis=2, keepdims=True)
        return {"position": rows[:, :, :3], "quat": quat, "omega": rows[:, :, 7:10]}


def simulate_exudyn(plant: Plant, times, effect=None, values=(), names=(), step: float | None = None) -> dict:
    """Channels at ``times`` (s) of ``plant`` with ``effect`` at ``values`` (physical, SI), by Exudyn.

    Parameters
    ----------
    plant : Plant
        A rigid or hinged plant.
    times : (k,) float
        Sample times (s) from t = 0, increasing.
    effect : Effect, optional
        The effect; None: the nominal model.
    values : (m,) float
        Its physical parameter values (SI, order of its ``parameter_specs``).
    names : sequence of str
        Their names.
    step : float, optional
        Exudyn RK44 step (s); default ``HINGED_STEP`` or ``RIGID_STEP``.

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    values = np.asarray(values, float)
    sample_times = np.asarray(times, float)
    if effect is not None:
        plant = effect.modify_plant(plant, values)
        sample_times = effect.sample_times(sample_times, values)
    scenario = ExudynScenario(plant, step)
    if effect is not None:
        effect.add_to_exudyn(scenario, values, names)
    out = scenario.simulate(sample_times)
    return effect.measure(out, values, names) if effect is not None else out


def simulate_case(case, times, step: float | None = None) -> dict:
    """Channels at ``times`` (s) of a case with every effect its ``[[effects]]`` lists (an extended
    case written by `riskassess diagnose`), by Exudyn: plant changes, loads and sensor effects in
    the order given.

    Parameters
    ----------
    case : DiagnosisCase
        Validated diagnosis case (a towing case: at most one effect).
    times : (k,) float
        Sample times (s) from the record's t = 0, increasing.
    step : float, optional
        Exudyn step (s); default the scenario's.

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    if case.kind == "towing":
        return _simulate_towing_case(case, times, CATALOG)
    plant = Plant.from_case(case)
    applied = []
    for entry in case.effects:
        effect = CATALOG[entry.id]
        names = list(entry.parameters)
        values = np.array([entry.parameters[n] for n in names], float)
        plant = effect.modify_plant(plant, values)
        applied.append((effect, values, names))
    sample_times = np.asarray(times, float)
    for effect, values, _ in applied:
        sample_times = effect.sample_times(sample_times, values)
    scenario = ExudynScenario(plant, step)
    for effect, values, names in applied:
        effect.add_to_exudyn(scenario, values, names)
    out = scenario.simulate(sample_times)
    for effect, values, names in applied:
        out = effect.measure(out, values, names)
    return out


def _simulate_towing_case(case, times, catalog) -> dict:
    """:func:`simulate_case` of a towing case: its one effect (an extended case has one) in Exudyn."""
    if len(case.effects) > 1:
        raise NotImplementedError("the towing scenario's Exudyn model takes one effect at a time; the case lists "
                                  f"{[e.id for e in case.effects]}")
    if not case.effects:
        return simulate_towing_exudyn(plant_of(case), times)
    entry = case.effects[0]
    names = list(entry.parameters)
    return simulate_towing_exudyn(plant_of(case), times, catalog[entry.id], [entry.parameters[n] for n in names], names)
