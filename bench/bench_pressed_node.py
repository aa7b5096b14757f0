"""A net node pressed into a plate's face by its thread for a long time: the energy the sub-cycled contact makes.

    python3 bench/bench_pressed_node.py [--depths 0.3e-3,1e-3] [--steps 1e-4,5e-5,2.5e-5]

Exploratory (helper keyon19, docs/model.md "The key-on contact's gain"): one 7.76 g node (1 mm radius) starts 2 mm in
front of a fixed 5 cm plate's face, pulled into it by one thread (62 308 N/m, 1.58 N s/m: the reference net's) to a
1e9 kg anchor behind the plate (key off: the thread passes through it freely), pre-stretched so that the node comes to
rest pressed ``depth`` into the face (the preload k_c depth^1.5). The contact law has no damping or friction, so the
balance (kinetic + thread + contact elastic + the threads' booked dissipation) should stay at its start; printed: its
change over 0.2 s, the threads' dissipation, and h omega_c, the step times the contact's small-oscillation frequency
sqrt(1.5 k_c depth^0.5 / m) at that depth (the sub-cycle integrates the contact, the thread's force is held over each
step: a multiple-time-step split). Not a case: the preloads (0.8-5 kN on one node) are far above the reference net's.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from multibody.assembly import ContactLaw, ImpactAssembly, SolverSpec
from multibody.impact import ImpactSimulation
from multibody.net import NetTopology

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_thread_strike_energy import fixed_plate  # noqa: E402

#: The seed paper's contact stiffness (N/m^1.5) [paper T2]; the reference net's node mass (kg) and thread (N/m).
CONTACT_STIFFNESS, NODE_MASS, THREAD_STIFFNESS = 1.622e8, 0.00776, 62308.25


def pressed_node(depth: float, step: float, implicit_speed: float = 0.15, end_time: float = 0.2) -> dict:
    """The recorded series of the node pressed ``depth`` (m) into the face, integrated at ``step`` (s); contacts slower
    than ``implicit_speed`` (m/s) take the node contact's implicit step (0: every contact sub-cycled)."""
    stretch = CONTACT_STIFFNESS * depth ** 1.5 / THREAD_STIFFNESS     # the thread's stretch at rest (m)
    y_node, anchor = -0.025 - 0.001 - 0.002, np.array([0.0, 0.5, 0.0])
    net = NetTopology(positions=np.array([[0.0, y_node, 0.0], anchor]), masses=np.array([NODE_MASS, 1e9]),
                      radii=np.full(2, 0.001), threads=np.array([[0, 1]]),
                      rest_lengths=np.array([anchor[1] - y_node - 0.002 - depth - stretch]),
                      stiffness=np.array([THREAD_STIFFNESS]), damping=np.array([1.58]),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    assembly = ImpactAssembly(
        net=net, net_velocity=np.zeros((2, 3)), bodies=[fixed_plate()], joints=[],
        contact=ContactLaw(stiffness=CONTACT_STIFFNESS, hunt_crossley_alpha=0.0, mu_static=0.0, mu_kinetic=0.0),
        solver=SolverSpec(end_time=end_time, step=step, output_rate=1000.0, net_output_rate=100.0,
                          implicit_contact_speed=implicit_speed))
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    return simulation.run().series


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="0.3e-3,1e-3")
    parser.add_argument("--steps", default="1e-4,5e-5,2.5e-5")
    parser.add_argument("--implicit-speed", type=float, default=0.15, help="m/s; 0: every contact sub-cycled")
    args = parser.parse_args(argv)
    for step in (float(v) for v in args.steps.split(",")):
        for depth in (float(v) for v in args.depths.split(",")):
            start = time.process_time()
            series = pressed_node(depth, step, args.implicit_speed)
            e = series["energy_total"]
            omega = np.sqrt(1.5 * CONTACT_STIFFNESS * depth ** 0.5 / NODE_MASS)
            print(f"implicit below {args.implicit_speed} m/s, step {step:.1e} s, depth {1e3 * depth:.1f} mm (preload {CONTACT_STIFFNESS * depth ** 1.5:.0f} N, "
                  f"h omega_c {step * omega:.2f}): start {e[0]:.2f} J, made over 0.2 s {e[-1] - e[0]:+.3f} J, threads "
                  f"dissipated {series['energy_dissipated_threads'][-1]:.3f} J; CPU {time.process_time() - start:.1f} s, "
                  f"load {os.getloadavg()[0]:.1f}", flush=True)


if __name__ == "__main__":
    main()
