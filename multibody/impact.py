"""Coupled net-impact simulation: net, contact, debris bodies and joints in one Exudyn system.

:func:`build_impact_system` turns an :class:`~multibody.assembly.ImpactAssembly` into an
Exudyn ``MainSystem``; :class:`ImpactSimulation` runs it with the explicit solver
(sparse mass matrix factorized once, Lie-group integration of the rigid bodies) and
records the time series through :mod:`multibody.recorder`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import exudyn as exu
import numpy as np
from exudyn.itemInterface import NodeGenericODE2, NodeRigidBodyRotVecLG, ObjectGenericODE2, ObjectRigidBody
from scipy.spatial.transform import Rotation

from multibody.assembly import ImpactAssembly
from multibody.broad_phase import box_shape_flags
from multibody.closing_winch import ClosingWinch
from multibody.geometry import contact_shapes_body_frame
from multibody.health import HealthWatch, SimulationFailed, check_solver_flag
from multibody.hinge import add_penalty_joint
from multibody.jit_cache import all_compiled_on_disk
from multibody.kernel import (
    BodyArrays,
    ContactLaw,
    KernelData,
    Mounts,
    NetArrays,
    ShapeArrays,
    coupled_generalized_forces,
    no_mounts,
    verlet_evaluation_state,
)
from multibody.kernel_net import KernelNet, kernel_net_start, kernel_net_step
from multibody.recorded_loads import add_recorded_loads
from multibody.net import thread_runs
from multibody.node_frame import inertia_node, node_to_body_rotations, vector_node
from multibody.recorder import Recorder
from multibody.recorder_kernel import sample_row
from multibody.tether_spool import TetherSpool
from multibody.rotation_update import ExactRotations
from multibody.solver_output import solver_chatter_captured

#: Exudyn explicit integrators a case may choose, with their force evaluations per step.
INTEGRATORS = {
    "VelocityVerlet": (exu.DynamicSolverType.VelocityVerlet, 1),
    "RK44": (exu.DynamicSolverType.RK44, 4),
    "ExplicitMidpoint": (exu.DynamicSolverType.ExplicitMidpoint, 2),
}


@dataclass
class BuiltSystem:
    """Handles into the assembled Exudyn system."""

    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    kernel: KernelData
    net_node: int | None
    body_nodes: list
    body_objects: list
    joint_objects: list
    joint_to_parent: list      # (3, 3) joint frame in parent body frame, per joint
    joint_to_child: list       # (3, 3) joint frame in child body frame (unrotated), per joint
    joint_point_parent_body: list   # (3,) joint point, parent body frame (m)
    joint_point_child_body: list    # (3,) joint point, child body frame (m)
    kernel_net: KernelNet | None = None  # the net's state when the kernel integrates it
    rotations: ExactRotations | None = None  # VelocityVerlet: the attitudes restored after each step
    closing: ClosingWinch | None = None  # the net's closing winch (assembly.closing), kernel path only
    tether: TetherSpool | None = None    # the main tether's spool (assembly.tether), kernel path only

    def net_state(self, q, qt):
        """(n, 3) node positions (m) and velocities (m/s), LVLH, at the end of the last step, from
        the kernel (``kernel_net``) or from Exudyn's system vectors ``q``, ``qt`` (net node).

        Parameters
        ----------
        q : (N,) float
            Exudyn's ODE2 coordinates: displacements from the reference configuration (m, LVLH;
            rotation vectors (rad) for the bodies).
        qt : (N,) float
            Their time derivatives (m/s, LVLH; rad/s, body frame for the bodies).

        Returns
        -------
        positions_lvlh, velocities_lvlh : (n, 3) float
            Net node positions (m) and velocities (m/s), LVLH.
        """
        if self.kernel_net is not None:
            return self.kernel_net.positions(), self.kernel_net.velocities()
        n = self.kernel.n_nodes
        i = self.mbs.GetNodeODE2Index(self.net_node) if self.net_node is not None else 0
        return (self.kernel.net.reference_lvlh + np.asarray(q[i:i + 3 * n]).reshape(n, 3),
                np.asarray(qt[i:i + 3 * n]).reshape(n, 3))

    def net_state_layout(self, q, qt):
        """The net's state where it lives, without copies: coordinates and velocities (flat, m and m/s, LVLH,
        displacements from ``self.kernel.net.reference_lvlh``) and where node ``i``'s coordinate ``d`` sits in them,
        ``offset + i * node_stride + d * coordinate_stride`` (the kernel's coordinate-major state, or the net
        node's block of Exudyn's vectors ``q``, ``qt``).

        Parameters
        ----------
        q, qt : (N,) float
            Exudyn's ODE2 coordinates and velocities (unused when the kernel holds the net).

        Returns
        -------
        q_net, qt_net : (M,) float
        offset, node_stride, coordinate_stride : int
        """
        n = self.kernel.n_nodes
        if self.kernel_net is not None:
            return self.kernel_net.q, self.kernel_net.qt, 0, 1, n
        i = self.mbs.GetNodeODE2Index(self.net_node) if self.net_node is not None else 0
        return np.asarray(q), np.asarray(qt), i, 3, 1

    def state_arrays(self) -> tuple:
        """Every state array of the run, for the finite-state check: Exudyn's coordinates and
        velocities, and the net's when the kernel holds it (Exudyn does not see it then)."""
        data = self.mbs.systemData
        arrays = (data.GetODE2Coordinates(), data.GetODE2Coordinates_t())
        if self.kernel_net is not None:
            arrays += (self.kernel_net.q, self.kernel_net.qt)
        return arrays


