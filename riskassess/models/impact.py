"""Turn a validated :class:`~riskassess.cases.impact.Case` into the multibody model's inputs.

Frames: shapes, centres of mass, inertia and joints come in the target frame; each body
frame has its origin at the body CoM and axes parallel to the target frame, so a body's
attitude at t = 0 is the target attitude (times the initial hinge rotation for a child).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.assembly import (ContactLaw, ImpactAssembly, JointSpec, NetMount, RigidBodySpec, SolverSpec,
                                subtree_bodies)
from multibody.closing import N_CLOSING, append_closing_loop
from multibody.closing_winch import ClosingSpec
from multibody.net_tether import anchor_point, central_node
from multibody.tether_spool import TetherSpec
from multibody.geometry import geometric_center_of_mass, uniform_density_inertia
from multibody.hinge import hinge_frame_lvlh, structural_modes_hz
from multibody.net import bowl_net_positions, flat_square_net, thread_node_mass
from multibody.orbit import mean_motion
from riskassess.cases.impact import Case, CircularOrbit, section_properties
from riskassess.cases.target_geometry import body_meshes_target_frame, target_points_lvlh, target_pose_lvlh
from structures.criteria import Allowable
from structures.member import member_stiffness_joint_frame
from structures.modal_load import mode_grid
from structures.weak_location import WeakLocation


@dataclass
class ModelInputs:
    """An assembly plus the joint rest states (child attitude and CoM before initial hinge angles)."""

    assembly: ImpactAssembly
    rest_attitudes: list
    rest_coms: list


def mass_properties_target_frame(case: Case, meshes):
    """Per body: (CoM (m), inertia about CoM (kg m^2)), target frame; defaults from geometry.

    Parameters
    ----------
    case : Case
        A net-impact case; a body without ``center_of_mass`` or ``inertia`` gets the uniform-density
        value of its shapes.
    meshes : list of list of trimesh.Trimesh
        Per body, its shapes in the target frame (m) (:func:`body_meshes_target_frame`).

    Returns
    -------
    list of ((3,) float, (3, 3) float)
        Per body, its CoM (m) and inertia about the CoM (kg m^2), target frame.
    """
    props = []
    for body, body_meshes in zip(case.target.bodies, meshes):
        com = (np.asarray(body.center_of_mass, float) if body.center_of_mass is not None
               else geometric_center_of_mass(body_meshes))
        inertia = (np.asarray(body.inertia, float) if body.inertia is not None
                   else uniform_density_inertia(body_meshes, body.mass, com))
        props.append((com, inertia))
    return props


def thread_area(thread) -> float:
    """Cross-section of a thread (m^2), a solid circle of the thread's diameter.

    Parameters
    ----------
    thread : riskassess.cases.impact.Thread
        The case's thread.
    """
    return np.pi * thread.diameter**2 / 4.0


def solid_bending_rigidity(modulus: float, diameter: float) -> float:
    """EI = E pi d^4 / 64 (N m^2) of a solid circular thread.

    Parameters
    ----------
    modulus : float
        Young's modulus E (Pa).
    diameter : float
        Thread diameter d (m).
    """
    return modulus * np.pi * diameter**4 / 64.0


def thread_bending_rigidity(thread) -> float:
    """The thread's bending rigidity EI (N m^2) as the net is built: 0 when ``bending`` is off, else
    ``bending_rigidity`` or the solid thread's from its modulus.

    Parameters
    ----------
    thread : riskassess.cases.impact.Thread
        The case's thread.
    """
    if not thread.bending:
        return 0.0
    if thread.bending_rigidity is not None:
        return thread.bending_rigidity
    return solid_bending_rigidity(thread.modulus, thread.diameter)


def build_net(case: Case):
    """Net topology (LVLH) and initial node velocities for the case's launch.

    Parameters
    ----------
    case : Case
        A net-impact case (net, thread, bullets, launch, target pose).

    Returns
    -------
    topology : multibody.net.NetTopology
        Square net centred ``launch.distance`` before the aim point, normal to the launch
        direction, node positions in LVLH (m): flat, or a bowl ``launch.sag`` deep
        (:func:`multibody.net.bowl_net_positions`).
    velocity : (n, 3) float
        Initial node velocities, all ``launch.velocity`` along the launch direction (m/s, LVLH).
    """
    net, launch, bullets = case.net, case.launch, case.bullets
    thread = net.thread
    mesh = net.mesh_size
    area = thread_area(thread)
    axial_rigidity = thread.stiffness * mesh if thread.stiffness is not None else thread.modulus * area
    bending_rigidity = thread_bending_rigidity(thread)
    node_mass = (net.node_mass if net.node_mass is not None
                 else thread_node_mass(net.side_length, net.nodes_per_side, thread.diameter, thread.density))
    direction = np.asarray(launch.direction, float) / np.linalg.norm(launch.direction)
    aim = target_points_lvlh(case, launch.aim_point)
    topology = flat_square_net(
        center=aim - launch.distance * direction, direction=direction,
        side_length=net.side_length, nodes_per_side=net.nodes_per_side,
        node_mass=node_mass, node_radius=thread.diameter / 2.0,
        thread_axial_rigidity=axial_rigidity, thread_damping=thread.damping,
        bullet_mass=bullets.mass, bullet_radius=bullets.radius,
        bullet_tether_length=bullets.tether_length or mesh, bending_rigidity=bending_rigidity)
    if launch.sag > 0.0:
        try:
            topology = replace(topology, positions=bowl_net_positions(topology, direction, launch.sag))
        except ValueError as exc:
            raise ValueError(f"launch.sag = {launch.sag:g} m: {exc}") from None
    velocity = np.tile(launch.velocity * direction, (topology.n_nodes, 1))
    if net.closing is not None:
        topology, _ = append_closing_loop(topology, net.closing.axial_rigidity,
                                          thread.damping if net.closing.damping is None else net.closing.damping)
    return topology, velocity


def closing_spec(case: Case, net) -> ClosingSpec | None:
    """The case's closing mechanism for the impact model, or None for an open net.

    Parameters
    ----------
    case : Case
        A net-impact case (``net.closing``, the launch speed for a delay given as travel).
    net : multibody.net.NetTopology
        The built net (:func:`build_net`), the loop its last 12 threads, open.

    Returns
    -------
    ClosingSpec or None
        Open natural lengths = the loop's threads' lengths in the launch shape (m); closed = ``closed_fraction`` of them.
    """
    closing = case.net.closing
    if closing is None:
        return None
    rest_open = np.asarray(net.rest_lengths[-N_CLOSING:], float).copy()
    start, delay = trigger_delay(closing, case.launch.velocity)
    return ClosingSpec(start=start, delay=delay,
                       duration=float(closing.duration_s), rest_open=rest_open,
                       rest_closed=closing.closed_fraction * rest_open, axial_rigidity=float(closing.axial_rigidity))


def trigger_delay(trigger, launch_velocity: float) -> tuple[float | None, float]:
    """A net mechanism's trigger (:class:`riskassess.cases.impact.Trigger`) as (start (s) or None for the first
    contact, delay (s)); a delay given as travel (m) is divided by ``launch_velocity`` (m/s)."""
    if trigger.delay_travel_m is not None:
        delay = trigger.delay_travel_m / launch_velocity
    else:
        delay = trigger.delay_s or 0.0
    return (None if trigger.start == "first_contact" else float(trigger.start)), float(delay)


def tether_spec(case: Case, net) -> TetherSpec | None:
    """The case's main tether for the impact model, or None without one.

    Parameters
    ----------
    case : Case
        A net-impact case (``net.tether``; the launch's direction and speed).
    net : multibody.net.NetTopology
        The built net (:func:`build_net`), positions at launch (m, LVLH).

    Returns
    -------
    TetherSpec or None
        From the net's central node (:func:`multibody.net_tether.central_node`) to the anchor: ``anchor_lvlh``, or
        ``standoff_m`` back along the launch direction from the centre of the net's grid at launch.
    """
    tether = case.net.tether
    if tether is None:
        return None
    n = case.net.nodes_per_side
    if tether.anchor_lvlh is not None:
        anchor_lvlh = np.asarray(tether.anchor_lvlh, float)
    else:
        anchor_lvlh = anchor_point(net.positions[: n * n].mean(axis=0), case.launch.direction, tether.standoff_m)
    start, delay = trigger_delay(tether, case.launch.velocity)
    return TetherSpec(node=central_node(n), anchor_lvlh=anchor_lvlh, stiffness=tether.stiffness,
                      axial_rigidity=tether.axial_rigidity, damping=float(tether.damping), start=start, delay=delay,
                      slack=float(tether.slack_m), reel_rate=float(tether.reel_rate_m_s), reel_in=float(tether.reel_in_m))


def build_bodies_and_joints(case: Case, base: Path):
    """Rigid-body and joint specs in LVLH at t = 0, and the joints' rest states.

    Parameters
    ----------
    case : Case
        A net-impact case (target bodies, joints, pose and rates).
    base : Path
        Folder of the case file; mesh files are relative to it.

    Returns
    -------
    bodies : list of RigidBodySpec
        CoM (m), velocity (m/s) and attitude in LVLH, angular velocity (rad/s) and inertia
        (kg m^2) in the body frame, shapes in the body frame (m); initial hinge angles and rates applied.
    joints : list of JointSpec
        Joint points (m) and hinge frames in LVLH.
    rest_attitudes : list of (3, 3) float
        Body -> LVLH rotation of each body before the initial hinge angles.
    rest_coms : list of (3,) float
        CoM of each body before the initial hinge angles, LVLH (m).
    """
    target = case.target
    meshes = body_meshes_target_frame(case, base)
    props = mass_properties_target_frame(case, meshes)
    origin, target_to_lvlh = target_pose_lvlh(case)
    omega_lvlh = target_to_lvlh @ np.asarray(target.angular_velocity, float)
    names = [b.name for b in target.bodies]

    bodies = []
    for body, body_meshes, (com_t, inertia) in zip(target.bodies, meshes, props):
        com = origin + target_to_lvlh @ com_t
        shifted = [m.copy().apply_translation(-com_t) for m in body_meshes]
        bodies.append(RigidBodySpec(
            name=body.name, mass=body.mass, inertia_body=inertia, com_lvlh=com,
            body_to_lvlh=target_to_lvlh.copy(),
            velocity_lvlh=np.asarray(target.velocity_lvlh, float) + np.cross(omega_lvlh, com - origin),
            omega_body=np.asarray(target.angular_velocity, float), meshes_body=shifted))
    rest_attitudes = [b.body_to_lvlh.copy() for b in bodies]
    rest_coms = [b.com_lvlh.copy() for b in bodies]

    joints = []
    for j in target.joints:
        parent, child = names.index(j.parent), names.index(j.child)
        point = origin + target_to_lvlh @ np.asarray(j.position, float)
        frame = hinge_frame_lvlh(target_to_lvlh @ np.asarray(j.axis, float), point, bodies[child].com_lvlh)
        joints.append(JointSpec(
            name=j.name, kind=j.kind, parent=parent, child=child, point_lvlh=point, hinge_to_lvlh=frame,
            torsional_stiffness=j.torsional_stiffness, torsional_damping=j.torsional_damping,
            penalty_translational=j.penalty_translational, penalty_rotational=j.penalty_rotational,
            penalty_damping_ratio=j.penalty_damping_ratio, first_mode_hz=j.first_mode_hz,
            rotation_modes_hz=None if j.rotation_modes is None else j.rotation_modes.frequencies_hz(),
            rotation_modes_damping_ratio=0.0 if j.rotation_modes is None else j.rotation_modes.damping_ratio,
            structural_stiffness=_member_springs(j, frame, target_to_lvlh),
            load_filter_hz=load_filter_hz(case, j),
            load_filter_order=case.structures.load_filter_order if case.structures is not None else 4))
        if j.initial_angle or j.initial_rate:
            _apply_initial_hinge_state(bodies, joints, len(joints) - 1, j.initial_angle, j.initial_rate)
    return bodies, joints, rest_attitudes, rest_coms


def load_filter_hz(case: Case, joint) -> float:
    """The cut-off (Hz) of joint ``joint``'s load filter (multibody.load_filter): its own ``load_filter_hz``, else
    the case's ``structures.load_filter_hz``, else 0 (none)."""
    if joint.load_filter_hz is not None:
        return float(joint.load_filter_hz)
    structures = case.structures
    return float(structures.load_filter_hz) if structures is not None and structures.load_filter_hz else 0.0


#: Fewest output samples per period of the fastest mode a member's springs make: the recorded reaction of a
#: ringing member is read at samples, and a sinusoid sampled n times per period shows at least cos(pi / n) of
#: its peak (95 % at 10).
MEMBER_SAMPLES_PER_PERIOD = 10


def _check_member_sampling(joints, bodies, step: float, output_rate: float) -> None:
    """Refuse a member whose modes the output rate does not resolve (its peaks would be read low)."""
    for joint in joints:
        if joint.structural_stiffness is None:
            continue
        fastest = structural_modes_hz(joint, bodies[joint.parent], bodies[joint.child], step).max()
        if output_rate < MEMBER_SAMPLES_PER_PERIOD * fastest:
            raise ValueError(f"target.joints '{joint.name}'.member: its springs ring at up to {fastest:.3g} Hz; "
                             f"simulation.output_rate must be at least {MEMBER_SAMPLES_PER_PERIOD * fastest:.3g} Hz "
                             f"({MEMBER_SAMPLES_PER_PERIOD} samples per period, peaks read within 5 %); got "
                             f"{output_rate:g} Hz")


def _member_springs(joint, hinge_to_lvlh, target_to_lvlh):
    """The joint's six springs from its member's compliance (structures.member), or None."""
    if joint.member is None:
        return None
    m = joint.member
    beam_axis_joint = hinge_to_lvlh.T @ (target_to_lvlh @ np.asarray(m.beam_axis, float))
    try:
        return member_stiffness_joint_frame(section_properties(m.section), m.length, m.modulus, m.shear_modulus,
                                            beam_axis_joint)
    except ValueError as exc:
        raise ValueError(f"target.joints '{joint.name}'.member: {exc}") from None


def _apply_initial_hinge_state(bodies, joints, index, angle, rate):
    """Rotate the child subtree about the hinge axis by ``angle`` and give it ``rate`` (LVLH)."""
    joint = joints[index]
    axis = joint.hinge_to_lvlh[:, 1]
    turn = Rotation.from_rotvec(angle * axis).as_matrix()
    for k in subtree_bodies(joints, joint.child):
        b = bodies[k]
        arm = turn @ (b.com_lvlh - joint.point_lvlh)
        b.com_lvlh = joint.point_lvlh + arm
        b.body_to_lvlh = turn @ b.body_to_lvlh
        b.velocity_lvlh = turn @ b.velocity_lvlh + rate * np.cross(axis, arm)
        b.omega_body = b.omega_body + rate * (b.body_to_lvlh.T @ axis)


def rim_nodes(nodes_per_side: int) -> np.ndarray:
    """Indices of the square grid's perimeter nodes (row-major grid, see multibody.net).

    Parameters
    ----------
    nodes_per_side : int
        Nodes along one side of the square net.

    Returns
    -------
    (4 nodes_per_side - 4,) int
        Node indices, ascending.
    """
    i, j = np.divmod(np.arange(nodes_per_side**2), nodes_per_side)
    return np.flatnonzero((i == 0) | (j == 0) | (i == nodes_per_side - 1) | (j == nodes_per_side - 1))


def build_chaser(case: Case, net, index: int) -> tuple[RigidBodySpec, NetMount]:
    """The chaser body behind the net plane, moving with the net, and the rods holding the rim
    on it; ``index`` is the chaser's place in the assembly's body list.

    Parameters
    ----------
    case : Case
        A net-impact case with a ``[chaser]`` table.
    net : multibody.net.NetTopology
        The launched net (:func:`build_net`), node positions in LVLH (m).
    index : int
        The chaser's index in the assembly's body list.

    Returns
    -------
    body : RigidBodySpec
        The chaser, ``chaser.standoff`` (m) behind the net centre, moving at the launch velocity
        (m/s, LVLH), body axes parallel to LVLH.
    mount : NetMount
        Rim nodes held by spring-dampers at their initial offsets from the chaser CoM (m, body frame).
    """
    chaser, launch = case.chaser, case.launch
    direction = np.asarray(launch.direction, float) / np.linalg.norm(launch.direction)
    n = case.net.nodes_per_side
    net_center = net.positions[: n * n].mean(axis=0)
    com = net_center - chaser.standoff * direction
    body = RigidBodySpec(name="chaser", mass=chaser.mass, inertia_body=np.diag(chaser.principal_inertia),
                         com_lvlh=com, velocity_lvlh=launch.velocity * direction)
    rim = rim_nodes(n)
    mount = NetMount(nodes=rim, body=index, points_body=net.positions[rim] - com,
                     stiffness=chaser.mount_stiffness, damping=chaser.mount_damping)
    return body, mount


def model_inputs(case: Case, base: Path = Path(".")) -> ModelInputs:
    """Everything :class:`multibody.impact.ImpactSimulation` needs for this case.

    Parameters
    ----------
    case : Case
        A validated net-impact case.
    base : Path
        Folder of the case file; mesh files are relative to it.

    Returns
    -------
    ModelInputs
        The assembly (net, bodies, joints, contact, solver, orbit mean motion (rad/s), chaser) and
        the joints' rest states.
    """
    net, velocity = build_net(case)
    bodies, joints, rest_att, rest_com = build_bodies_and_joints(case, base)
    mount = chaser_index = None
    if case.chaser is not None:
        chaser_index = len(bodies)
        chaser, mount = build_chaser(case, net, chaser_index)
        bodies.append(chaser)
        rest_att.append(chaser.body_to_lvlh.copy())
        rest_com.append(chaser.com_lvlh.copy())
    law = case.contact
    sim = case.simulation
    _check_member_sampling(joints, bodies, sim.step, sim.output_rate)
    assembly = ImpactAssembly(
        net=net, net_velocity=velocity, bodies=bodies, joints=joints,
        contact=ContactLaw(stiffness=law.stiffness, exponent=law.exponent,
                           hunt_crossley_alpha=law.hunt_crossley_alpha, mu_static=law.mu_static,
                           mu_kinetic=law.mu_kinetic, transition_speed=law.transition_speed,
                           thread_segments=law.thread_segments),
        solver=SolverSpec(end_time=sim.end_time, step=sim.step, integrator=sim.integrator,
                          output_rate=sim.output_rate, net_output_rate=sim.net_output_rate,
                          contact_substep=sim.contact_substep, net_integration=sim.net_integration,
                          implicit_contact_speed=sim.implicit_contact_speed),
        mean_motion=mean_motion(case.orbit.altitude) if isinstance(case.orbit, CircularOrbit) else 0.0,
        mount=mount, chaser=chaser_index, closing=closing_spec(case, net),
        tether=tether_spec(case, net))
    return ModelInputs(assembly, rest_att, rest_com)


def weak_locations(case: Case, assembly) -> list:
    """The case's weak locations with axes and offsets in their joint frames (t = 0).

    Parameters
    ----------
    case : Case
        A net-impact case (``structures.weak_locations``: offset (m) and section axes in the
        target frame).
    assembly : multibody.assembly.ImpactAssembly
        The built assembly (joint frames in LVLH at t = 0).

    Returns
    -------
    list of structures.weak_location.WeakLocation
        Empty without a ``[structures]`` table. Revolute joints are judged by default on the
        moment about h1 and h3 (not the hinge axis h2).
    """
    if case.structures is None:
        return []
    _, target_to_lvlh = target_pose_lvlh(case)
    names = [j.name for j in assembly.joints]
    out = []
    for spec in case.structures.weak_locations:
        k = names.index(spec.joint)
        joint = assembly.joints[k]
        target_to_joint = joint.hinge_to_lvlh.T @ target_to_lvlh
        beam = np.asarray(spec.beam_axis, float)
        beam /= np.linalg.norm(beam)
        width = np.asarray(spec.width_axis, float)
        width = width - (width @ beam) * beam
        width /= np.linalg.norm(width)
        section_to_target = np.column_stack([beam, width, np.cross(beam, width)])
        if spec.moment_axes is not None:
            axes = tuple(sorted({"h1": 0, "h2": 1, "h3": 2}[a] for a in spec.moment_axes))
        else:
            axes = (0, 2) if joint.kind == "revolute" else (0, 1, 2)
        material = spec.material
        out.append(WeakLocation(
            name=spec.name, joint=k, section_to_joint=target_to_joint @ section_to_target,
            offset_joint=target_to_joint @ np.asarray(spec.offset, float),
            section=section_properties(spec.section) if spec.section is not None else None,
            ultimate_normal=Allowable.of(material.ultimate_normal) if material else None,
            ultimate_shear=Allowable.of(material.ultimate_shear) if material else None,
            allowable_moment=Allowable.of(spec.allowable_moment) if spec.allowable_moment is not None else None,
            allowable_force=Allowable.of(spec.allowable_force) if spec.allowable_force is not None else None,
            moment_axes=axes, load_filter_hz=joint.load_filter_hz, load_filter_order=joint.load_filter_order,
            **_structural_modes(spec)))
    return out


def _structural_modes(spec) -> dict:
    """WeakLocation keys of a location read through its structure's first mode (a value or a range)."""
    if spec.structural_mode_hz is None:
        return {}
    low, high = np.atleast_1d(np.asarray(spec.structural_mode_hz, float))[[0, -1]]
    return {"structural_modes_hz": tuple(mode_grid(low, high)), "structural_damping_ratio": spec.structural_damping_ratio}
