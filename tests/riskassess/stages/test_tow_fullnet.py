"""Capture start of the full-net tow (riskassess/stages/tow_fullnet.py, Sec. 2.1, 4.1): the ejected net's
initial state and its free flight towards the debris."""
import numpy as np
import pytest

from multibody.maths.rotations import quaternion_to_matrix
from multibody.net_towing import NetTowState, run_exudyn
from riskassess.cases.impact import load_model
from riskassess.models.towing_fullnet import capture_start, full_net_model
from riskassess.cases.towing import TowingCase

CASE = "cases/zenit2_towing.toml"


@pytest.fixture(scope="module")
def capture_case():
    """The shipped case with the capture start, a 7 x 7 net (same side, mass, threads)."""
    case = load_model(CASE, TowingCase)
    return case.model_copy(update=dict(full_net=case.full_net.model_copy(update=dict(start="capture", nodes_per_side=7))))


def test_capture_start_ejects_the_open_net_towards_the_debris(capture_case):
    case, fn = capture_case, capture_case.full_net
    net, nodes, velocities, chaser, omega = capture_start(case, 12.67)
    # Table 2: the chaser stays where it is; r_D/C from its tether attachment to the debris CoM
    np.testing.assert_array_equal(chaser, case.chaser.position_inertial)
    attach = chaser + quaternion_to_matrix(np.asarray(case.chaser.attitude_quaternion)) @ np.asarray(
        case.chaser.tether_attachment_body)
    e = np.asarray(case.debris.position_inertial) - attach
    e /= np.linalg.norm(e)
    grid = nodes[:49]
    # flat net normal to r_D/C, centred launch_offset ahead of the attachment (round-off of 7e6 m positions: 1e-8 m)
    np.testing.assert_allclose((grid - attach) @ e, fn.launch_offset, atol=1e-8)
    np.testing.assert_allclose(grid.mean(axis=0), attach + fn.launch_offset * e, atol=1e-8)
    # open: 22 m side, the closing loop at its open (straight-line) lengths
    assert np.linalg.norm(grid[6] - grid[0]) == pytest.approx(fn.side_length, abs=1e-8)
    np.testing.assert_allclose(net.topology.rest_lengths[-12:], net.closing_rest_open, rtol=1e-15)
    # every node at the chaser's velocity plus the launch speed along r_D/C; the debris spins at 12.67 deg/s about d_y
    expected = np.asarray(case.chaser.velocity_inertial) + fn.launch_speed * e
    np.testing.assert_allclose(velocities, np.tile(expected, (len(velocities), 1)), rtol=1e-14)
    np.testing.assert_allclose(omega, [0.0, -np.deg2rad(12.67), 0.0], rtol=1e-15)


def test_closing_loop_is_reeled_in_over_the_closing_duration(capture_case):
    model = full_net_model(capture_case, end_time=0.1)
    state = NetTowState(model)
    fn, net = capture_case.full_net, model.net
    for t, ramp in ((fn.closing_time + 0.4 * fn.closing_duration, 0.4), (fn.closing_time + 2 * fn.closing_duration, 1.0)):
        state.reel(t)   # linear from open to closed, EA/l0 stiffness (multibody.net_towing.NetTowState.reel)
        expected = net.closing_rest_open + ramp * (net.closing_rest_closed - net.closing_rest_open)
        np.testing.assert_allclose(state.rest[-12:], expected, rtol=1e-14)
        np.testing.assert_allclose(state.stiffness[-12:], fn.closing_axial_rigidity / expected, rtol=1e-14)
        # the loop's dampers read the stretch's rate: the natural lengths' rate is the ramp's while it reels, then 0
        rate = (net.closing_rest_closed - net.closing_rest_open) / fn.closing_duration if ramp < 1.0 else 0.0
        np.testing.assert_allclose(state.rest_rate[-12:], rate, rtol=1e-14)
    assert not np.any(state.rest_rate[:-12])
    assert not state.reeling and state.rest[:-12] == pytest.approx(net.topology.rest_lengths[:-12], rel=0)


def test_ejected_net_flies_ballistically_relative_to_the_chaser(capture_case):
    # before contact (arrival ~8 s) and before closing (15 s) only gravity acts on the net and the tether
    # is slack: the net's CoM moves at the launch speed relative to the chaser (Verlet, exact for a uniform
    # field), shifted by the sub-steps' symplectic Euler offset g h t / 2 (x_k = x0 + v0 t + g t^2/2 + g h t/2,
    # h = 0.1 ms: 3.8e-4 m after 1 s). Tolerance: the gravity gradient over the few metres between chaser
    # and net, 3 n^2 d < 2e-5 m/s^2 (n = 1.06e-3 rad/s at 840 km, d < 4 m), over 1 s: 1e-5 m; we allow 3e-5 m.
    model = full_net_model(capture_case, end_time=1.0)
    launch = model.node_velocities[0] - model.velocities[0]
    result = run_exudyn(model)
    s, m = result.series(), model.net.topology.masses
    net_com = np.einsum("j,kjd->kd", m, result.net_positions) / m.sum()
    i = np.searchsorted(s["time"], result.net_time)
    relative = net_com - s["chaser_com_inertial"][i]
    r = s["chaser_com_inertial"][0]
    gravity = -capture_case.simulation.mu * r / np.linalg.norm(r) ** 3
    offset = gravity * model.step / model.substeps / 2.0
    np.testing.assert_allclose(relative - relative[0], np.outer(result.net_time - result.net_time[0], launch + offset),
                               atol=3e-5)
    assert s["net_contacts"].max() == 0 and s["main_tether_tension"].max() == 0.0
