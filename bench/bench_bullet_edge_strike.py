"""A bullet striking beside the box edge its tether wraps: the energy balance of the threads' contact there.

    python3 bench/bench_bullet_edge_strike.py [--steps 1e-4,1e-5] [--keys off,on]

The reference case's key-on gain at 3.22 s rebuilt (helper keyon19, docs/model.md "The key-on contact's gain"): bullet
1226 (1.786 kg, 1 cm) strikes the main body's -x face at 20.9 m/s beside its bottom edge (x = -1.6875, z = -3.9375 m;
the 3.375 x 3.75 x 7.875 m box, fixed: 1e12 kg) while its tether (0.8824 m, to corner node 34, 7.76 g, 1 mm) runs
round that edge, the tether's line a few millimetres inside the box's corner. States: the run's (key on, contact
sub-step 5e-7 s), body frame, 0.25 ms before the bullet touches. The tether's spring is off (``--tether-stiffness``),
so the contact is the only force. For each key setting, step and law (none: no damping, no friction; the case's:
Hunt-Crossley alpha 0.05 s/m, mu 0.19 / 0.152) the bench prints the energy balance (kinetic + thread + contact
elastic + booked dissipation) at the end (3 ms, the contact over) against the launch energy, its largest excursion,
and the kinetic energy left. The health check's energy limit is lifted so a drifting set-up is measured.
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.impact import ImpactSimulation
from multibody.net import NetTopology

#: The seed paper's contact stiffness (N/m^1.5) [paper T2].
STIFFNESS = 1.622e8
#: Bullet 1226 and node 34 of the reference run at 3.2189 s (m, m/s; main body frame), key on, sub-step 5e-7 s.
BULLET, BULLET_VELOCITY = np.array([-1.699, 1.5684, -3.9379]), np.array([20.9, 3.73, 12.53])
NODE, NODE_VELOCITY = np.array([-1.5304, 0.7025, -4.0166]), np.array([20.56, 5.03, 10.7])
#: The reference case's main body box (m) [cases/envisat_net_impact.toml].
BOX = np.array([3.375, 3.75, 7.875])


def strike(thread_segments: bool, step: float, alpha: float, mu: float, tether_stiffness: float = 0.0,
           end_time: float = 3e-3) -> dict:
    """The recorded series of the bullet's strike beside the edge (module doc).

    Parameters
    ----------
    thread_segments : bool
        The case key contact.thread_segments.
    step : float
        Integrator step (s).
    alpha, mu : float
        Hunt-Crossley alpha (s/m) and static friction coefficient (-; kinetic 0.8 of it, as the paper's 0.152/0.19).
    tether_stiffness : float
        The tether's axial stiffness (N/m); its damping is off.
    end_time : float
        (s)
    """
    back = 2.5 * step
    net = NetTopology(positions=np.array([BULLET - back * BULLET_VELOCITY, NODE - back * NODE_VELOCITY]),
                      masses=np.array([1.786, 0.00776]), radii=np.array([0.01, 0.001]), threads=np.array([[0, 1]]),
                      rest_lengths=np.array([0.8824]), stiffness=np.array([tether_stiffness]), damping=np.zeros(1),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    mass = 1e12
    inertia = mass / 12.0 * np.diag([BOX[1] ** 2 + BOX[2] ** 2, BOX[0] ** 2 + BOX[2] ** 2, BOX[0] ** 2 + BOX[1] ** 2])
    box = RigidBodySpec(name="main_body", mass=mass, inertia_body=inertia, com_lvlh=np.zeros(3),
                        meshes_body=[trimesh.creation.box(extents=BOX)])
    assembly = ImpactAssembly(
        net=net, net_velocity=np.array([BULLET_VELOCITY, NODE_VELOCITY]), bodies=[box], joints=[],
        contact=ContactLaw(stiffness=STIFFNESS, hunt_crossley_alpha=alpha, mu_static=mu, mu_kinetic=0.8 * mu,
                           thread_segments=thread_segments),
        solver=SolverSpec(end_time=end_time, step=step, output_rate=1.0 / step, net_output_rate=1.0 / step,
                          implicit_contact_speed=0.15))
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    return simulation.run().series


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", default="1e-4,1e-5")
    parser.add_argument("--keys", default="off,on")
    parser.add_argument("--tether-stiffness", type=float, default=0.0)
    args = parser.parse_args(argv)
    for key in args.keys.split(","):
        for step in (float(v) for v in args.steps.split(",")):
            for law, (alpha, mu) in (("none", (0.0, 0.0)), ("case's", (0.05, 0.19))):
                start = time.process_time()
                series = strike(key == "on", step, alpha, mu, args.tether_stiffness)
                e = series["energy_total"]
                print(f"key {key:3s} step {step:.0e} s, law {law:6s}: launch {e[0]:.2f} J, balance at the end "
                      f"{e[-1] - e[0]:+.3f} J ({100 * (e[-1] - e[0]) / e[0]:+.2f} %), largest "
                      f"{np.max(np.abs(e - e[0])):.3f} J; kinetic left {series['energy_net_kinetic'][-1]:.2f} J, "
                      f"dissipated {series['energy_dissipated_contact'][-1]:.2f} J; CPU "
                      f"{time.process_time() - start:.1f} s, load {os.getloadavg()[0]:.1f}", flush=True)


if __name__ == "__main__":
    main()
