"""Recorded loads on a free body (the sequential method's second step, multibody.recorded_loads):
impulse and angular impulse against the analytic rigid-body answer, energy balance closed."""
import numpy as np
import pytest
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.impact import ImpactSimulation
from multibody.recorded_loads import RecordedBodyLoads
from tests.conftest import single_node

MASS, INERTIA = 500.0, np.diag([100.0, 200.0, 300.0])
STEP, RATE = 1e-4, 1000.0


def driven_body(force_lvlh, moment_body, end_time=0.1):
    body = RigidBodySpec(name="box", mass=MASS, inertia_body=INERTIA, com_lvlh=np.array([0.0, 30.0, 0.0]),
                         meshes_body=[trimesh.creation.box(extents=[1.0, 1.0, 1.0])])
    time = np.arange(1, int(round(end_time * RATE)) + 1) / RATE
    loads = RecordedBodyLoads(time=time, force_lvlh=force_lvlh(time)[:, None, :],
                              moment_body=moment_body(time)[:, None, :], reference_energy=10.0)
    far = single_node([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    assembly = ImpactAssembly(net=far, net_velocity=np.zeros((1, 3)), bodies=[body], joints=[],
                              contact=ContactLaw(stiffness=1e8),
                              solver=SolverSpec(end_time=end_time, step=STEP, output_rate=RATE), body_loads=loads)
    return ImpactSimulation(assembly).run()


def test_held_force_and_moment_give_the_recorded_impulses():
    # force 40 N along x over (0, 0.05], moment 3 N m about body z over (0.02, 0.06]
    force = lambda t: np.where((t <= 0.05 + 1e-12)[:, None], [40.0, 0.0, 0.0], 0.0)
    moment = lambda t: np.where(((t > 0.02 + 1e-12) & (t <= 0.06 + 1e-12))[:, None], [0.0, 0.0, 3.0], 0.0)
    rec = driven_body(force, moment)
    s = rec.series
    # impulse 40 N x 0.05 s on 500 kg: 4 mm/s; angular impulse 3 x 0.04 about I_zz = 300: 0.4 mrad/s;
    # exact but for round-off (the loads are read half a step back, see _HeldLoad)
    assert s["body_velocity_lvlh"][-1, 0, 0] == pytest.approx(40.0 * 0.05 / MASS, rel=1e-9)
    assert s["body_omega_body"][-1, 0, 2] == pytest.approx(3.0 * 0.04 / 300.0, rel=1e-9)
    assert abs(s["body_velocity_lvlh"][-1, 0, 1]) < 1e-12 and abs(s["body_omega_body"][-1, 0, 0]) < 1e-12
    # the balance counts the loads' work: kinetic energy gained = work done, total constant
    kinetic = s["energy_debris_translational"][-1] + s["energy_debris_rotational"][-1]
    # (1e-5: the handover half step takes the rate at its start, second order in h; measured 2e-6)
    assert -s["energy_applied_loads_work"][-1] == pytest.approx(kinetic, rel=1e-5)
    assert np.ptp(s["energy_total"]) < 1e-5 * kinetic
