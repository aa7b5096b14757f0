"""One thread striking a fixed plate: the energy balance of the threads' contact (``contact.thread_segments``).

    python3 bench/bench_thread_strike_energy.py [--speed V] [--steps 1e-4,5e-5] [--keys off,on]

Each set-up is one thread of envisat_small (two 42.2 g nodes, 62 308 N/m, 1 mm radius) falling flat at ``--speed``
onto a fixed (1e12 kg) 0.4 x 0.05 x 0.4 m plate whose face is at y = -0.025 m: both nodes beside the plate with it
under the thread's middle ("flat, s = 0.5") or off it ("flat, s = 0.625"), or one node over the face and the other
0.3 m or 0.85 m beyond its edge ("edge"). For each step and key setting the bench prints the energy balance
(kinetic + thread + contact elastic + dissipation the contacts book) against the launch energy: the largest drift
and the drift at the end (4 ms, the contact over), the kinetic energy left against the launch's and, with the key
on, the thread contact's own record: the energy made between steps (its contact energy at each step's start less
what its sub-cycle ended the last step with, summed: ``SegmentBuffers.energy_jump``) and the energy it booked as
dissipated. The health check's energy limit is lifted here so a drifting set-up is measured, not refused
(docs/model.md, "Contact", "Where the strike's energy came from").
"""
from __future__ import annotations

import argparse
import os

import numpy as np
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.impact import ImpactSimulation
from multibody.net import NetTopology

#: The seed paper's contact stiffness (N/m^1.5) [paper T2], as tests/conftest.py.
STIFFNESS = 1.622e8
#: name: (x of node a, x of node b) (m); the plate spans x in [-0.2, 0.2]
SETUPS = {"flat, s = 0.5": (-0.5, 0.5), "flat, s = 0.625": (-0.5, 0.3), "edge, 0.3 m beyond": (-0.1, 0.5),
          "edge, 0.85 m beyond": (-0.15, 1.0)}


def fixed_plate() -> RigidBodySpec:
    """A 0.4 x 0.05 x 0.4 m plate of 1e12 kg centred at the LVLH origin (its face at y = -0.025 m): it does not move
    under a thread's strike."""
    extents, mass = np.array([0.4, 0.05, 0.4]), 1e12
    inertia = mass / 12.0 * np.diag([extents[1] ** 2 + extents[2] ** 2, extents[0] ** 2 + extents[2] ** 2,
                                     extents[0] ** 2 + extents[1] ** 2])
    return RigidBodySpec(name="plate", mass=mass, inertia_body=inertia, com_lvlh=np.zeros(3),
                         meshes_body=[trimesh.creation.box(extents=extents)])


def strike(x_a: float, x_b: float, speed: float, step: float, thread_segments: bool, end_time: float = 4e-3):
    """The recorded series of one thread (nodes at x_a, x_b, m) falling flat at ``speed`` (m/s) onto the plate,
    its surface 2.5 steps of flight from the face at the start, and the thread contact's buffers
    (:class:`multibody.contact_segment.SegmentBuffers`: its per-thread energy record)."""
    y0 = -0.025 - 0.001 - 2.5 * speed * step
    positions = np.array([[x_a, y0, 0.0], [x_b, y0, 0.0]])
    net = NetTopology(positions=positions, masses=np.full(2, 0.04223), radii=np.full(2, 0.001),
                      threads=np.array([[0, 1]]), rest_lengths=np.array([abs(x_b - x_a)]),
                      stiffness=np.array([62308.25]), damping=np.array([1.58]),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    assembly = ImpactAssembly(
        net=net, net_velocity=np.array([[0.0, speed, 0.0]] * 2), bodies=[fixed_plate()], joints=[],
        contact=ContactLaw(stiffness=STIFFNESS, hunt_crossley_alpha=0.05, mu_static=0.19, mu_kinetic=0.152,
                           thread_segments=thread_segments),
        solver=SolverSpec(end_time=end_time, step=step, output_rate=1.0 / step, net_output_rate=1000.0,
                          implicit_contact_speed=0.15))
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    series = simulation.run().series
    return series, simulation.system.kernel.buffers.segments


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed", type=float, default=20.0)
    parser.add_argument("--steps", default="1e-4")
    parser.add_argument("--keys", default="off,on")
    args = parser.parse_args(argv)
    print(f"one thread onto a fixed plate at {args.speed:g} m/s; load {os.getloadavg()[0]:.1f}", flush=True)
    for name, (x_a, x_b) in SETUPS.items():
        for step in (float(s) for s in args.steps.split(",")):
            for key in args.keys.split(","):
                series, segments = strike(x_a, x_b, args.speed, step, key == "on")
                launch = series["energy_net_kinetic"][0]
                drift = (series["energy_total"] - series["energy_total"][0]) / launch
                print(f"{name:22s} step {step:.1e} s  thread_segments {key:3s}: drift largest {100 * drift.max():+7.2f} %"
                      f", at the end {100 * drift[-1]:+7.3f} %; kinetic energy left "
                      f"{series['energy_net_kinetic'][-1] / launch:.3f} of the launch's"
                      + (f"; the thread contact made {100 * segments.energy_jump.sum() / launch:+.3f} % between steps, "
                         f"dissipated {100 * segments.dissipated.sum() / launch:.2f} %" if key == "on" else ""),
                      flush=True)


if __name__ == "__main__":
    main()