def kernel_data(assembly: ImpactAssembly) -> KernelData:
    """Arrays for the compiled force kernel.

    Parameters
    ----------
    assembly : ImpactAssembly
        The simulation's description (SI, LVLH).

    Returns
    -------
    KernelData
        Net, bodies (reference CoMs in LVLH, inverse inertias in body frames), contact shapes
        (body frames) and laws, as the kernel reads them.
    """
    net, law = assembly.net, assembly.contact
    shapes = contact_shapes_body_frame([b.meshes_body for b in assembly.bodies],
                                       np.zeros((len(assembly.bodies), 3)))
    # Only the bending springs that act: a triple of zero stiffness adds nothing (bending off, the default,
    # is all zeros), and scanning them was 1.5 % of the reference case's run (perf, cpu-clock samples).
    bending = np.asarray(net.bending_stiffness, float) != 0.0
    net_arrays = NetArrays(
        reference_lvlh=np.ascontiguousarray(net.positions, float), mass=np.asarray(net.masses, float),
        radius=np.asarray(net.radii, float), threads=net.threads, rest_lengths=net.rest_lengths,
        thread_stiffness=net.stiffness, thread_damping=net.damping,
        bending_triples=np.ascontiguousarray(np.asarray(net.bending_triples, np.int64).reshape(-1, 3)[bending]),
        bending_stiffness=np.ascontiguousarray(np.asarray(net.bending_stiffness, float)[bending]),
        thread_runs=thread_runs(net.threads, net.rest_lengths, net.stiffness, net.damping))
    bodies = BodyArrays(
        reference_com_lvlh=np.array([b.com_lvlh for b in assembly.bodies], float).reshape(-1, 3),
        mass=np.array([b.mass for b in assembly.bodies], float),
        inverse_inertia_body=np.array([np.linalg.inv(b.inertia_body) for b in assembly.bodies]).reshape(-1, 3, 3),
        node_to_body=node_to_body_rotations(assembly.bodies))
    shape_arrays = ShapeArrays(
        triangles_body=shapes.triangles_body, normals_body=shapes.normals_body, body=shapes.shape_body,
        triangle_range=shapes.triangle_range, box_min_body=shapes.box_min_body, box_max_body=shapes.box_max_body,
        is_box=box_shape_flags(shapes.triangles_body, shapes.triangle_range, shapes.box_min_body,
                               shapes.box_max_body))
    contact_law = ContactLaw(
        stiffness=float(law.stiffness), exponent=float(law.exponent), damping=float(law.damping),
        mu_static=float(law.mu_static), mu_kinetic=float(law.mu_kinetic), transition_speed=float(law.transition_speed),
        implicit_speed=float(assembly.solver.implicit_contact_speed))
    return KernelData(
        net=net_arrays, bodies=bodies, shapes=shape_arrays, law=contact_law,
        mean_motion=float(assembly.mean_motion), step=float(assembly.solver.step),
        # Sub-cycling assumes Verlet's kick-drift use of the force (see contact.py).
        contact_substep=(float(assembly.solver.contact_substep)
                         if assembly.solver.integrator == "VelocityVerlet" else np.inf),
        stage_weight=1.0 / INTEGRATORS[assembly.solver.integrator][1],
        mounts=_mounts(assembly.mount),
        thread_segments=bool(law.thread_segments),
    )


