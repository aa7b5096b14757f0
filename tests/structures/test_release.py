"""A failed joint is released during the run and its piece flies off: spinning two-body check.

A 100 kg cube and a 10 kg arm clamped to it spin rigidly at 1 rad/s about the system CoM
(no orbit; a one-node 'net' far away). The clamped joint carries the arm's centripetal
load m w^2 d (d: arm CoM to system CoM). With a 10 N allowable force the joint fails at
the first judged sample after the skipped transient, and the arm then moves on a straight
line at w d (Newton's first law), keeping its spin.
"""
import numpy as np
import pytest
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, JointSpec, RigidBodySpec, SolverSpec
from multibody.impact import ImpactSimulation
from structures.criteria import Allowable
from structures.release import ReleaseMonitor, released_pieces
from structures.weak_location import WeakLocation
from tests.conftest import single_node

OMEGA = 1.0                       # rad/s about z
M_BODY, M_ARM = 100.0, 10.0
ARM_COM = np.array([1.5, 0.0, 0.0])
SYSTEM_COM = M_ARM * ARM_COM / (M_BODY + M_ARM)
ARM_RADIUS = np.linalg.norm(ARM_COM - SYSTEM_COM)


def _spinning_pair(step=1e-4, end_time=0.6):
    w = np.array([0.0, 0.0, OMEGA])

    def body(name, mass, com, extents):
        inertia = mass / 12 * np.diag([extents[1] ** 2 + extents[2] ** 2, extents[0] ** 2 + extents[2] ** 2,
                                       extents[0] ** 2 + extents[1] ** 2])
        return RigidBodySpec(name=name, mass=mass, inertia_body=inertia, com_lvlh=np.asarray(com, float),
                             velocity_lvlh=np.cross(w, np.asarray(com, float) - SYSTEM_COM), omega_body=w,
                             meshes_body=[trimesh.creation.box(extents=extents)])

    bodies = [body("cube", M_BODY, [0, 0, 0], [1.0, 1.0, 1.0]), body("arm", M_ARM, ARM_COM, [2.0, 0.2, 0.2])]
    joint = JointSpec(name="arm_root", kind="clamped", parent=0, child=1, point_lvlh=np.array([0.5, 0, 0]),
                      hinge_to_lvlh=np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0]], float).T)
    net = single_node([0.0, -50.0, 0.0], [0.0, 0.0, 0.0])
    return ImpactAssembly(net=net, net_velocity=np.zeros((1, 3)), bodies=bodies, joints=[joint],
                          contact=ContactLaw(stiffness=1e8, hunt_crossley_alpha=0.0, mu_static=0.0, mu_kinetic=0.0),
                          solver=SolverSpec(end_time=end_time, step=step, output_rate=1000.0, net_output_rate=10.0))


def test_centripetal_joint_load_then_release_and_free_flight():
    assembly = _spinning_pair()
    sim = ImpactSimulation(assembly)
    location = WeakLocation(name="arm_root", joint=0, section_to_joint=np.eye(3), offset_joint=np.zeros(3),
                            allowable_force=Allowable.of(10.0))
    monitor = ReleaseMonitor([location], sim.system, skip_until=0.1, policy="low")
    rec = sim.run(monitor=monitor)
    s = rec.series
    centripetal = M_ARM * OMEGA**2 * ARM_RADIUS      # 13.6 N
    # released at the first judged sample, under the centripetal load (penalty ringing of the
    # suddenly loaded joint has decayed by 0.1 s: 5 % damping at ~5000 rad/s)
    assert len(monitor.events) == 1
    event = monitor.events[0]
    assert event.time == pytest.approx(0.1, abs=1.5e-3)
    # 3 %: Exudyn's reported connector force (ForceLocal) reads 2.5 % under the force the
    # bodies actually feel in this steady spin with 5 % penalty damping at 1e-4 s (0.6 % at
    # 2.5e-5 s, exact without damping on average); the orbit itself is exact. Open problem,
    # see docs/structures.md.
    assert event.demand == pytest.approx(centripetal, rel=0.03)
    # after release: straight line at w d, spin kept (samples from one output step after the release)
    after = s["time"] > event.time + 2e-3
    v_arm = s["body_velocity_lvlh"][after, 1]
    assert np.linalg.norm(v_arm - v_arm[-1], axis=1).max() < 1e-6 * np.linalg.norm(v_arm[-1])
    assert np.linalg.norm(v_arm[-1]) == pytest.approx(OMEGA * ARM_RADIUS, rel=0.01)
    assert s["body_omega_body"][-1, 1, 2] == pytest.approx(OMEGA, rel=1e-3)
    assert np.abs(s["joint_force_joint"][after, 0]).max() == 0.0
    # momentum of the pair stays zero (it spun about its own CoM), energy stays booked
    p = s["momentum_linear_lvlh"]
    assert np.abs(p).max() < 1e-6 * M_ARM * OMEGA * ARM_RADIUS
    e = s["energy_total"]
    assert np.abs(e - e[0]).max() < 1e-3 * e[0]
    piece = released_pieces(monitor.events, assembly, s, rec.net["positions_lvlh"][-1])[0]
    assert piece["bodies"] == ["arm"] and piece["mass_kg"] == M_ARM
    assert piece["size_m"] == pytest.approx([2.0, 0.2, 0.2], rel=1e-9)
    assert piece["spin_rate_rad_s"] == pytest.approx(OMEGA, rel=1e-3)
    assert piece["inside_net_at_end"] is False


def test_piece_is_the_subtree_below_the_released_joint():
    """Chain 0-1-2-3 (joints 0, 1, 2): releasing joint 0 frees bodies 1, 2, 3 once each; after
    joint 1 was released earlier, only body 1 leaves with joint 0."""
    from multibody.assembly import subtree_bodies

    joints = [JointSpec(name=f"j{k}", kind="clamped", parent=k, child=k + 1, point_lvlh=np.zeros(3),
                        hinge_to_lvlh=np.eye(3)) for k in range(3)]
    assert subtree_bodies(joints, 1) == [1, 2, 3]
    assert subtree_bodies(joints, 1, cut_joints={1}) == [1]
