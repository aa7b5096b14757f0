"""Replay of an approach trajectory in 3-D: two MU bodies pull the corners of the Exudyn net.

The guidance (:mod:`multibody.control.mu_approach`) treats the net mouth as a massless segment between two
maneuverable units (MUs). Here the same square lumped-mass net as the impact model
(:func:`multibody.net.flat_square_net`, :func:`multibody.impact.build_impact_system`) hangs from
two rigid MU bodies: its two mouth corners are held on the MUs by stiff mounts
(:class:`multibody.assembly.NetMount`), the rest of the net trails behind the mouth in the plane of
motion (world z = 0, the paper's x-y plane). Each MU follows the planned path by a force

.. math:: F = m\\,a_{ref}(t) + K_p (r_{ref} - r) + K_d (v_{ref} - v)

(feed-forward of the planned acceleration plus a tracking term that takes the net's pull), applied
as an Exudyn load. The replay reports whether the mouth reaches the debris and how much force
the MUs need beyond the massless-net plan.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import exudyn as exu
import numpy as np
from exudyn.itemInterface import LoadForceVector, MarkerBodyPosition
from scipy.interpolate import CubicSpline

from multibody.assembly import ContactLaw, ImpactAssembly, NetMount, RigidBodySpec, SolverSpec
from multibody.health import HealthWatch
from multibody.impact import (INTEGRATORS, build_impact_system, checked_post_step, detach_step_functions,
                              likely_failure_cause, simulation_settings, solve_checked)
from multibody.net import flat_square_net

#: MU bodies are spheres of this radius for their (unused) inertia (m).
MU_RADIUS = 0.2
#: Mount spring-damper from a net corner to its MU (N/m, N s/m): stiffer than a replay thread
#: (EA/l ~ 2e3 N/m for EA 6 kN), soft enough for a 0.5 ms explicit step with ~10 g corner nodes.
MOUNT_STIFFNESS, MOUNT_DAMPING = 5e3, 10.0


@dataclass
class ReplayResult:
    """Sampled replay: ``time`` (k,) (s), ``unit_positions`` (k, 2, 3) and ``mouth_edge`` (k, n, 3)
    (m, world), ``tracking_force`` (k, 2) (N, beyond the feed-forward) and the figures of merit."""

    time: np.ndarray
    unit_positions: np.ndarray
    mouth_edge: np.ndarray
    tracking_force: np.ndarray
    summary: dict


def _reference(t, unit_paths):
    """Cubic splines of the planned MU positions (2, 2, M) (m, world) over ``t`` (M,) (s)."""
    return [CubicSpline(t, path, axis=1) for path in unit_paths]


def replay_net(side_length, nodes_per_side, net_mass, axial_rigidity, damping, start_1, start_2, debris):
    """The square net laid flat in the world x-y plane: mouth edge from ``start_1`` to ``start_2``
    (its corners, compressed along the mouth when the MUs start closer than ``side_length``), the
    rest trailing away from ``debris``.

    Parameters
    ----------
    side_length : float
        Side of the square net (m).
    nodes_per_side : int
        N of the N x N node grid.
    net_mass : float
        Whole net, the four corner bullets included (kg).
    axial_rigidity : float
        EA of a thread (N).
    damping : float
        Axial damping of every thread (N s/m).
    start_1, start_2 : (2,) float
        Initial MU positions, the mouth corners (m), world x-y.
    debris : (2,) float
        Debris centre (m), world x-y.

    Returns
    -------
    net : NetTopology
        Node positions (m) in the world frame (z = 0).
    mouth_nodes : (N,) int
        Nodes of the mouth edge, from ``start_1`` to ``start_2``.
    """
    n = nodes_per_side
    node_mass = net_mass / (n * n + 4)
    net = flat_square_net(np.zeros(3), [0.0, 0.0, 1.0], side_length, n, node_mass, 0.005, axial_rigidity,
                          damping, node_mass, 0.005, side_length / (n - 1))
    start_1, start_2 = np.asarray(start_1, float), np.asarray(start_2, float)
    mouth_world = start_2 - start_1
    width = np.linalg.norm(mouth_world)
    along_world = mouth_world / width
    trailing_world = np.array([-along_world[1], along_world[0]])
    middle_world = (start_1 + start_2) / 2.0
    if trailing_world @ (middle_world - np.asarray(debris, float)) < 0:
        trailing_world = -trailing_world
    positions_net = net.positions[:, :2] * [width / side_length, 1.0] + [0.0, side_length / 2.0]
    positions_world_xy = middle_world + positions_net[:, :1] * along_world + positions_net[:, 1:2] * trailing_world
    positions_world = np.c_[positions_world_xy, np.zeros(len(positions_world_xy))]
    return replace(net, positions=positions_world), np.arange(n) * n


def _unit_body(name, mass, position_world, velocity_world):
    inertia = 0.4 * mass * MU_RADIUS**2 * np.eye(3)
    return RigidBodySpec(name=name, mass=mass, inertia_body=inertia, com_lvlh=np.r_[position_world, 0.0],
                         velocity_lvlh=np.r_[velocity_world, 0.0])


class _TrackingLoad:
    """Exudyn load user function of one MU: feed-forward plus tracking force (N, world)."""

    def __init__(self, node, mass, spline, gains, log):
        # no reference to the system: Exudyn holds this function from C++, and one back to the system would be a
        # cycle the collector cannot see (multibody.impact.detach_step_functions)
        self.node, self.mass, self.spline, self.gains, self.log = node, mass, spline, gains, log

    def __call__(self, mbs, t, load):
        r_ref_world = np.r_[self.spline(t), 0.0]
        v_ref_world = np.r_[self.spline(t, 1), 0.0]
        a_ref_world = np.r_[self.spline(t, 2), 0.0]
        r_world = np.asarray(mbs.GetNodeOutput(self.node, exu.OutputVariableType.Position))
        v_world = np.asarray(mbs.GetNodeOutput(self.node, exu.OutputVariableType.Velocity))
        tracking_world = self.gains[0] * (r_ref_world - r_world) + self.gains[1] * (v_ref_world - v_world)
        self.log[0] = float(np.linalg.norm(tracking_world))
        return list(self.mass * a_ref_world + tracking_world)


def replay(t_plan, unit_paths, unit_masses, net_spec: dict, debris, keep_out_radius, step, output_rate=50.0):
    """Run the 3-D replay of a planned approach.

    Parameters
    ----------
    t_plan : (M,) float              Times of the planned path (s), from 0 to t_f.
    unit_paths : (2, 2, M) float     Planned MU positions (m), world x-y.
    unit_masses : (2,) float         Masses of the MU bodies (kg) (initial masses; constant here).
    net_spec : dict                  side_length, nodes_per_side, net_mass, axial_rigidity, damping,
                                     tracking_stiffness, tracking_damping.
    debris : (2,) float              Debris centre (m), world.
    keep_out_radius : float          (m), for the report only.
    step : float                     Explicit step (s).
    output_rate : float              Samples per second of the result (Hz).
    """
    splines = _reference(t_plan, unit_paths)
    net, mouth_nodes = replay_net(net_spec["side_length"], net_spec["nodes_per_side"], net_spec["net_mass"],
                                  net_spec["axial_rigidity"], net_spec["damping"], unit_paths[0][:, 0],
                                  unit_paths[1][:, 0], debris)
    bodies = [_unit_body(f"MU{k + 1}", unit_masses[k], unit_paths[k][:, 0], splines[k](0.0, 1)) for k in range(2)]
    corners = mouth_nodes[[0, -1]]
    assembly = ImpactAssembly(
        net=net, net_velocity=np.zeros((net.n_nodes, 3)), bodies=bodies, joints=[],
        contact=ContactLaw(stiffness=1.0), solver=SolverSpec(end_time=float(t_plan[-1]), step=step,
                                                                  # the sampler reads the net from Exudyn's node
                                                                  net_integration="exudyn"),
        mount=NetMount(nodes=corners, body=np.array([0, 1]), points_body=np.zeros((2, 3)),
                       stiffness=MOUNT_STIFFNESS, damping=MOUNT_DAMPING))
    built = build_impact_system(assembly)
    mbs = built.mbs
    logs = [[0.0], [0.0]]
    gains = (net_spec["tracking_stiffness"], net_spec["tracking_damping"])
    for k in range(2):
        marker = mbs.AddMarker(MarkerBodyPosition(bodyNumber=built.body_objects[k], localPosition=[0.0] * 3))
        mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVector=[0.0] * 3, loadVectorUserFunction=_TrackingLoad(
            built.body_nodes[k], unit_masses[k], splines[k], gains, logs[k])))
    mbs.Assemble()
    samples = _Sampler(mbs, built, net.n_nodes, mouth_nodes, logs, max(1, int(round(1.0 / (output_rate * step)))))
    # thrust-driven tracking: no closed energy balance, so the checks are a finite state and the solver's flag
    watch = HealthWatch(likely_failure_cause(assembly))
    mbs.SetPostStepUserFunction(checked_post_step(watch, samples))
    samples(mbs, 0.0)
    try:
        solve_checked(mbs, simulation_settings(assembly), INTEGRATORS[assembly.solver.integrator][0], watch)
    finally:
        detach_step_functions(mbs)     # the sampler holds the built system: freed with it once the replay is over
    samples(mbs, float(t_plan[-1]), force=True)
    return samples.result(debris, keep_out_radius)


class _Sampler:
    """Post-step function recording MU positions, the mouth edge and the tracking forces."""

    def __init__(self, mbs, built, n_nodes, mouth_nodes, logs, every):
        self.built, self.n_nodes, self.mouth_nodes, self.logs, self.every = built, n_nodes, mouth_nodes, logs, every
        self.count = 0
        self.time, self.units, self.edge, self.force = [], [], [], []

    def __call__(self, mbs, t, force=False):
        self.count += 1
        if not force and self.count % self.every:
            return True
        if self.time and abs(t - self.time[-1]) < 1e-12:
            return True
        q = np.asarray(self.built.mbs.GetNodeOutput(self.built.net_node, exu.OutputVariableType.Coordinates))
        reference = np.asarray(self.built.mbs.GetNodeParameter(self.built.net_node, "referenceCoordinates"))
        nodes_world = (reference + q).reshape(-1, 3)
        self.time.append(t)
        self.edge.append(nodes_world[self.mouth_nodes])
        self.units.append([self.built.mbs.GetNodeOutput(n, exu.OutputVariableType.Position)
                           for n in self.built.body_nodes])
        self.force.append([log[0] for log in self.logs])
        return True

    def result(self, debris, keep_out_radius) -> ReplayResult:
        unit_positions_world, edge_world = np.array(self.units), np.array(self.edge)
        debris_world = np.r_[debris, 0.0]
        chord_mid_world = unit_positions_world.mean(axis=1)
        distance = np.linalg.norm(unit_positions_world - debris_world, axis=2)
        middle_world = edge_world[:, len(self.mouth_nodes) // 2]
        summary = {"final_mouth_chord_center_distance_m":
                   float(np.linalg.norm(chord_mid_world[-1] - debris_world)),
                   "final_mouth_edge_middle_node_distance_m": float(np.linalg.norm(middle_world[-1] - debris_world)),
                   "min_unit_debris_distance_m": float(distance.min()),
                   "keep_out_respected": bool(distance.min() >= keep_out_radius),
                   "max_tracking_force_N": float(np.max(self.force)),
                   "final_time_s": float(self.time[-1])}
        return ReplayResult(np.array(self.time), unit_positions_world, edge_world, np.array(self.force), summary)
