"""A net node, or a thread, pinched between two free rigid plates closing on it: the energy balance and the momentum.

    python3 bench/bench_pinch.py [--steps 1e-4,5e-5,2.5e-5]

Helper pinch21 (issue 23; docs/model.md, "A net pinched between two bodies"; docs/structures.md, sample 9). Two scenes
with a known answer (no orbit: momentum conserved; kinetic + contact elastic + booked dissipation constant up to the
integration error):

- the node pinch (:func:`node_pinch`): one 42.2 g node between two plates closing on it (10 kg at +0.5 m/s, 20 kg at
  -0.2 m/s), printed: the balance's largest change, the plates' end velocities along y, the momentum's changes;
- the thread pinch (:func:`thread_pinch`): a 0.4 m thread across two 1000 kg bars closing on its middle at 0.01 m/s
  each (Envisat sample 9's pinch: about 500 N on a thread point), bars face to face or 2 cm apart along the thread,
  with and without Hunt-Crossley damping, printed: the booked contact dissipation and the balance's change;
- the shared-node pinch (:func:`shared_node_pinch`, helper cluster22): the thread pinch with a tether from its node to
  a bullet, on bar b only (sample 9's tether 423), the companion threads off (main before cluster22) and on, printed:
  the booked contact dissipation, the balance's change and the momentum's.

Prints the CPU time of each run and the load.
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

#: The seed paper's contact stiffness (N/m^1.5) [paper T2]; the reduced net's node mass (kg) and thread (N/m).
CONTACT_STIFFNESS, NODE_MASS, THREAD_STIFFNESS = 1.622e8, 0.04223, 62308.25
NODE_RADIUS = 0.001     # m, the net's node and thread contact radius
BULLET_MASS = 5.0       # kg, the shared-node scene's bullet (a heavy end: the tether stays on bar b)
PLATE_HALF = 0.025      # m, half the plates' thickness along y


def plate(name: str, extents, com_lvlh, velocity_lvlh, mass: float) -> RigidBodySpec:
    """A free box of ``extents`` (m) and ``mass`` (kg) at ``com_lvlh`` (m) moving at ``velocity_lvlh`` (m/s)."""
    extents = np.asarray(extents, float)
    inertia = mass / 12.0 * np.diag([extents[1] ** 2 + extents[2] ** 2, extents[0] ** 2 + extents[2] ** 2,
                                     extents[0] ** 2 + extents[1] ** 2])
    return RigidBodySpec(name=name, mass=mass, inertia_body=inertia, com_lvlh=np.asarray(com_lvlh, float),
                         velocity_lvlh=np.asarray(velocity_lvlh, float), meshes_body=[trimesh.creation.box(extents=extents)])


def run(net: NetTopology, bodies, step: float, end_time: float, alpha: float, mu: float, thread_segments: bool,
        net_velocity=None, companions: bool = True):
    """The recorded series of ``net`` (at rest, or at ``net_velocity`` (n, 3) m/s) and ``bodies`` under the paper's
    contact law with Hunt-Crossley ``alpha`` (s/m) and friction ``mu``, every sample (the health check's refusal off:
    the balance is measured); ``companions`` False: a box's cluster does not follow the threads on other boxes only
    that share its nodes (main before helper cluster22: :func:`multibody.contact_segment._companion_threads`)."""
    assembly = ImpactAssembly(
        net=net, net_velocity=np.zeros((len(net.masses), 3)) if net_velocity is None else net_velocity, bodies=bodies,
        joints=[], contact=ContactLaw(stiffness=CONTACT_STIFFNESS, hunt_crossley_alpha=alpha, mu_static=mu,
                                      mu_kinetic=0.8 * mu, thread_segments=thread_segments),
        solver=SolverSpec(end_time=end_time, step=step, output_rate=1.0 / step, net_output_rate=100.0,
                          implicit_contact_speed=0.15))
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None
    if thread_segments:
        simulation.system.kernel.buffers.segments.companions[0] = int(companions)
    return simulation.run().series


def node_pinch(step: float, alpha: float = 0.0, mu: float = 0.0):
    """One free node (42.2 g, 1 mm radius) between two plates 2 mm apart closing on it: plate a (10 kg) at +0.5 m/s
    and 3 cm off the node along x, plate b (20 kg) at -0.2 m/s with a 0.1 m/s slide along z (a second node, 5 m
    away on a slack 10 m thread, keeps the net a net: the thread never pulls)."""
    net = NetTopology(positions=np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]]), masses=np.full(2, NODE_MASS),
                      radii=np.full(2, NODE_RADIUS), threads=np.array([[0, 1]]), rest_lengths=np.array([10.0]),
                      stiffness=np.array([THREAD_STIFFNESS]), damping=np.array([0.0]),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    y = NODE_RADIUS + 0.001 + PLATE_HALF
    bodies = [plate("a", [0.4, 0.05, 0.4], [0.03, -y, 0.0], [0.0, 0.5, 0.0], 10.0),
              plate("b", [0.4, 0.05, 0.4], [0.0, y, 0.0], [0.0, -0.2, 0.1], 20.0)]
    return run(net, bodies, step, 0.03, alpha, mu, thread_segments=False)


def thread_pinch(step: float, alpha: float, offset: float):
    """One thread (0.4 m, two 42.2 g nodes) across two 5 cm wide bars of 1000 kg closing on its middle at 0.01 m/s
    each, 1 mm apart at the start, bar b ``offset`` (m) along the thread from bar a: the nodes stay clear of both
    bars, only the thread's interior is squeezed (Envisat sample 9's pinch: about 500 N on a thread point)."""
    net = NetTopology(positions=np.array([[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0]]), masses=np.full(2, NODE_MASS),
                      radii=np.full(2, NODE_RADIUS), threads=np.array([[0, 1]]), rest_lengths=np.array([0.4]),
                      stiffness=np.array([THREAD_STIFFNESS]), damping=np.array([0.0]),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    y = NODE_RADIUS + 0.0005 + PLATE_HALF
    bodies = [plate("a", [0.05, 0.05, 0.4], [-offset / 2, -y, 0.0], [0.0, 0.01, 0.0], 1000.0),
              plate("b", [0.05, 0.05, 0.4], [offset / 2, y, 0.0], [0.0, -0.01, 0.0], 1000.0)]
    return run(net, bodies, step, 0.1, alpha, 0.0, thread_segments=True)


def shared_node_pinch(step: float, alpha: float, companions: bool = True):
    """The thread pinch of :func:`thread_pinch` (bars face to face) with a second thread sharing node 1 and touching
    bar b only (Envisat sample 9's tether 423 from node 224 to bullet 228, on the ASAR alone): from node 1 at
    (0.2, 0, 0) m to a 5 kg bullet at (-0.2, 0, 0.6) m; it crosses bar b (0.8 m long along z) at z = 0.26-0.34 m,
    where bar a (0.4 m) is not, 0.5 mm from its face as the first thread. Bar b meets both threads at 50 ms; the second
    lies on bar b alone for 15 ms of the first's pinch (149 steps at 1e-4 s), pushed off by it after that."""
    positions = np.array([[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], [-0.2, 0.0, 0.6]])
    lengths = np.linalg.norm(positions[[1, 2]] - positions[[0, 1]], axis=1)
    net = NetTopology(positions=positions, masses=np.array([NODE_MASS, NODE_MASS, BULLET_MASS]),
                      radii=np.full(3, NODE_RADIUS), threads=np.array([[0, 1], [1, 2]]), rest_lengths=lengths,
                      stiffness=np.full(2, THREAD_STIFFNESS), damping=np.zeros(2),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    y = NODE_RADIUS + 0.0005 + PLATE_HALF
    bodies = [plate("a", [0.05, 0.05, 0.4], [0.0, -y, 0.0], [0.0, 0.01, 0.0], 1000.0),
              plate("b", [0.05, 0.05, 0.8], [0.0, y, 0.0], [0.0, -0.01, 0.0], 1000.0)]
    return run(net, bodies, step, 0.1, alpha, 0.0, thread_segments=True, companions=companions)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", default="1e-4,5e-5,2.5e-5")
    args = parser.parse_args(argv)
    steps = [float(v) for v in args.steps.split(",")]
    for alpha in (0.0, 0.05):
        for step in steps:
            start = time.process_time()
            s = node_pinch(step, alpha, 0.19 if alpha > 0.0 else 0.0)
            total, p, h = s["energy_total"], s["momentum_linear_lvlh"], s["momentum_angular_lvlh"]
            print(f"node pinch, alpha {alpha} s/m, step {step:.1e} s: start {total[0]:.4f} J, balance's largest change "
                  f"{np.max(np.abs(total - total[0])):.3e} J, booked {s['energy_dissipated_contact'][-1]:.4f} J, plates' "
                  f"end v_y {s['body_velocity_lvlh'][-1, 0, 1]:+.5f} / {s['body_velocity_lvlh'][-1, 1, 1]:+.5f} m/s, "
                  f"momentum change {np.max(np.abs(p - p[0])):.1e} N s, {np.max(np.abs(h - h[0])):.1e} N m s; "
                  f"CPU {time.process_time() - start:.1f} s, load {os.getloadavg()[0]:.1f}", flush=True)
    for offset in (0.0, 0.02):
        for alpha in (0.0, 0.05):
            for step in steps:
                start = time.process_time()
                s = thread_pinch(step, alpha, offset)
                total = s["energy_total"]
                print(f"thread pinch, offset {offset} m, alpha {alpha} s/m, step {step:.1e} s: start {total[0]:.4f} J, "
                      f"booked {s['energy_dissipated_contact'][-1]:.2e} J, balance's change {total[-1] - total[0]:+.2e} J "
                      f"(largest {np.max(np.abs(total - total[0])):.2e}), peak force "
                      f"{np.abs(s['contact_force_lvlh'][:, 0, 1]).max():.0f} N; CPU {time.process_time() - start:.1f} s, "
                      f"load {os.getloadavg()[0]:.1f}", flush=True)
    for companions in (False, True):
        for alpha in (0.0, 0.05):
            for step in steps:
                start = time.process_time()
                s = shared_node_pinch(step, alpha, companions)
                total = s["energy_total"]
                p, h = s["momentum_linear_lvlh"], s["momentum_angular_lvlh"]
                print(f"shared-node pinch, companions {companions}, alpha {alpha} s/m, step {step:.1e} s: start "
                      f"{total[0]:.4f} J, booked {s['energy_dissipated_contact'][-1]:.2e} J, balance's change "
                      f"{total[-1] - total[0]:+.2e} J (largest {np.max(np.abs(total - total[0])):.2e}), momentum change "
                      f"{np.max(np.abs(p - p[0])):.1e} N s, {np.max(np.abs(h - h[0])):.1e} N m s; "
                      f"CPU {time.process_time() - start:.1f} s, load {os.getloadavg()[0]:.1f}", flush=True)

if __name__ == "__main__":
    main()