def _mounts(mount) -> Mounts:
    if mount is None:
        return no_mounts()
    return Mounts(node=np.asarray(mount.nodes, np.int64), body=np.full(len(mount.nodes), mount.body, np.int64),
                  point_body=np.ascontiguousarray(mount.points_body, float),
                  stiffness=float(mount.stiffness), damping=float(mount.damping))


def _inertia6(inertia):
    """Exudyn's inertia 6-vector [Jxx, Jyy, Jzz, Jyz, Jxz, Jxy] from a 3x3 tensor."""
    j = np.asarray(inertia, float)
    return [j[0, 0], j[1, 1], j[2, 2], j[1, 2], j[0, 2], j[0, 1]]


def add_rigid_bodies(mbs, bodies, node_to_body=None) -> tuple[list, list]:
    """Add each body as a rotation-vector node (Lie-group integration) and a rigid body;
    returns the node and object numbers.

    Parameters
    ----------
    mbs : exudyn.MainSystem
        System to add the bodies to.
    bodies : list of RigidBodySpec
        Mass, body-frame inertia, LVLH CoM, body->LVLH attitude, LVLH velocity and body-frame
        angular velocity of each body at t = 0.
    node_to_body : (nb, 3, 3) float, optional
        Each node's frame in its body frame (:mod:`multibody.node_frame`); the node's attitude,
        angular velocity and inertia are given in it. None: the node frame is the body frame.

    Returns
    -------
    nodes, objects : list of int
        Exudyn node and object numbers, one per body.
    """
    nodes, objects = [], []
    for k, body in enumerate(bodies):
        c = np.eye(3) if node_to_body is None else node_to_body[k]
        node = mbs.AddNode(NodeRigidBodyRotVecLG(
            referenceCoordinates=list(body.com_lvlh) + [0.0, 0.0, 0.0],
            initialCoordinates=[0.0, 0.0, 0.0] + list(Rotation.from_matrix(body.body_to_lvlh @ c).as_rotvec()),
            initialVelocities=list(body.velocity_lvlh) + list(vector_node(body.omega_body, c))))
        nodes.append(node)
        objects.append(mbs.AddObject(ObjectRigidBody(
            name=body.name, nodeNumber=node, physicsMass=body.mass,
            physicsInertia=_inertia6(inertia_node(body.inertia_body, c)))))
    return nodes, objects


