"""Exudyn alone: does the explicit Lie-group update's floor reach the joint springs inside a step?

A rigid body (principal inertias 1, 2, 3 kg m^2) on one rotational spring about its principal axis z to
ground, started at rest at zero deflection with a small angular velocity, rings as the linear
oscillator theta(t) = A sin(omega t) (no gyroscopic coupling: the spin stays on a principal axis).
Exudyn's explicit VelocityVerlet with Lie-group updates (the impact simulation's settings) integrates it
four ways:

- ``plain``: Exudyn alone, the node's rotation vector the body's attitude (starts at the identity);
- ``restore``: plus multibody.rotation_update's end-of-step restore (the exact composed attitude written
  over Exudyn's after each step), so only the in-step attitude the spring sees is Exudyn's own;
- ``offset``: the node frame turned by a fixed rotation from the body frame (inertia and marker rotated
  once), so the node's rotation vector sits far from the identity;
- ``offset+restore``: both.

Prints the largest error of the angle and of the spring moment against the analytic solution, relative
to the amplitude, over the run. Usage: ``python bench/bench_instep_attitude.py [--hz 2] [--step 1e-4]``.
"""
from __future__ import annotations

import argparse
import time

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (MarkerBodyRigid, NodeRigidBodyRotVecLG, ObjectConnectorRigidBodySpringDamper,
                                  ObjectGround, ObjectRigidBody)
from scipy.spatial.transform import Rotation

from multibody.impact import explicit_settings
from multibody.maths.rotations import compose_rotation_vectors

INERTIA_BODY = np.diag([1.0, 2.0, 3.0])


def ring(amplitude, hz, step, periods, node_to_body=None, restore=False):
    """Angle (rad) and spring moment (N m) about z at every step: (time, angle, moment) arrays."""
    c = np.eye(3) if node_to_body is None else node_to_body
    omega_n = 2.0 * np.pi * hz
    k = INERTIA_BODY[2, 2] * omega_n ** 2
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    rv0 = Rotation.from_matrix(c).as_rotvec()
    inertia_node = c.T @ INERTIA_BODY @ c
    omega_node = c.T @ np.array([0.0, 0.0, amplitude * omega_n])
    node = mbs.AddNode(NodeRigidBodyRotVecLG(referenceCoordinates=[0.0] * 6, initialCoordinates=[0.0] * 3 + list(rv0),
                                             initialVelocities=[0.0] * 3 + list(omega_node)))
    j = inertia_node
    body = mbs.AddObject(ObjectRigidBody(mass=1.0, inertia=[j[0, 0], j[1, 1], j[2, 2], j[1, 2], j[0, 2], j[0, 1]],
                                         nodeNumber=node))
    ground = mbs.AddObject(ObjectGround())
    m0 = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground))
    m1 = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body, localHT=exu.HT(rotation=c.T, translation=[0.0, 0.0, 0.0])))
    spring = mbs.AddObject(ObjectConnectorRigidBodySpringDamper(
        markerNumbers=[m0, m1], stiffness=np.diag([0, 0, 0, 0, 0, k]), damping=np.zeros((6, 6)),
        useIntrinsicFormulation=True))
    mbs.Assemble()
    n_steps = int(round(periods / hz / step))
    rows = [(0.0, 0.0, 0.0)]
    kept = {}

    def pre_step(mbs_, t):
        if restore:
            data = mbs_.systemData
            q, qt, qtt = data.GetODE2Coordinates(), data.GetODE2Coordinates_t(), data.GetODE2Coordinates_tt()
            kept["rot"] = compose_rotation_vectors(np.ascontiguousarray(q[3:6]),
                                                   step * (np.asarray(qt[3:6]) + 0.5 * step * np.asarray(qtt[3:6])))
        return True

    def post_step(mbs_, t):
        if restore and "rot" in kept:
            mbs_.systemData.GetODE2Coordinates(copy=False)[3:6] = kept.pop("rot")
        rel = mbs_.GetObjectOutput(spring, exu.OutputVariableType.Rotation)
        rows.append((t, rel[2], mbs_.GetObjectOutput(spring, exu.OutputVariableType.TorqueLocal)[2]))
        return True

    mbs.SetPreStepUserFunction(pre_step)
    mbs.SetPostStepUserFunction(post_step)
    exu.SolveDynamic(mbs, explicit_settings(step, n_steps), solverType=exu.DynamicSolverType.VelocityVerlet)
    out = np.array(rows)
    return out[:, 0], out[:, 1], out[:, 2], k


def errors(amplitude, hz, step, periods, **kw):
    t, angle, moment, k = ring(amplitude, hz, step, periods, **kw)
    exact = amplitude * np.sin(2.0 * np.pi * hz * t)
    return (np.abs(angle - exact).max() / amplitude, np.abs(moment - k * exact).max() / (k * amplitude),
            np.abs(angle).max() / amplitude)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--hz", type=float, nargs="+", default=[2.0, 50.0])
    p.add_argument("--step", type=float, default=1e-4)
    p.add_argument("--amplitudes", type=float, nargs="+", default=[1e-9, 1e-7, 1e-5, 1e-3])
    p.add_argument("--periods", type=float, default=3.0)
    p.add_argument("--offset", type=float, default=2.0, help="node-frame offset angle (rad) about (1,1,1)")
    a = p.parse_args()
    c = Rotation.from_rotvec(a.offset * np.ones(3) / np.sqrt(3.0)).as_matrix()
    print(f"step {a.step:g} s; errors relative to the amplitude: angle, moment; largest |angle|/A", flush=True)
    for hz in a.hz:
        for amp in a.amplitudes:
            for name, kw in (("plain", {}), ("restore", {"restore": True}), ("offset", {"node_to_body": c}),
                             ("offset+restore", {"node_to_body": c, "restore": True})):
                t0 = time.process_time()
                e = errors(amp, hz, a.step, a.periods, **kw)
                print(f"{hz:5g} Hz A {amp:7.0e} increment/step {amp * 2 * np.pi * hz * a.step:7.1e} {name:15s} "
                      f"angle {e[0]:9.2e} moment {e[1]:9.2e} max {e[2]:8.5f}  ({time.process_time() - t0:.1f} s CPU)",
                      flush=True)


if __name__ == "__main__":
    main()
