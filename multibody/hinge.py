"""Joints between debris bodies: revolute hinge with torsional spring-damper, or clamped.

Exudyn's ideal joints cannot run in explicit solvers, so each joint is an
``ObjectConnectorRigidBodySpringDamper`` (intrinsic formulation): stiff penalty springs
lock the joint point and the rotations about h1 and h3 (and about h2 when clamped); a
revolute joint keeps only the torsional spring-damper about the hinge axis h2. Its
connector forces are the joint reactions, read in the joint frame.
"""
from __future__ import annotations

import numpy as np
import exudyn as exu
from exudyn.itemInterface import MarkerBodyRigid, ObjectConnectorRigidBodySpringDamper

from multibody.assembly import JointSpec, RigidBodySpec
from multibody.maths.rotations import rotation_vector_from_matrix
from multibody.node_frame import frame_node, vector_node


def hinge_frame_lvlh(axis_lvlh, point_lvlh, child_com_lvlh) -> np.ndarray:
    """Hinge frame (columns h1, h2, h3) in LVLH; seed paper Sec. 2.4.1.

    h2 is the hinge axis; h1 is anti-parallel to the child CoM offset from the hinge,
    projected normal to h2; h3 = h1 x h2.

    Parameters
    ----------
    axis_lvlh : (3,) float
        Hinge axis direction (any length), LVLH.
    point_lvlh : (3,) float
        Hinge point (m), LVLH.
    child_com_lvlh : (3,) float
        CoM of the child body (the appendage) (m), LVLH.

    Returns
    -------
    (3, 3) float
        hinge->LVLH rotation: columns h1, h2, h3 in LVLH components.
    """
    h2_lvlh = np.asarray(axis_lvlh, float) / np.linalg.norm(axis_lvlh)
    offset_lvlh = np.asarray(child_com_lvlh, float) - np.asarray(point_lvlh, float)
    h1_lvlh = -(offset_lvlh - (offset_lvlh @ h2_lvlh) * h2_lvlh)
    if np.linalg.norm(h1_lvlh) < 1e-9:
        seed_lvlh = np.array([1.0, 0.0, 0.0]) if abs(h2_lvlh[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        h1_lvlh = seed_lvlh - (seed_lvlh @ h2_lvlh) * h2_lvlh
    h1_lvlh /= np.linalg.norm(h1_lvlh)
    return np.column_stack([h1_lvlh, h2_lvlh, np.cross(h1_lvlh, h2_lvlh)])


#: Penalty joints are tuned to a frequency of PENALTY_STEP_FACTOR / step (rad/s): well under
#: Verlet's stability limit 2 / step, with room for bodies held by two joints (x sqrt(2)).
PENALTY_STEP_FACTOR = 0.5
#: Upper bounds of automatic penalty stiffness; EXUDYN-NOTES: 1e9 N/m and 1e8 N m/rad give
#: joint loads within 0.4 % of an ideal implicit joint.
PENALTY_TRANSLATIONAL_CAP = 1e9
PENALTY_ROTATIONAL_CAP = 1e8
#: A structural mode (``first_mode_hz``) must be resolved in time: Verlet's phase error is
#: (omega h)^2 / 24, 0.4 % of the frequency at 20 steps per period.
STRUCTURAL_STEPS_PER_PERIOD = 20
#: names of a joint's six spring axes in messages: translations along, rotations about the hinge frame's axes
JOINT_AXIS_NAMES = ("x", "y", "z", "rot h1", "rot h2", "rot h3")


def effective_mass_joint_frame(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec) -> np.ndarray:
    """Reduced mass (kg) and reduced inertias about the joint axes h1, h2, h3 (kg m^2).

    Each body's inertia is taken about the joint point; the pair acts like two
    inertias on one spring, so the reduced value sets the penalty mode's frequency.

    Parameters
    ----------
    joint : JointSpec
        The joint (point and hinge frame in LVLH at t = 0).
    parent, child : RigidBodySpec
        The two bodies it connects (CoM, attitude and inertia at t = 0).

    Returns
    -------
    (6,) float
        [m, m, m, J_h1, J_h2, J_h3]: reduced mass (kg) three times, then reduced inertias (kg m^2)
        about the hinge-frame axes.
    """
    reduced = [parent.mass * child.mass / (parent.mass + child.mass)] * 3
    for axis_lvlh in joint.hinge_to_lvlh.T:
        j = [axis_lvlh @ _inertia_about_point_lvlh(b, joint.point_lvlh) @ axis_lvlh for b in (parent, child)]
        reduced.append(j[0] * j[1] / (j[0] + j[1]))
    return np.array(reduced)


def coupled_mode_inertia_joint_frame(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec) -> np.ndarray:
    """Mass (kg) and inertias (kg m^2) each joint axis [x, y, z, rot h1, rot h2, rot h3] moves
    when it alone deforms and the other five are rigid, the two bodies otherwise free.

    Exact for one spring between two free rigid bodies: with the inverse mass ``W`` of both
    bodies (about their CoMs, LVLH) projected onto the motions the other five axes allow, a
    spring k on axis i rings at omega^2 = k c_i W c_i^T (c_i: the axis' relative-motion row).
    Unlike :func:`effective_mass_joint_frame` it counts the turn a translational spring gives
    each body about its CoM, and the translation a rotational one gives it.

    Parameters
    ----------
    joint : JointSpec
        The joint (point and hinge frame in LVLH at t = 0).
    parent, child : RigidBodySpec
        The two bodies it connects (CoM, attitude and inertia at t = 0).

    Returns
    -------
    (6,) float
        Modal mass (kg) on the three translations, then modal inertia (kg m^2) on the three
        rotations, hinge-frame axes.
    """
    rows = _joint_motion_rows_lvlh(joint, parent, child)
    inverse_mass = np.zeros((12, 12))
    for k, body in enumerate((parent, child)):
        inertia_lvlh = body.body_to_lvlh @ body.inertia_body @ body.body_to_lvlh.T
        inverse_mass[6 * k:6 * k + 3, 6 * k:6 * k + 3] = np.eye(3) / body.mass
        inverse_mass[6 * k + 3:6 * k + 6, 6 * k + 3:6 * k + 6] = np.linalg.inv(inertia_lvlh)
    out = np.empty(6)
    for i in range(6):
        others = np.delete(rows, i, axis=0)
        locked = inverse_mass @ others.T
        allowed = inverse_mass - locked @ np.linalg.solve(others @ locked, locked.T)
        out[i] = 1.0 / (rows[i] @ allowed @ rows[i])
    return out


def _joint_motion_rows_lvlh(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec) -> np.ndarray:
    """(6, 12) rows giving the joint's relative motion (translation of the joint point, then
    rotation, along h1, h2, h3) from both bodies' (velocity, angular velocity) at their CoMs, LVLH."""
    def point_motion(body):          # velocity of the joint point = v + omega x r = v - r x omega
        r_lvlh = np.asarray(joint.point_lvlh) - body.com_lvlh
        skew_r_lvlh = np.array([[0, -r_lvlh[2], r_lvlh[1]], [r_lvlh[2], 0, -r_lvlh[0]], [-r_lvlh[1], r_lvlh[0], 0]])
        return np.hstack([np.eye(3), -skew_r_lvlh])
    rotation = np.hstack([np.zeros((3, 3)), np.eye(3)])
    relative = np.vstack([np.hstack([-point_motion(parent), point_motion(child)]),
                          np.hstack([-rotation, rotation])])
    hinge_to_lvlh = joint.hinge_to_lvlh
    to_joint = np.block([[hinge_to_lvlh.T, np.zeros((3, 3))], [np.zeros((3, 3)), hinge_to_lvlh.T]])
    return to_joint @ relative


def _inertia_about_point_lvlh(body: RigidBodySpec, point_lvlh) -> np.ndarray:
    offset_lvlh = body.com_lvlh - np.asarray(point_lvlh)
    inertia_lvlh = body.body_to_lvlh @ body.inertia_body @ body.body_to_lvlh.T
    return inertia_lvlh + body.mass * ((offset_lvlh @ offset_lvlh) * np.eye(3)
                                       - np.outer(offset_lvlh, offset_lvlh))


def joint_stiffness_joint_frame(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec,
                                step: float) -> np.ndarray:
    """Diagonal stiffness [x, y, z, rot h1, rot h2, rot h3] (N/m, N m/rad), joint frame.

    Penalty values not given in the joint are set so that each penalty mode sits at
    ``PENALTY_STEP_FACTOR / step`` rad/s (capped), or, when the joint gives the structure's
    ``first_mode_hz``, at that frequency: the joint then carries the structure's compliance,
    and its loads no longer follow the step (docs/structures.md, "Are the judged peaks
    converged?"). A structural mode is tuned exactly on each axis alone
    (:func:`coupled_mode_inertia_joint_frame`); the automatic penalty is tuned on the reduced mass,
    which puts its modes up to ~2x faster than asked (a margin the 1 / step check leaves). Given
    values must stay below the explicit stability limit, and a structural mode must be resolved by at least
    ``STRUCTURAL_STEPS_PER_PERIOD`` steps; otherwise a ``ValueError`` names the joint.

    Parameters
    ----------
    joint : JointSpec
        The joint (point and hinge frame in LVLH at t = 0).
    parent, child : RigidBodySpec
        The two bodies it connects (CoM, attitude and inertia at t = 0).
    step : float
        Explicit integration step the automatic penalties are tuned to (s).

    Returns
    -------
    (6,) float
        Spring stiffness on [x, y, z] (N/m) and [rot h1, rot h2, rot h3] (N m/rad), hinge frame.
    """
    inertia = effective_mass_joint_frame(joint, parent, child)
    if joint.structural_stiffness is not None:
        return _resolved_structural_stiffness(joint, parent, child, step)
    if joint.first_mode_hz is not None:
        omega = 2.0 * np.pi * joint.first_mode_hz
        if omega * step > 2.0 * np.pi / STRUCTURAL_STEPS_PER_PERIOD:
            raise ValueError(
                f"joint '{joint.name}': first_mode_hz = {joint.first_mode_hz:g} Hz has fewer than "
                f"{STRUCTURAL_STEPS_PER_PERIOD} steps of {step:g} s per period; reduce simulation.step below "
                f"{1.0 / (STRUCTURAL_STEPS_PER_PERIOD * joint.first_mode_hz):.3g} s")
        k = coupled_mode_inertia_joint_frame(joint, parent, child) * omega ** 2
    else:
        auto = inertia * (PENALTY_STEP_FACTOR / step) ** 2
        k = np.minimum(auto, [PENALTY_TRANSLATIONAL_CAP] * 3 + [PENALTY_ROTATIONAL_CAP] * 3)
    if joint.penalty_translational is not None:
        k[:3] = joint.penalty_translational
    if joint.penalty_rotational is not None:
        k[3:] = joint.penalty_rotational
    if joint.rotation_modes_hz is not None:
        k[3:] = _rotation_mode_springs(joint, parent, child, step, k[3:])
    if joint.kind == "revolute":
        k[4] = joint.torsional_stiffness
    omega_step = np.sqrt(k / inertia) * step
    if omega_step.max() > 1.0:
        axis = JOINT_AXIS_NAMES[int(omega_step.argmax())]
        raise ValueError(
            f"joint '{joint.name}': stiffness {k[omega_step.argmax()]:.3g} on {axis} gives a mode at "
            f"{omega_step.max() / step:.3g} rad/s, too fast for the step {step:g} s (limit 1/step); "
            f"lower the penalty stiffness (or omit it for the automatic value) or reduce simulation.step")
    return k


def _rotation_mode_springs(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec, step: float,
                           automatic: np.ndarray) -> np.ndarray:
    """Springs about h1, h2, h3 (N m/rad): each axis the joint's ``rotation_modes_hz`` names rings alone at that
    frequency (:func:`coupled_mode_inertia_joint_frame`), the others keep ``automatic``; a mode with fewer than
    ``STRUCTURAL_STEPS_PER_PERIOD`` steps per period is refused."""
    frequency_hz = np.asarray(joint.rotation_modes_hz, float)
    named = ~np.isnan(frequency_hz)
    fastest = frequency_hz[named].max()
    if fastest * step * STRUCTURAL_STEPS_PER_PERIOD > 1.0:
        raise ValueError(
            f"joint '{joint.name}': rotation_modes up to {fastest:g} Hz have fewer than {STRUCTURAL_STEPS_PER_PERIOD} "
            f"steps of {step:g} s per period; reduce simulation.step below "
            f"{1.0 / (STRUCTURAL_STEPS_PER_PERIOD * fastest):.3g} s")
    structural = coupled_mode_inertia_joint_frame(joint, parent, child)[3:] * (2.0 * np.pi * frequency_hz) ** 2
    return np.where(named, structural, automatic)


def _resolved_structural_stiffness(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec,
                                   step: float) -> np.ndarray:
    """The joint's own structural springs, refused when a mode they make has fewer than
    ``STRUCTURAL_STEPS_PER_PERIOD`` steps per period (each axis alone, the others rigid)."""
    k = np.asarray(joint.structural_stiffness, float).copy()
    frequency_hz = np.sqrt(k / coupled_mode_inertia_joint_frame(joint, parent, child)) / (2.0 * np.pi)
    if frequency_hz.max() * step * STRUCTURAL_STEPS_PER_PERIOD > 1.0:
        axis = JOINT_AXIS_NAMES[int(frequency_hz.argmax())]
        raise ValueError(
            f"joint '{joint.name}': its structural stiffness {k[frequency_hz.argmax()]:.3g} on {axis} rings at "
            f"{frequency_hz.max():.3g} Hz, fewer than {STRUCTURAL_STEPS_PER_PERIOD} steps of {step:g} s per period; "
            f"reduce simulation.step below {1.0 / (STRUCTURAL_STEPS_PER_PERIOD * frequency_hz.max()):.3g} s")
    return k


def structural_modes_hz(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec, step: float) -> np.ndarray:
    """The frequencies (Hz) at which each joint axis alone rings with the springs the run uses.

    Parameters
    ----------
    joint : JointSpec
        The joint.
    parent, child : RigidBodySpec
        The two bodies it connects.
    step : float
        The run's step (s), which sets the automatic penalty springs.

    Returns
    -------
    (6,) float
        [x, y, z, rot h1, rot h2, rot h3] (Hz), each axis alone, the other five rigid, both bodies free.
    """
    k = joint_stiffness_joint_frame(joint, parent, child, step)
    return np.sqrt(k / coupled_mode_inertia_joint_frame(joint, parent, child)) / (2.0 * np.pi)


def joint_damping_joint_frame(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec,
                              stiffness: np.ndarray) -> np.ndarray:
    """Diagonal damping: each penalty spring gets ``penalty_damping_ratio`` of critical damping, each axis
    that carries one of the joint's ``rotation_modes_hz`` its ``rotation_modes_damping_ratio``.

    Parameters
    ----------
    joint : JointSpec
        The joint (point and hinge frame in LVLH at t = 0).
    parent, child : RigidBodySpec
        The two bodies it connects (CoM, attitude and inertia at t = 0).
    stiffness : (6,) float
        The springs of :func:`joint_stiffness_joint_frame` (N/m, N m/rad), hinge frame.

    Returns
    -------
    (6,) float
        Damping on [x, y, z] (N s/m) and on the rotations (N m s/rad), hinge frame; the revolute
        axis h2 gets the joint's torsional damping instead.
    """
    inertia = effective_mass_joint_frame(joint, parent, child)
    ratio = np.full(6, joint.penalty_damping_ratio)
    if joint.rotation_modes_hz is not None:      # the structure's damping on the axes that carry its modes
        ratio[3:] = np.where(np.isnan(joint.rotation_modes_hz), ratio[3:], joint.rotation_modes_damping_ratio)
    c = 2.0 * ratio * np.sqrt(stiffness * inertia)
    if joint.kind == "revolute":
        c[4] = joint.torsional_damping
    return c


def add_penalty_joint(mbs, joint: JointSpec, bodies: list[RigidBodySpec], body_objects,
                      child_body_to_lvlh_unrotated: np.ndarray, child_com_lvlh_unrotated: np.ndarray, step: float,
                      node_to_body=None):
    """Add the joint's connector to ``mbs``; return its object index.

    The joint frame is attached to the child as it was before any initial hinge angle, so
    the spring's rest state is the zero hinge angle.

    Parameters
    ----------
    mbs : exudyn.MainSystem
        System to add the markers and the connector to.
    joint : JointSpec
        The joint (point and hinge frame in LVLH at t = 0).
    bodies : list of RigidBodySpec
        All bodies of the assembly; ``joint.parent`` and ``joint.child`` index into it.
    body_objects : list of int
        Exudyn object numbers of ``bodies``.
    child_body_to_lvlh_unrotated : (3, 3) float
        The child's attitude (body->LVLH) at zero hinge angle.
    child_com_lvlh_unrotated : (3,) float
        The child's CoM at zero hinge angle (m), LVLH.
    step : float
        Step the automatic penalty springs are tuned to (s).
    node_to_body : (nb, 3, 3) float, optional
        Each body's Exudyn node frame in its body frame (:mod:`multibody.node_frame`): the markers are
        placed in it. None: the node frames are the body frames.

    Returns
    -------
    int
        Exudyn object number of the connector.
    """
    parent, child = bodies[joint.parent], bodies[joint.child]
    joint_to_parent = parent.body_to_lvlh.T @ joint.hinge_to_lvlh
    joint_to_child = child_body_to_lvlh_unrotated.T @ joint.hinge_to_lvlh
    point_parent_body = parent.body_to_lvlh.T @ (joint.point_lvlh - parent.com_lvlh)
    point_child_body = child_body_to_lvlh_unrotated.T @ (joint.point_lvlh - child_com_lvlh_unrotated)
    stiffness = joint_stiffness_joint_frame(joint, parent, child, step)
    c_parent, c_child = (np.eye(3), np.eye(3)) if node_to_body is None else (node_to_body[joint.parent],
                                                                               node_to_body[joint.child])
    m0 = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body_objects[joint.parent], localHT=exu.HT(
        rotation=frame_node(joint_to_parent, c_parent), translation=vector_node(point_parent_body, c_parent))))
    m1 = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body_objects[joint.child], localHT=exu.HT(
        rotation=frame_node(joint_to_child, c_child), translation=vector_node(point_child_body, c_child))))
    return mbs.AddObject(ObjectConnectorRigidBodySpringDamper(
        name=joint.name, markerNumbers=[m0, m1],
        stiffness=np.diag(stiffness), damping=np.diag(joint_damping_joint_frame(joint, parent, child, stiffness)),
        useIntrinsicFormulation=True))


def relative_rotation_vector_joint_frame(parent_to_lvlh, child_to_lvlh, joint_to_parent, joint_to_child):
    """Rotation vector (rad) of the child's joint frame relative to the parent's, joint frame.

    Component 1 is the hinge angle about h2 for a revolute joint.

    Parameters
    ----------
    parent_to_lvlh, child_to_lvlh : (3, 3) float
        Current attitudes (body->LVLH) of the parent and the child.
    joint_to_parent, joint_to_child : (3, 3) float
        Joint (hinge) frame in each body's frame (columns h1, h2, h3 in body components).

    Returns
    -------
    (3,) float
        Relative rotation vector (rad), joint frame (h1, h2, h3).
    """
    child_joint_to_parent_joint = (parent_to_lvlh @ joint_to_parent).T @ (child_to_lvlh @ joint_to_child)
    return rotation_vector_from_matrix(np.ascontiguousarray(child_joint_to_parent_joint, float))