def build_impact_system(assembly: ImpactAssembly, rest_body_to_lvlh=None, rest_com_lvlh=None) -> BuiltSystem:
    """Assemble the coupled system in Exudyn.

    Parameters
    ----------
    assembly : ImpactAssembly
        The simulation's description (SI, LVLH).
    rest_body_to_lvlh : list of (3, 3) float, optional
        Per body, the attitude (body->LVLH) in which the joints are unloaded; default: the
        initial state. A case with an initial hinge angle passes the unrotated child state here.
    rest_com_lvlh : list of (3,) float, optional
        Per body, the CoM (m, LVLH) in which the joints are unloaded (given with
        ``rest_body_to_lvlh``).
    """
    if rest_body_to_lvlh is None:
        rest_body_to_lvlh = [b.body_to_lvlh for b in assembly.bodies]
        rest_com_lvlh = [b.com_lvlh for b in assembly.bodies]
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    net = assembly.net
    verlet = assembly.solver.integrator == "VelocityVerlet"
    in_kernel = uses_kernel_net(assembly)
    n = net.n_nodes
    n_exudyn = 0 if in_kernel else n  # net nodes Exudyn integrates
    generic_nodes = []
    net_node = None
    if n_exudyn:
        net_node = mbs.AddNode(NodeGenericODE2(
            referenceCoordinates=net.positions.ravel().tolist(),
            initialCoordinates=[0.0] * (3 * n),
            initialCoordinates_t=np.asarray(assembly.net_velocity, float).ravel().tolist(),
            numberOfODE2Coordinates=3 * n))
        generic_nodes.append(net_node)

    kernel = kernel_data(assembly)
    # every node's frame turned from its body's, away from Exudyn's imprecise identity (multibody.node_frame)
    node_to_body = kernel.bodies.node_to_body
    body_nodes, body_objects = add_rigid_bodies(mbs, assembly.bodies, node_to_body)
    generic_nodes += body_nodes

    size = 3 * n_exudyn + 6 * len(assembly.bodies)
    mass = exu.MatrixContainer()
    diagonal = np.arange(3 * n_exudyn)
    triplets = np.c_[diagonal, diagonal, np.repeat(net.masses, 3)] if n_exudyn else np.zeros((0, 3))
    mass.SetWithSparseMatrixCSR(size, size, triplets.tolist(), useDenseMatrix=False)

    if verlet:
        # Forces enter as the object's force vector, set once per step by a pre-step
        # function (VerletForces): no Python lists cross the C++ boundary.
        coupled = mbs.AddObject(ObjectGenericODE2(nodeNumbers=generic_nodes, massMatrix=mass,
                                                  forceVector=[0.0] * size))
    else:
        # Runge-Kutta stages need the force at every stage state: a force user function,
        # which receives the state as Python lists (about 0.3 ms a call for the reference net);
        # it reads Exudyn's system vectors instead once the layout is known (after Assemble).
        layout = {}

        def coupled_forces(mbs_, t, item, q, q_t):
            data = mbs_.systemData
            x, v = _object_state(layout["index"], data.GetODE2Coordinates(), data.GetODE2Coordinates_t())
            return kernel.evaluate(x, v, t)

        coupled = mbs.AddObject(ObjectGenericODE2(nodeNumbers=generic_nodes, massMatrix=mass,
                                                  forceUserFunction=coupled_forces))

    joint_objects, joints_to_parent, joints_to_child, points_parent_body, points_child_body = [], [], [], [], []
    for joint in assembly.joints:
        joint_objects.append(add_penalty_joint(mbs, joint, assembly.bodies, body_objects,
                                               rest_body_to_lvlh[joint.child], rest_com_lvlh[joint.child],
                                               assembly.solver.joint_tuning_step or assembly.solver.step,
                                               node_to_body))
        parent = assembly.bodies[joint.parent]
        joints_to_parent.append(parent.body_to_lvlh.T @ joint.hinge_to_lvlh)
        joints_to_child.append(rest_body_to_lvlh[joint.child].T @ joint.hinge_to_lvlh)
        points_parent_body.append(parent.body_to_lvlh.T @ (joint.point_lvlh - parent.com_lvlh))
        points_child_body.append(rest_body_to_lvlh[joint.child].T @ (joint.point_lvlh - rest_com_lvlh[joint.child]))
    if assembly.body_loads is not None:
        add_recorded_loads(mbs, body_objects, assembly.body_loads, assembly.solver.step, node_to_body)
    mbs.Assemble()
    state_index = _object_state_index(mbs, generic_nodes, [3 * n_exudyn] * bool(n_exudyn) + [6] * len(body_nodes))
    kernel_net = None
    # Exudyn's explicit Lie-group update loses turns below ~2e-8 rad a step (multibody.rotation_update)
    rotations = ExactRotations(3 * n_exudyn, len(body_nodes), state_index) if verlet else None
    closing = spool = None
    for name, mechanism in (("closing mechanism", assembly.closing), ("main tether", assembly.tether)):
        if mechanism is not None and not in_kernel:
            raise ValueError(f"the net's {name} needs the compiled kernel to integrate the net "
                             "(simulation.net_integration = \"kernel\" with VelocityVerlet)")
    if in_kernel:
        tether = None if assembly.tether is None else assembly.tether.kernel_tether()
        kernel_net = KernelNet(mbs, coupled, kernel, assembly.net_velocity, state_index, rotations, tether)
        mbs.SetPreStepUserFunction(kernel_net)
        if assembly.closing is not None:
            closing = ClosingWinch(assembly.closing, kernel, kernel_net.q, assembly.solver.step)
        if tether is not None:
            spool = TetherSpool(assembly.tether, tether, kernel.buffers.scalars, kernel.net.reference_lvlh,
                                kernel_net.q, assembly.solver.step)
    elif verlet:
        mbs.SetPreStepUserFunction(VerletForces(mbs, coupled, kernel, assembly.solver.step, 3 * n,
                                                len(body_nodes), state_index, rotations))
    else:
        layout["index"] = state_index
    return BuiltSystem(sc, mbs, kernel, net_node, body_nodes, body_objects, joint_objects,
                       joints_to_parent, joints_to_child, points_parent_body, points_child_body, kernel_net,
                       rotations, closing, spool)


