"""Plain descriptions of what goes into an impact simulation (SI units, named frames).

These dataclasses are the interface between the case files (``riskassess.cases.impact``) and the
Exudyn builders; tests build them directly for analytic set-ups.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import trimesh

from multibody.net import NetTopology

if TYPE_CHECKING:       # annotation only: the loads module needs Exudyn, these descriptions do not
    from multibody.closing_winch import ClosingSpec
    from multibody.recorded_loads import RecordedBodyLoads
    from multibody.tether_spool import TetherSpec


@dataclass
class RigidBodySpec:
    """One debris rigid body.

    Attributes
    ----------
    name : str
    mass : float                      (kg)
    inertia_body : (3, 3) float       Inertia about the CoM, body frame (kg m^2).
    com_lvlh : (3,) float             Initial CoM position, LVLH (m).
    body_to_lvlh : (3, 3) float       Initial attitude (rotation matrix body->LVLH).
    velocity_lvlh : (3,) float        Initial CoM velocity (m/s), LVLH.
    omega_body : (3,) float           Initial angular velocity (rad/s), body frame.
    meshes_body : list of trimesh.Trimesh   Contact shapes, body frame (origin at CoM) (m).
    """

    name: str
    mass: float
    inertia_body: np.ndarray
    com_lvlh: np.ndarray
    body_to_lvlh: np.ndarray = field(default_factory=lambda: np.eye(3))
    velocity_lvlh: np.ndarray = field(default_factory=lambda: np.zeros(3))
    omega_body: np.ndarray = field(default_factory=lambda: np.zeros(3))
    meshes_body: list[trimesh.Trimesh] = field(default_factory=list)


@dataclass
class JointSpec:
    """A joint between two bodies, realised as a stiff penalty spring-damper in 6 DOF.

    The joint frame (columns h1, h2, h3) follows the seed paper's hinge frame (Sec. 2.4.1):
    h2 is the hinge axis, h1 points from the child's CoM towards the hinge (anti-parallel
    to the appendage CoM), h3 completes the right-handed set.

    Attributes
    ----------
    kind : {"revolute", "clamped"}
    parent, child : int               Body indices.
    point_lvlh : (3,) float           Joint point at t = 0, LVLH (m).
    hinge_to_lvlh : (3, 3) float      Joint frame at t = 0 (columns h1, h2, h3 in LVLH), before
                                      any initial hinge angle is applied to the child.
    torsional_stiffness : float       About h2 for revolute joints (N m/rad).
    torsional_damping : float         About h2 (N m s/rad).
    penalty_translational : float or None   Penalty stiffness on the joint point offset (N/m);
                                      None: automatic, tuned to the step (multibody.hinge).
    penalty_rotational : float or None      Penalty stiffness on locked rotations (N m/rad).
    penalty_damping_ratio : float     Damping of the penalty springs, fraction of critical (-).
    first_mode_hz : float or None     The structure's own first mode on this joint (Hz): the
                                      penalty springs not given explicitly are set from it instead
                                      of from the step (multibody.hinge.joint_stiffness_joint_frame).
    rotation_modes_hz : (3,) float or None   The structure's own modes about h1, h2, h3 (Hz, each axis
                                      alone), NaN where the axis keeps its automatic penalty; the
                                      translations keep theirs (multibody.hinge).
    rotation_modes_damping_ratio : float   Damping of those axes, fraction of critical (-).
    structural_stiffness : (6,) float or None   The structure's own springs on [x, y, z] (N/m) and
                                      [rot h1, rot h2, rot h3] (N m/rad), joint frame, e.g. a member's
                                      compliance lumped at its root (structures.member); replaces
                                      every penalty spring of the joint.
    load_filter_hz : float            Cut-off (Hz) of the Butterworth low-pass its recorded loads are
                                      also read through, every step (multibody.load_filter); 0: none.
                                      Recording only: the dynamics do not see it.
    load_filter_order : int           That filter's order, 2 or 4.
    """

    name: str
    kind: str
    parent: int
    child: int
    point_lvlh: np.ndarray
    hinge_to_lvlh: np.ndarray
    torsional_stiffness: float = 0.0
    torsional_damping: float = 0.0
    penalty_translational: float | None = None
    penalty_rotational: float | None = None
    penalty_damping_ratio: float = 0.05
    first_mode_hz: float | None = None
    rotation_modes_hz: np.ndarray | None = None
    rotation_modes_damping_ratio: float = 0.0
    structural_stiffness: np.ndarray | None = None
    load_filter_hz: float = 0.0
    load_filter_order: int = 4


def subtree_bodies(joints: list[JointSpec], root: int, cut_joints=()) -> list[int]:
    """``root`` and every body attached below it through joints not in ``cut_joints`` (indices).

    Parameters
    ----------
    joints : list of JointSpec
        The assembly's joints (parent -> child).
    root : int
        Index of the body the subtree starts from.
    cut_joints : collection of int
        Indices into ``joints`` of joints treated as broken.

    Returns
    -------
    list of int
        Body indices, ``root`` first, depth-first.
    """
    out = [root]
    for k, joint in enumerate(joints):
        if joint.parent == root and k not in cut_joints:
            out += subtree_bodies(joints, joint.child, cut_joints)
    return out


@dataclass
class ContactLaw:
    """Hertz / Hunt-Crossley / Hollar contact parameters (seed paper Table 2)."""

    stiffness: float          # k_n (N/m^exponent)
    exponent: float = 1.5     # n (-)
    hunt_crossley_alpha: float = 0.05  # alpha (s/m); d_n = 1.5 alpha k_n
    mu_static: float = 0.19
    mu_kinetic: float = 0.152
    transition_speed: float = 0.01    # V_t0 (m/s)
    # threads touch the box shapes too, not only the nodes (multibody.contact_segment); off: the seed paper's model
    thread_segments: bool = False

    @property
    def damping(self) -> float:
        """Hunt-Crossley damping coefficient d_n (N s/m^(n+1))."""
        return 1.5 * self.hunt_crossley_alpha * self.stiffness


@dataclass
class SolverSpec:
    """Time integration and output settings."""

    end_time: float                 # (s)
    step: float                     # fixed step (s)
    integrator: str = "VelocityVerlet"
    output_rate: float = 1000.0     # time-series samples per second (Hz)
    net_output_rate: float = 50.0   # net snapshots per second (Hz)
    contact_substep: float = 2e-6   # shortest contact sub-step (s); multibody.kernel sizes each node's
    joint_tuning_step: float | None = None  # step the automatic penalty joints are tuned to (s); None: step
    # who integrates the net: "kernel" (the compiled kernel, inside the bodies' Verlet step;
    # multibody.kernel_net) or "exudyn" (one Exudyn node for the whole net, the reference path)
    net_integration: str = "kernel"
    # resting contacts: a node's single contact whose normal speed is below this (m/s) takes one
    # implicit step instead of the sub-cycle (multibody.contact_implicit); 0 turns it off (the default)
    implicit_contact_speed: float = 0.0

    @property
    def n_steps(self) -> int:
        return int(round(self.end_time / self.step))


@dataclass
class NetMount:
    """Net nodes held on a body by stiff rods (a chaser's net frame, Tang et al. 2023 Sec. 4.2.2).

    Attributes
    ----------
    nodes : (k,) int            Mounted net nodes.
    body : int                  Index of the carrying body (the chaser) in ``ImpactAssembly.bodies``.
    points_body : (k, 3) float  Mount points, carrying body's frame, origin at its CoM (m).
    stiffness : float           Rod stiffness per mount (N/m).
    damping : float             Rod damping per mount (N s/m).
    """

    nodes: np.ndarray
    body: int
    points_body: np.ndarray
    stiffness: float
    damping: float


@dataclass
class ImpactAssembly:
    """Everything one coupled net-impact simulation needs.

    When a chaser body is simulated (``chaser`` is its index in ``bodies``; it carries the net
    through ``mount``), it has no contact shapes and is not debris: the recorder keeps it out
    of the debris totals.
    """

    net: NetTopology
    net_velocity: np.ndarray        # (n, 3) initial node velocities, LVLH (m/s)
    bodies: list[RigidBodySpec]
    joints: list[JointSpec]
    contact: ContactLaw
    solver: SolverSpec
    mean_motion: float = 0.0        # (rad/s), 0 without orbit
    mount: NetMount | None = None
    chaser: int | None = None
    #: recorded contact loads applied to the bodies (the sequential method's second step,
    #: :mod:`multibody.recorded_loads`); None in a coupled run
    body_loads: RecordedBodyLoads | None = None
    #: the net's closing mechanism (:class:`multibody.closing_winch.ClosingSpec`; the loop is the net's last 12
    #: threads); None: the net stays open
    closing: ClosingSpec | None = None
    #: the main tether from a net node to a station-keeping chaser (:class:`multibody.tether_spool.TetherSpec`,
    #: :mod:`multibody.net_tether`); None: the net flies free of the chaser
    tether: TetherSpec | None = None

    @property
    def debris_indices(self) -> list[int]:
        """Indices of the debris bodies (every body but the chaser)."""
        return [k for k in range(len(self.bodies)) if k != self.chaser]
