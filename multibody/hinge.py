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
from scipy.spatial.transform import Rotation

from multibody.assembly import JointSpec, RigidBodySpec


def hinge_frame_lvlh(axis_lvlh, point_lvlh, child_com_lvlh) -> np.ndarray:
    """Hinge frame (columns h1, h2, h3) in LVLH; seed paper Sec. 2.4.1.

    h2 is the hinge axis; h1 is anti-parallel to the child CoM offset from the hinge,
    projected normal to h2; h3 = h1 x h2.
    """
    h2 = np.asarray(axis_lvlh, float) / np.linalg.norm(axis_lvlh)
    offset = np.asarray(child_com_lvlh, float) - np.asarray(point_lvlh, float)
    h1 = -(offset - (offset @ h2) * h2)
    if np.linalg.norm(h1) < 1e-9:
        seed = np.array([1.0, 0.0, 0.0]) if abs(h2[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        h1 = seed - (seed @ h2) * h2
    h1 /= np.linalg.norm(h1)
    return np.column_stack([h1, h2, np.cross(h1, h2)])


def joint_stiffness_joint_frame(joint: JointSpec) -> np.ndarray:
    """Diagonal 6x6 stiffness (N/m, N m/rad) in the joint frame: [x, y, z, rot h1, rot h2, rot h3]."""
    k_rot_h2 = joint.torsional_stiffness if joint.kind == "revolute" else joint.penalty_rotational
    return np.diag([joint.penalty_translational] * 3
                   + [joint.penalty_rotational, k_rot_h2, joint.penalty_rotational])


def joint_damping_joint_frame(joint: JointSpec, parent: RigidBodySpec, child: RigidBodySpec) -> np.ndarray:
    """Diagonal 6x6 damping: the penalty springs get a fraction of their critical damping.

    The effective mass is the reduced mass of the two bodies; the effective inertia is
    the child's mean inertia about the joint point (child usually lighter).
    """
    reduced_mass = parent.mass * child.mass / (parent.mass + child.mass)
    arm = child.com_lvlh - joint.point_lvlh
    inertia_at_joint = np.trace(child.inertia_body) / 3.0 + child.mass * (arm @ arm)
    zeta = joint.penalty_damping_ratio
    c_trans = 2.0 * zeta * np.sqrt(joint.penalty_translational * reduced_mass)
    c_rot = 2.0 * zeta * np.sqrt(joint.penalty_rotational * inertia_at_joint)
    c_h2 = joint.torsional_damping if joint.kind == "revolute" else c_rot
    return np.diag([c_trans] * 3 + [c_rot, c_h2, c_rot])


def add_penalty_joint(mbs, joint: JointSpec, bodies: list[RigidBodySpec], body_objects,
                      child_body_to_lvlh_unrotated: np.ndarray, child_com_unrotated: np.ndarray):
    """Add the joint's connector to ``mbs``; return its object index.

    The joint frame is attached to the child as it was before any initial hinge angle, so
    the spring's rest state is the zero hinge angle.
    """
    parent, child = bodies[joint.parent], bodies[joint.child]
    joint_to_parent = parent.body_to_lvlh.T @ joint.hinge_to_lvlh
    joint_to_child = child_body_to_lvlh_unrotated.T @ joint.hinge_to_lvlh
    point_parent = parent.body_to_lvlh.T @ (joint.point_lvlh - parent.com_lvlh)
    point_child = child_body_to_lvlh_unrotated.T @ (joint.point_lvlh - child_com_unrotated)
    m0 = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body_objects[joint.parent],
                                       localHT=exu.HT(rotation=joint_to_parent, translation=point_parent)))
    m1 = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body_objects[joint.child],
                                       localHT=exu.HT(rotation=joint_to_child, translation=point_child)))
    return mbs.AddObject(ObjectConnectorRigidBodySpringDamper(
        name=joint.name, markerNumbers=[m0, m1],
        stiffness=joint_stiffness_joint_frame(joint),
        damping=joint_damping_joint_frame(joint, parent, child),
        useIntrinsicFormulation=True))


def relative_rotation_vector_joint_frame(parent_to_lvlh, child_to_lvlh, joint_to_parent, joint_to_child):
    """Rotation vector (rad) of the child's joint frame relative to the parent's, joint frame.

    Component 1 is the hinge angle about h2 for a revolute joint.
    """
    relative = (parent_to_lvlh @ joint_to_parent).T @ (child_to_lvlh @ joint_to_child)
    return Rotation.from_matrix(relative).as_rotvec()