def uses_kernel_net(assembly: ImpactAssembly) -> bool:
    """True when the compiled kernel integrates the net (``solver.net_integration = "kernel"``,
    VelocityVerlet only: Runge-Kutta stages need Exudyn to hold every coordinate).

    Parameters
    ----------
    assembly : ImpactAssembly
        The simulation's description (SI, LVLH).
    """
    return (assembly.solver.net_integration == "kernel" and assembly.solver.integrator == "VelocityVerlet"
            and assembly.net.n_nodes > 0 and len(assembly.bodies) > 0)


def _object_state_index(mbs, nodes, sizes):
    """Where the generic object's coordinates sit in Exudyn's system vectors: an index array,
    or None when they are the whole system vector in order (the usual case)."""
    index = np.concatenate([np.arange(mbs.GetNodeODE2Index(nd), mbs.GetNodeODE2Index(nd) + k)
                            for nd, k in zip(nodes, sizes)]).astype(np.int64)
    if mbs.systemData.ODE2Size() == len(index) and np.array_equal(index, np.arange(len(index))):
        return None
    return index


def _object_state(index, *system_vectors):
    """The generic object's part of each system vector (see _object_state_index)."""
    if index is None:
        return system_vectors
    return tuple(vector[index] for vector in system_vectors)


class VerletForces:
    """Exudyn pre-step function that feeds the coupled forces to VelocityVerlet.

    Exudyn's VelocityVerlet step from (q, v, a) is: v += h/2 a; q += h v (Lie-group update
    for rotation vectors); a = M^-1 f(q, v); v += h/2 a. The state at which it evaluates f
    is therefore known before the step starts (:func:`multibody.kernel.verlet_evaluation_state`):
    this function computes f there and sets it as the generic object's force vector, which
    the solver then uses, unchanged, inside the step. Same forces as a force user function,
    without converting the state and the force to and from Python lists every step
    (0.3 ms of a 0.9 ms step for the reference net). Joint and rigid-body forces are still
    Exudyn's own, evaluated inside the step.
    """

    def __init__(self, mbs, coupled_object, kernel, step, n_net_coordinates, n_bodies, state_index, rotations=None):
        self.mbs = mbs
        self.rotations = rotations      # ExactRotations: keeps the step's exact end attitudes
        self.coupled_object = coupled_object
        self.kernel = kernel
        self.step = step
        self.n_net_coordinates = n_net_coordinates
        self.n_bodies = n_bodies
        self.state_index = state_index  # see _object_state_index
        # The solver's initial acceleration uses the force at the initial state.
        q, v = _object_state(state_index, mbs.systemData.GetODE2Coordinates(), mbs.systemData.GetODE2Coordinates_t())
        self._set_force(kernel.evaluate(q, v, 0.0))

    def _set_force(self, force):
        self.mbs.SetObjectParameter(self.coupled_object, "forceVector", force)

    def __call__(self, mbs, t):
        data = mbs.systemData
        q, v, a = _object_state(self.state_index, data.GetODE2Coordinates(), data.GetODE2Coordinates_t(),
                                data.GetODE2Coordinates_tt())
        q_next, v_half = verlet_evaluation_state(q, v, a, self.step, self.n_net_coordinates, self.n_bodies)
        if self.rotations is not None:
            self.rotations.keep(q_next)
        # Exudyn calls the pre-step function with the step's end time already set: t is the time
        # of the evaluation state (checked in tests/multibody/test_towing.py).
        self._set_force(self.kernel.evaluate(q_next, v_half, t))
        return True


