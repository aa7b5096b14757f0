"""Joint springs see every small turn (multibody/node_frame.py): Exudyn's Lie-group update reads a
rotation vector near zero through the cosine of its half angle, so inside a step a body near its node's
identity is seen with a dead zone of about 2e-8 rad; the impact simulation turns every node frame 2 rad
away from its body frame."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bench.bench_instep_attitude import ring
from multibody.impact import ImpactSimulation
from multibody.node_frame import (
    NODE_TO_LVLH_AT_START,
    body_state_into,
    inertia_node,
    node_to_body_rotation,
    vector_node,
)
from tests.multibody.test_hinge import analytic_frequency, ring_down_assembly


def ring_error(amplitude, **kw):
    """Largest error (relative to the amplitude) and largest |angle| / amplitude of a body on a 2 Hz
    rotational spring to ground over two periods at the shipped step 1e-4 s (Exudyn alone)."""
    t, angle, _, _ = ring(amplitude, 2.0, 1e-4, 2.0, **kw)
    exact = amplitude * np.sin(4.0 * np.pi * t)
    return np.abs(angle - exact).max() / amplitude, np.abs(angle).max() / amplitude


def test_exudyn_alone_spring_misses_turns_below_its_floor_even_with_the_restore():
    # 1e-9 rad of amplitude sits inside the dead zone: with the end-of-step restore the body turns at its
    # initial rate and the spring never pulls it back (|angle| grows to omega0 t = 4 pi A in two periods)
    _, largest = ring_error(1e-9, restore=True)
    assert largest > 10.0


@pytest.mark.parametrize("amplitude", [1e-9, 1e-7, 1e-3])
def test_exudyn_alone_spring_in_a_turned_node_frame_rings_as_the_linear_oscillator(amplitude):
    # theta = A sin(omega t) (principal axis, no gyroscopic coupling). Verlet's own phase error is
    # (omega h)^2 / 24 omega t = 5e-7 here; round-off of the 2 rad node attitude (~1e-16 rad a step) on
    # 1e-9 rad leaves 2e-4 (measured 2.2e-4 over three periods): bound 1e-3 at 1e-9, 1e-5 above
    error, _ = ring_error(amplitude, node_to_body=Rotation.from_rotvec([1.2, 0.9, -1.3]).as_matrix())
    assert error < (1e-3 if amplitude < 1e-8 else 1e-5)


def test_node_frame_quantities_turn_back_to_the_body_frame():
    body_to_lvlh = Rotation.from_rotvec([0.3, -0.2, 0.1]).as_matrix()
    c = node_to_body_rotation(body_to_lvlh)
    np.testing.assert_allclose(body_to_lvlh @ c, NODE_TO_LVLH_AT_START, atol=1e-15)
    inertia_body = np.diag([10.0, 20.0, 30.0])
    omega_body = np.array([0.1, -0.2, 0.3])
    # kinetic energy and angular momentum in LVLH are frame-independent
    omega_node, j_node = vector_node(omega_body, c), inertia_node(inertia_body, c)
    assert omega_node @ j_node @ omega_node == pytest.approx(omega_body @ inertia_body @ omega_body, rel=1e-14)
    np.testing.assert_allclose(NODE_TO_LVLH_AT_START @ j_node @ omega_node, body_to_lvlh @ inertia_body @ omega_body,
                               rtol=1e-14, atol=1e-15)


def test_body_state_from_the_node_coordinates_matches_the_rotations():
    # the one turn the kernel and the recorder share: body->LVLH = node->LVLH (node->body)^T, the node-frame
    # rate turned into LVLH and into the body frame; against scipy's rotations (round-off, 1e-15)
    body_to_lvlh_start = Rotation.from_rotvec([0.3, -0.2, 0.1]).as_matrix()
    node_to_body = node_to_body_rotation(body_to_lvlh_start)[np.newaxis]
    rotation_vector, omega_node = np.array([0.7, -1.1, 0.4]), np.array([0.02, -0.05, 0.3])
    com, velocity = np.array([1.0, -2.0, 3.0]), np.array([0.1, 0.2, -0.3])
    q = np.concatenate([np.zeros(4), com, rotation_vector])     # the body's six coordinates start at 4
    qt = np.concatenate([np.zeros(4), velocity, omega_node])
    reference = np.array([[10.0, 20.0, 30.0]])
    out = [np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3, 3)), np.zeros((2, 3, 3)), np.zeros((2, 3)),
           np.zeros((2, 3))]
    body_state_into(q, qt, 4, 0, reference, node_to_body, *out)
    com_lvlh, velocity_lvlh, node_to_lvlh, body_to_lvlh, omega_lvlh, omega_body = (a[0] for a in out)
    node_expected = Rotation.from_rotvec(rotation_vector).as_matrix()
    np.testing.assert_array_equal(com_lvlh, reference[0] + com)
    np.testing.assert_array_equal(velocity_lvlh, velocity)
    np.testing.assert_allclose(node_to_lvlh, node_expected, atol=1e-15)
    np.testing.assert_allclose(body_to_lvlh, node_expected @ node_to_body[0].T, atol=1e-15)
    np.testing.assert_allclose(omega_lvlh, node_expected @ omega_node, atol=1e-15)
    np.testing.assert_allclose(omega_body, node_to_body[0] @ omega_node, atol=1e-15)
    # the same rate, seen from either frame
    np.testing.assert_allclose(body_to_lvlh @ omega_body, omega_lvlh, atol=1e-15)


def hinge_angle_per_amplitude(angle0):
    """The free main body + hinged array of tests/multibody/test_hinge.py ringing from ``angle0`` (rad):
    time (s) and hinge angle about h2 over the initial angle."""
    assembly, rest_att, rest_com = ring_down_assembly(angle0)
    assembly.solver.end_time = 3.0
    rec = ImpactSimulation(assembly, rest_att, rest_com).run()
    return rec.series["time"], rec.series["joint_rotation_joint"][:, 0, 1] / angle0


def test_hinge_rings_alike_from_1e_9_and_1e_2_rad():
    # the linearized two-body system (test_hinge's analytic frequency) rings the same at every amplitude:
    # from 1e-9 rad (far inside Exudyn's 2e-8 rad dead zone near the identity) as from 1e-2 rad. Both bodies
    # start at the identity attitude, so without the turned node frames the joint spring would miss it.
    t, small = hinge_angle_per_amplitude(1e-9)
    _, large = hinge_angle_per_amplitude(1e-2)
    # geometric nonlinearity at 1e-2 rad is O(angle^2) = 1e-4; round-off on 1e-9 rad ~1e-16/1e-9 a step.
    # Measured 4.1e-5; with the node frames equal to the body frames (end-of-step restore only) 7.3
    np.testing.assert_allclose(small, large, atol=5e-4)
    crossings = np.flatnonzero(np.sign(small[:-1]) != np.sign(small[1:]))
    times = t[crossings] - small[crossings] * (t[crossings + 1] - t[crossings]) / (small[crossings + 1] - small[crossings])
    # 1 %: test_hinge's bound (penalty compliance and Verlet's phase error are each below 0.01 %)
    assert np.pi / np.mean(np.diff(times)) == pytest.approx(analytic_frequency(), rel=0.01)
