"""Slow turns survive the explicit integration (multibody/rotation_update.py): Exudyn's Lie-group update
drops rotation increments below about 2e-8 rad a step; the impact simulation restores the exact
attitude after every step."""
import exudyn as exu
import numpy as np
import pytest
from exudyn.itemInterface import NodeRigidBodyRotVecLG, ObjectRigidBody

from multibody.assembly import ContactLaw, ImpactAssembly, RigidBodySpec, SolverSpec
from multibody.impact import ImpactSimulation, explicit_settings
from multibody.maths.rotations import rotation_vector_from_matrix
from tests.conftest import single_node


def exudyn_alone_turn(omega, step, n_steps):
    """Angle (rad) a free body spinning at ``omega`` (rad/s) about a principal axis reaches in Exudyn's own
    explicit VelocityVerlet with Lie-group rotation updates (the settings of the impact simulation)."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    node = mbs.AddNode(NodeRigidBodyRotVecLG(referenceCoordinates=[0.0] * 6, initialVelocities=[0, 0, 0, 0, 0, omega]))
    mbs.AddObject(ObjectRigidBody(mass=1.0, inertia=[1.0, 2.0, 3.0, 0.0, 0.0, 0.0], nodeNumber=node))
    mbs.Assemble()
    exu.SolveDynamic(mbs, explicit_settings(step, n_steps), solverType=exu.DynamicSolverType.VelocityVerlet)
    return mbs.GetNodeOutput(node, exu.OutputVariableType.Rotation)[2]


def test_exudyn_alone_drops_turns_below_its_floor():
    # the floor this module works around (Exudyn 1.13.6): 1e-8 rad a step is lost entirely, 1e-7 kept.
    # If a later Exudyn keeps the small turns, the restoration is no longer needed (it stays exact).
    assert exudyn_alone_turn(1e-4, 1e-4, 1000) == 0.0
    assert exudyn_alone_turn(1e-3, 1e-4, 1000) == pytest.approx(1e-4, rel=1e-3)


def slow_spinner(omega_body, step, end_time=0.2):
    """A 100 kg body with principal inertias 10, 20, 30 kg m^2 turning freely at ``omega_body`` (rad/s), a
    far-away net node that never touches it (the kernel path of the impact simulation)."""
    body = RigidBodySpec(name="spinner", mass=100.0, inertia_body=np.diag([10.0, 20.0, 30.0]), com_lvlh=np.zeros(3),
                         omega_body=np.asarray(omega_body, float))
    return ImpactAssembly(net=single_node([100.0, 100.0, 100.0], [0.0, 0.0, 0.0]), net_velocity=np.zeros((1, 3)),
                          bodies=[body], joints=[], contact=ContactLaw(stiffness=1e8),
                          solver=SolverSpec(end_time=end_time, step=step, output_rate=100.0, net_output_rate=10.0))


@pytest.mark.parametrize("step", [1e-4, 5e-5])
def test_a_slow_spin_about_a_principal_axis_turns_by_rate_times_time(step):
    # torque-free spin about a principal axis keeps its rate: the angle is omega t exactly. 1e-4 rad/s is
    # 1e-8 rad a step at 1e-4 s, below Exudyn's floor: without the restoration the body would not turn.
    omega = 1e-4
    series = ImpactSimulation(slow_spinner([0.0, 0.0, omega], step)).run().series
    angle = rotation_vector_from_matrix(np.ascontiguousarray(series["body_to_lvlh"][-1, 0], float))
    # round-off of 2000-4000 compositions of 1e-8 rad turns: far below 1e-9 of the angle. Off the spin
    # axis, the body's attitude is the node's (2 rad from the identity, multibody.node_frame) times a fixed
    # rotation: round-off of O(1) matrices, ~eps sqrt(steps) rad (measured 9e-15): 1e-13 bounds it
    np.testing.assert_allclose(angle, [0.0, 0.0, omega * series["time"][-1]], rtol=1e-9, atol=1e-13)