def explicit_settings(step: float, n_steps: int) -> exu.SimulationSettings:
    """Explicit fixed-step settings with Lie-group rotation updates, no files written.

    Parameters
    ----------
    step : float
        Fixed time step (s).
    n_steps : int
        Number of steps; the end time is ``n_steps * step``.
    """
    s = exu.SimulationSettings()
    s.timeIntegration.endTime = n_steps * step
    s.timeIntegration.numberOfSteps = n_steps
    s.timeIntegration.verboseMode = 0
    s.timeIntegration.explicit.computeEndOfStepAccelerations = False
    s.timeIntegration.explicit.useLieGroupIntegration = True
    s.solution.file.write = False
    s.solution.sensors.active = False
    # Python user functions must stay on one thread (EXUDYN-NOTES: two threads can hang).
    s.parallel.numberOfThreads = 1
    return s


def simulation_settings(assembly: ImpactAssembly) -> exu.SimulationSettings:
    """The impact's settings: explicit, sparse mass matrix factorized once.

    Parameters
    ----------
    assembly : ImpactAssembly
        The simulation's description (SI, LVLH).
    """
    s = explicit_settings(assembly.solver.step, assembly.solver.n_steps)
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    return s


#: The compiled functions an impact run calls from Python, per path (the others compile inside them; the
#: recorder's sample, :func:`multibody.recorder_kernel.sample_row`, on both): the
#: kernel integrating the net (the default, :func:`uses_kernel_net`), and Exudyn integrating every net node (the
#: reference path, and every Runge-Kutta integrator). A run of one path compiles only its own: asking for both
#: after a default run read "not compiled" and announced the compilation before every run.
KERNEL_NET_KERNELS = (kernel_net_start, kernel_net_step, sample_row)
EXUDYN_NET_KERNELS = (coupled_generalized_forces, verlet_evaluation_state, sample_row)


def kernels_compiled(kernel_net: bool = True) -> bool:
    """The impact kernels of one path are in numba's disk cache: a run starts at once (else it first
    compiles them, about 30 s on one core; :mod:`multibody.jit_cache`).

    Parameters
    ----------
    kernel_net : bool
        The path of the run: the compiled kernel integrates the net (True, :data:`KERNEL_NET_KERNELS`) or
        Exudyn integrates every net node (False, :data:`EXUDYN_NET_KERNELS`).
    """
    return all_compiled_on_disk(KERNEL_NET_KERNELS if kernel_net else EXUDYN_NET_KERNELS)


def net_stable_step(net) -> float:
    """Explicit (Verlet) stability limit of the net's threads (s).

    The highest mode of a flat lumped-mass net is about :math:`\\omega = 2\\sqrt{k/m}` (a chain's
    zig-zag mode, docs/model.md "Step size"); Verlet is stable for :math:`h < 2/\\omega = \\sqrt{m/k}`,
    taken here with the stiffest thread on the lightest node. Contact and joints need smaller
    steps still: contact is sub-cycled and the joints are tuned to the step.

    Parameters
    ----------
    net : NetTopology
        The net (node masses (kg), thread stiffnesses (N/m)).
    """
    if not len(net.stiffness):
        return np.inf
    return float(np.sqrt(np.min(net.masses) / np.max(net.stiffness)))


def likely_failure_cause(assembly: ImpactAssembly) -> str:
    """Words for a failed impact run: the step against the threads' stable step, or the inputs.

    Parameters
    ----------
    assembly : ImpactAssembly
        The simulation's description (SI, LVLH).
    """
    step, limit = assembly.solver.step, net_stable_step(assembly.net)
    if step > 0.5 * limit:
        return (f"the step {step:g} s is too large for the net threads (explicit stability limit "
                f"sqrt(m/k) = {limit:.3g} s for the stiffest thread on the lightest node); "
                f"use simulation.step <= {0.5 * limit:.2g} s")
    return (f"the step {step:g} s is within the threads' stable step {limit:.3g} s, so look at the contact "
            f"stiffness, a joint's stiffness or damping, or an extreme input value")


