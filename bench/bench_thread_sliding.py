"""A taut thread sliding along a plate's edge under a constant load: the friction work against the dissipation booked.

    python3 bench/bench_thread_sliding.py [--speed V] [--steps 1e-4,5e-5] [--end-time T] [--keys on,off]
                                          [--node-on-face] [--implicit-speed 0.15]

The scene of tests/multibody/test_contact_segment.py's taut thread (helper thread12): light nodes a and c (0.04 kg)
joined by a 0.55 m thread in front of a fixed 5 cm plate's edge face (the plate spans x -0.025..0.025 m, y 0..1 m,
z -1..1 m), each pulled back over the edge by a 0.85 m thread to an anchor behind it (1e9 kg nodes). The anchors
move along the edge (z) at ``--speed``: the light nodes are dragged along, the thread a-c slides on the edge face
pressed by the anchor threads' pull (about 28 N, constant while the anchors are far), and friction does work at
the rate mu(slip) N slip. With ``--node-on-face`` a third light node sits in the middle of the thread a-c, so the
edge face carries that node's own contact (node contact) besides the two threads'.

For each step and key the bench prints, over the run and over its second half (the slide steady):
the energy balance's drift (kinetic + thread elastic + contact elastic + dissipated; the anchors' kinetic energy
included, so the drift is the energy made or lost), against the friction work measured from the recorded contact
force on the plate (the power -F_plate . v_slip summed over the output samples, v_slip the light nodes' mean speed
along z: every contact force on the plate acts at a point sliding at that speed in steady state), the energy the
contacts booked as dissipated, and the thread contact's own record (energy made between steps).
Helper thread14 (docs/model.md, "Contact", the threads' steady loss during the wrapping).
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

#: The seed paper's contact stiffness (N/m^1.5) [paper T2], as tests/conftest.py.
STIFFNESS = 1.622e8
#: The anchors' mass (kg): they keep their speed (their kinetic energy pays the friction work).
ANCHOR_MASS = 1e9
#: The light nodes' mass (kg).
LIGHT_MASS = 0.04


def sliding_thread(speed: float, step: float, thread_segments: bool, end_time: float = 0.6,
                   node_on_face: bool = False, mu=(0.19, 0.152), alpha: float = 0.05,
                   implicit_speed: float = 0.15):
    """The taut thread of the module doc dragged along the plate's edge at ``speed`` (m/s, the anchors' along z).

    Returns the recorded run (series sampled every step, net snapshots every millisecond) and the thread contact's
    buffers (:class:`multibody.contact_segment.SegmentBuffers`).
    """
    z0 = -0.8
    light = [[-0.3, -0.05, z0], [0.3, -0.05, z0]]
    threads, rest = [[0, 1], [1, 2], [2, 3]], [0.85, 0.55, 0.85]
    if node_on_face:
        light = [[-0.3, -0.05, z0], [0.0, -0.05, z0], [0.3, -0.05, z0]]
        threads, rest = [[0, 1], [1, 2], [2, 3], [3, 4]], [0.85, 0.275, 0.275, 0.85]
    positions = np.array([[-1.0, 0.6, z0]] + light + [[1.0, 0.6, z0]])
    n = len(positions)
    masses = np.full(n, LIGHT_MASS)
    masses[[0, -1]] = ANCHOR_MASS
    m = len(threads)
    net = NetTopology(positions=positions, masses=masses, radii=np.full(n, 0.001), threads=np.array(threads, np.int64),
                      rest_lengths=np.array(rest), stiffness=np.full(m, 1000.0),
                      damping=np.full(m, 10.0),  # near the critical 12.6 N s/m of a 0.04 kg node on 1000 N/m
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0,
                      n_bullets=0)
    extents, plate_mass = np.array([0.05, 1.0, 2.0]), 1e12
    inertia = plate_mass / 12.0 * np.diag([extents[1] ** 2 + extents[2] ** 2, extents[0] ** 2 + extents[2] ** 2,
                                           extents[0] ** 2 + extents[1] ** 2])
    plate = RigidBodySpec(name="plate", mass=plate_mass, inertia_body=inertia, com_lvlh=np.array([0.0, 0.5, 0.0]),
                          meshes_body=[trimesh.creation.box(extents=extents)])
    velocity = np.zeros((n, 3))
    velocity[:, 2] = speed
    assembly = ImpactAssembly(
        net=net, net_velocity=velocity, bodies=[plate], joints=[],
        contact=ContactLaw(stiffness=STIFFNESS, hunt_crossley_alpha=alpha, mu_static=mu[0], mu_kinetic=mu[1],
                           thread_segments=thread_segments),
        solver=SolverSpec(end_time=end_time, step=step, output_rate=1.0 / step, net_output_rate=1000.0,
                          implicit_contact_speed=implicit_speed))
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    return simulation.run(), simulation.system.kernel.buffers.segments


def friction_work(series: dict, net: dict) -> np.ndarray:
    """The work the plate's contact forces take from the sliding nodes, cumulative at each output sample (J):
    the power F_plate . v of the light nodes' mean velocity (LVLH), trapezoid over the samples (module doc).
    The net's velocities are interpolated from its 1 kHz snapshots to the series' times."""
    t = series["time"]
    light = net["velocities_lvlh"][:, 1:-1, :].astype(float).mean(axis=1)
    v = np.stack([np.interp(t, net["time"], light[:, d]) for d in range(3)], axis=1)
    power = np.einsum("kd,kd->k", series["contact_force_lvlh"][:, 0, :], v)
    return np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])


def balance_figures(series: dict, net: dict, segments, start: int = 0) -> dict:
    """From sample ``start`` to the end (J): the balance's drift, the booked dissipation by the contacts and by the
    threads' dampers, the friction work (:func:`friction_work`), the normal load on the plate (N, mean along y)."""
    total, booked = series["energy_total"], series["energy_dissipated_contact"]
    work = friction_work(series, net)
    return {"drift": total[-1] - total[start], "booked": booked[-1] - booked[start],
            "dampers": series["energy_dissipated_threads"][-1] - series["energy_dissipated_threads"][start],
            "friction": work[-1] - work[start], "load": series["contact_force_lvlh"][start:, 0, 1].mean(),
            "slip": net["velocities_lvlh"][-1, 1:-1, 2].mean(),
            "made": segments.energy_jump.sum() if segments.enabled else 0.0}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed", type=float, default=1.0)
    parser.add_argument("--steps", default="1e-4")
    parser.add_argument("--end-time", type=float, default=0.6)
    parser.add_argument("--keys", default="on,off")
    parser.add_argument("--node-on-face", action="store_true")
    parser.add_argument("--implicit-speed", type=float, default=0.15,
                        help="solver implicit_contact_speed (m/s): the cases' default 0.15; 0 sub-cycles every contact")
    args = parser.parse_args(argv)
    print(f"taut thread sliding along a plate's edge at {args.speed:g} m/s, node on the face: {args.node_on_face}; "
          f"implicit_contact_speed {args.implicit_speed:g} m/s; load {os.getloadavg()[0]:.1f}", flush=True)
    for step in (float(s) for s in args.steps.split(",")):
        for key in args.keys.split(","):
            start_cpu = time.process_time()
            rec, segments = sliding_thread(args.speed, step, key == "on", args.end_time, args.node_on_face,
                                           implicit_speed=args.implicit_speed)
            cpu = time.process_time() - start_cpu
            half = len(rec.series["time"]) // 2
            for label, k in (("whole run", 0), ("second half", half)):
                f = balance_figures(rec.series, rec.net, segments, k)
                share = f"{100 * f['drift'] / f['booked']:+.2f} % of the booked" if f["booked"] > 1e-9 else "no contact"
                print(f"step {step:.0e} s key {key:3s} {label:11s}: load {f['load']:6.2f} N, slip {f['slip']:.3f} m/s;"
                      f" friction work {f['friction']:8.4f} J, booked by the contacts {f['booked']:8.4f} J "
                      f"(dampers {f['dampers']:.4f} J); balance drift {f['drift']:+9.5f} J "
                      f"({share}); thread contact made "
                      f"between steps {f['made']:+.5f} J (whole run); CPU {cpu:.1f} s", flush=True)


if __name__ == "__main__":
    main()
