"""Energy balance of a fast thread-connected impact against the integrator step.

A 15 x 15 net of 7.8 g nodes (8 m, the reference case's node mass and thread stiffness)
hits a free 2000 kg box at 20 m/s. Prints, per step, the booked energy balance drift
(largest over the run and at the end), relative to the initial energy.

Usage: python3 bench/energy_growth.py [--steps 1e-4 5e-5 2.5e-5] [--end-time 2] [--no-friction]
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.impact import ImpactSimulation
from multibody.net import flat_square_net


def assembly(step, end_time, friction, speed):
    net = flat_square_net(center=[0.0, -1.5, 0.0], direction=[0, 1, 0], side_length=8.0, nodes_per_side=15,
                          node_mass=0.0078, node_radius=0.001, thread_axial_rigidity=62308.25 * 8.0 / 14,
                          thread_damping=1.58, bullet_mass=1.786, bullet_radius=0.05, bullet_tether_length=1.5)
    box = RigidBodySpec(name="box", mass=2000.0, inertia_body=np.diag([500.0, 700.0, 900.0]),
                        com_lvlh=np.zeros(3), meshes_body=[trimesh.creation.box(extents=[2.0, 1.0, 1.5])])
    mu = (0.19, 0.152) if friction else (0.0, 0.0)
    return ImpactAssembly(
        net=net, net_velocity=np.tile([0.0, speed, 0.0], (net.n_nodes, 1)), bodies=[box], joints=[],
        contact=ContactLaw(stiffness=1.622e8, hunt_crossley_alpha=0.05, mu_static=mu[0], mu_kinetic=mu[1]),
        solver=SolverSpec(end_time=end_time, step=step, output_rate=1000.0, net_output_rate=10.0))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--steps", type=float, nargs="+", default=[1e-4, 5e-5, 2.5e-5])
    parser.add_argument("--end-time", type=float, default=2.0)
    parser.add_argument("--speed", type=float, default=20.0)
    parser.add_argument("--no-friction", action="store_true")
    args = parser.parse_args()
    print(f"{'step (s)':>10} {'max drift':>10} {'end drift':>10} {'wall (s)':>9}")
    for step in args.steps:
        t0 = time.perf_counter()
        rec = ImpactSimulation(assembly(step, args.end_time, not args.no_friction, args.speed)).run()
        e = rec.series["energy_total"]
        drift = (e - e[0]) / e[0]
        print(f"{step:10.2e} {np.abs(drift).max():10.2%} {drift[-1]:10.2%} {time.perf_counter() - t0:9.1f}")


if __name__ == "__main__":
    main()