def initial_kinetic_energy(assembly: ImpactAssembly) -> float:
    """Kinetic energy (J) of net and bodies at t = 0: the reference of the energy-balance check.

    Parameters
    ----------
    assembly : ImpactAssembly
        The simulation's description (SI, LVLH).
    """
    v_lvlh = np.asarray(assembly.net_velocity, float).reshape(-1, 3)
    energy = 0.5 * float(np.sum(assembly.net.masses * np.sum(v_lvlh * v_lvlh, axis=1))) if len(v_lvlh) else 0.0
    for b in assembly.bodies:
        omega_body = np.asarray(b.omega_body, float)
        energy += (0.5 * b.mass * float(np.dot(b.velocity_lvlh, b.velocity_lvlh))
                   + 0.5 * omega_body @ b.inertia_body @ omega_body)
    if assembly.body_loads is not None:     # driven by recorded loads: the recording run's reference
        energy = max(energy, assembly.body_loads.reference_energy)
    return energy


#: Floor of the energy reference (J): a run with (almost) nothing moving still gets a finite bound.
MIN_REFERENCE_ENERGY_J = 1.0


def checked_post_step(watch: HealthWatch, post_step=None, every: int = 1):
    """A post-step function that calls ``post_step`` (if any) and checks the state is finite every
    ``every`` steps; it stops the solver (returns False) at the first failure, kept in ``watch``.

    Parameters
    ----------
    watch : HealthWatch
        Keeps the first failure.
    post_step : callable ``(mbs, t) -> bool``, optional
        Exudyn post-step function to run first (t in s).
    every : int
        Check every ``every``-th step.

    Returns
    -------
    callable ``(mbs, t) -> bool``
        The post-step function for ``mbs.SetPostStepUserFunction``.
    """
    count = [0]

    def hook(mbs, t):
        keep = post_step(mbs, t) if post_step is not None else True
        count[0] += 1
        if count[0] % every == 0:
            data = mbs.systemData
            watch.state(t, data.GetODE2Coordinates(), data.GetODE2Coordinates_t())
        return bool(keep) and watch.ok

    return hook


def solve_checked(mbs, settings, solver_type, watch: HealthWatch, stopped_early=None) -> None:
    """``exudyn.SolveDynamic`` with the health checks: raise :class:`SimulationFailed` when a hook
    stopped the run (``watch.failure``), when the solver reports failure, or when it raised.

    Parameters
    ----------
    mbs : exudyn.MainSystem
        The assembled system.
    settings : exudyn.SimulationSettings
        Its settings (:func:`explicit_settings`).
    solver_type : exudyn.DynamicSolverType
        The explicit integrator.
    watch : HealthWatch
        The run's health record (the hooks' failures, the likely cause).
    stopped_early : callable ``() -> bool``, optional
        True when a hook stopped the run on purpose before the end time (the capture was over,
        :mod:`structures.capture_window`): then reaching less than the end time is not a failure.
    """
    end_time = settings.timeIntegration.endTime
    try:
        with solver_chatter_captured():
            success = exu.SolveDynamic(mbs, settings, solverType=solver_type)
    except Exception as exc:  # Exudyn's C++ errors (ModelError, RuntimeError) after a failed step
        if watch.failure is not None:
            raise watch.failure from exc
        raise SimulationFailed(mbs.systemData.GetTime(), f"the integrator raised {type(exc).__name__}: "
                               f"{str(exc).strip().splitlines()[0] if str(exc).strip() else ''}", watch.cause) from exc
    if watch.failure is not None:
        raise watch.failure
    if stopped_early is not None and stopped_early():
        return
    reached = mbs.systemData.GetTime()
    half_step = 0.5 * end_time / max(settings.timeIntegration.numberOfSteps, 1)
    # a solver that reports success but stopped short failed all the same
    check_solver_flag(bool(success) and reached >= end_time - half_step, end_time, reached, watch.cause)


