"""Shared physical set-ups for the tests (SI units)."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.health import HealthWatch
from multibody.impact import ImpactSimulation
from multibody.net import NetTopology, flat_square_net, single_node_net

#: Seed paper Table 1/2 values used by several tests.
KEVLAR_NODE_MASS = 0.0077      # kg, 35 x 35 Kevlar net node (paper Sec. 3.1, thread mass spread)
PAPER_CONTACT_STIFFNESS = 1.622e8  # N/m^1.5, paper Table 2


def single_node(position, velocity, mass=KEVLAR_NODE_MASS, radius=0.001) -> NetTopology:
    """A 'net' of one free node: no threads."""
    return single_node_net(position, mass, radius)


def run_unwatched(assembly):
    """Run ``assembly`` with the numerical health check off: for tests whose subject is the energy balance
    itself (a check that stopped the run would hide what they measure). Returns (simulation, recording)."""
    simulation = ImpactSimulation(assembly)
    simulation.health = HealthWatch("", None)
    return simulation, simulation.run()


def wall_body(center=(0.0, 1.0, 0.0), size=2.0, mass=1e12) -> RigidBodySpec:
    """A box so heavy that it acts as a fixed plane for a 7.7 g node (face at y = center - size/2)."""
    return RigidBodySpec(name="wall", mass=mass, inertia_body=np.eye(3) * mass * size**2 / 6,
                         com_lvlh=np.asarray(center, float), meshes_body=[trimesh.creation.box(extents=[size] * 3)])


@pytest.fixture
def node_strikes_plane():
    """Build a single node hitting a fixed plane normally at ``speed``; Hertz n = 1.5."""

    def build(speed, alpha, step, contact_substep, end_time=4e-4, stiffness=PAPER_CONTACT_STIFFNESS):
        end_time += 2.5 * step
        # Start 2.5 steps before touching: the first Verlet drift precedes any sub-cycled kick.
        net = single_node([0.0, -0.001 - 2.5 * speed * step, 0.0], [0.0, speed, 0.0])
        return ImpactAssembly(
            net=net, net_velocity=np.array([[0.0, speed, 0.0]]), bodies=[wall_body()], joints=[],
            contact=ContactLaw(stiffness=stiffness, exponent=1.5, hunt_crossley_alpha=alpha,
                               mu_static=0.0, mu_kinetic=0.0),
            solver=SolverSpec(end_time=end_time, step=step, output_rate=1.0 / step, net_output_rate=1.0 / step,
                              contact_substep=contact_substep))

    return build


@pytest.fixture
def small_net_on_box():
    """A 7 x 7 node, 6 m net at 10 m/s onto a free 200 kg box with friction; no orbit.

    Returns a builder taking the thread damping (N s/m) and contact alpha (s/m).
    """

    def build(thread_damping=1.58, alpha=0.05, end_time=0.6, step=1e-4, mu=(0.19, 0.152)):
        net = flat_square_net(center=[0.3, -1.5, 0.2], direction=[0, 1, 0], side_length=6.0, nodes_per_side=7,
                              node_mass=0.05, node_radius=0.001, thread_axial_rigidity=62308.25 * 0.8824,
                              thread_damping=thread_damping, bullet_mass=0.5, bullet_radius=0.01,
                              bullet_tether_length=1.0)
        box = RigidBodySpec(name="box", mass=200.0, inertia_body=np.diag([30.0, 40.0, 50.0]),
                            com_lvlh=np.zeros(3), omega_body=np.array([0.0, 0.0, 0.3]),
                            meshes_body=[trimesh.creation.box(extents=[2.0, 1.0, 1.5])])
        velocity = np.tile([0.0, 10.0, 0.0], (net.n_nodes, 1))
        return ImpactAssembly(
            net=net, net_velocity=velocity, bodies=[box], joints=[],
            contact=ContactLaw(stiffness=PAPER_CONTACT_STIFFNESS, hunt_crossley_alpha=alpha,
                               mu_static=mu[0], mu_kinetic=mu[1]),
            solver=SolverSpec(end_time=end_time, step=step, output_rate=1000.0, net_output_rate=50.0))

    return build