def with_winch(post_step, *winches):
    """``post_step`` between the winches' booking of their last update (:meth:`ClosingWinch.book_pending`,
    :meth:`TetherSpool.book_pending`) and their next update (``after_step``), or ``post_step`` itself without a
    winch (the default path calls exactly what it called before).

    Parameters
    ----------
    post_step : callable ``(mbs, t) -> bool``
        The recorder's post-step work (its sample at ``t`` reads the loop and the tether as they were over the step).
    *winches : ClosingWinch, TetherSpool or None
        The closing winch and the tether's spool; None entries are left out.
    """
    winches = [w for w in winches if w is not None]
    if not winches:
        return post_step

    def hook(mbs, t):
        for winch in winches:
            winch.book_pending()    # the last update's work completed at this step's end, before the sample reads it
        keep = post_step(mbs, t)
        for winch in winches:
            winch.after_step(t)
        return keep

    return hook


def detach_step_functions(mbs) -> None:
    """Clear the system's pre- and post-step functions once a run is over.

    They are Python objects that hold the system (the kernel's hook, the recorder through the built system), and
    Exudyn holds them from C++: a reference cycle Python's collector cannot see, so every finished simulation stayed
    in memory with its recorded histories (about 1.8 GB a 420 s envisat_small run; a sweep worker paused by Dask's
    memory limit after five such runs and the sweep stalled, 2026-11-28). Cleared, a dropped simulation is freed.
    Every runner whose step function holds the system (directly or through what it records) calls it when its run
    ends: the impact, the approach's replay (:mod:`multibody.mu_replay`) and the diagnosis's Exudyn model.
    """
    mbs.SetPreStepUserFunction(0)
    mbs.SetPostStepUserFunction(0)


class ImpactSimulation:
    """Build and run one coupled impact; ``run()`` returns the recorder with all time series."""

    def __init__(self, assembly: ImpactAssembly, rest_body_to_lvlh=None, rest_com_lvlh=None):
        self.assembly = assembly
        self.system = build_impact_system(assembly, rest_body_to_lvlh, rest_com_lvlh)
        self.wall_time = None
        self.health = HealthWatch(likely_failure_cause(assembly),
                                  max(initial_kinetic_energy(assembly), MIN_REFERENCE_ENERGY_J))

    def run(self, progress=None, monitor=None, capture=None) -> Recorder:
        """Integrate to the end time.

        Raises :class:`~multibody.health.SimulationFailed` at the first failed health check
        (non-finite state, energy balance drift, integrator failure); the recorder then holds
        the samples up to it (``self.recorder``).

        Parameters
        ----------
        progress : callable ``(t) -> None``, optional
            Called at every output sample with the time (s).
        monitor : object with ``check(...)``, optional
            Called after ``progress`` (see :class:`~multibody.recorder.Recorder`).
        capture : structures.capture_window.CaptureMonitor, optional
            The capture's settle test; the run stops (before the end time) once the capture is over
            (``recorder.stopped_early``).

        Returns
        -------
        Recorder
            All time series of the run.
        """
        recorder = Recorder(self.assembly, self.system, progress=progress, monitor=monitor, health=self.health,
                            capture=capture)
        self.recorder = recorder
        mbs = self.system.mbs
        post_step = recorder.post_step
        kernel_net = self.system.kernel_net
        if kernel_net is not None:
            # the post-step work runs from the kernel's pre-step, for the step before (one Python
            # call from Exudyn a step instead of two; the same work in the same order), after the kernel
            # has restored the step's exact attitudes (multibody.rotation_update)
            kernel_net.set_after_step(with_winch(post_step, self.system.closing, self.system.tether), mbs.systemData.GetTime())
        else:
            if self.system.rotations is not None:
                # Exudyn's attitudes made exact before anything reads them (multibody.rotation_update)
                post_step = self.system.rotations.restoring(post_step)
            mbs.SetPostStepUserFunction(post_step)
        settings = simulation_settings(self.assembly)
        recorder.sample(0.0)
        start = time.perf_counter()
        try:
            if not self.health.ok:
                raise self.health.failure
            solve_checked(mbs, settings, INTEGRATORS[self.assembly.solver.integrator][0], self.health,
                          stopped_early=lambda: recorder.stopped_early)
            # a run stopped early has done its last step's work already (the hook that stopped it)
            if kernel_net is not None and not recorder.stopped_early and not kernel_net.finish_steps(mbs):
                raise self.health.failure
            if not self.health.finish():
                raise self.health.failure
        finally:
            self.wall_time = time.perf_counter() - start
            recorder.finish(self.wall_time)
            detach_step_functions(mbs)
        return recorder
