"""Full-net towing model (multibody/net_towing.py): conservation, Newton and orbit checks on a small
wrapped net (7 x 7 nodes around a 3 m x 1 m cylinder), short horizons."""
from __future__ import annotations

import numpy as np
import pytest

from multibody.net_towing import FullNetModel, run_exudyn
from multibody.net_towing_kernel import cylinder_distance
from multibody.net_wrap import DrapeSchedule, drape_and_close, towing_net, wrap_summary
from multibody.orbit import MU_EARTH

GEOMETRY = np.array([0.5, 1.5, -0.1])            # radius, half length, axial centre (m)
LAW = np.array([1e7, 1.5, 1.5 * 0.05 * 1e7, 0.19, 0.152, 0.01])  # Hertz k_n, n, d_n, mu_s, mu_k, V_t0
UP = np.array([0.0, 1.0, 0.0])                   # the chaser's side, debris frame
R_ORBIT = 7.218e6                                # 840 km altitude (m)


@pytest.fixture(scope="module")
def small_wrapped_net():
    """6 m net, 7 x 7 nodes, 0.5 kg, EA 5 kN (threads stable below ~1.3 ms at 8.6 g per node),
    draped and closed around the cylinder in the debris frame."""
    net = towing_net(6.0, 7, 0.5, 0.02, 0.005, 0.01, 5000.0, 0.5, 5000.0, 0.2, UP * 0.8 + [0, 0, GEOMETRY[2]], -UP)
    x_body = drape_and_close(net, GEOMETRY, LAW, UP, DrapeSchedule(fall=2.0, reel=3.0, settle=3.0, step=2e-4))
    top = net.topology
    top.rest_lengths[-12:] = net.closing_rest_closed
    top.stiffness[-12:] = net.closing_stiffness(net.closing_rest_closed)
    return net, x_body


def _model(wrapped, mu=0.0, spin=0.0, thrust=(1e9, 1.0, 0.0), end=1.0, step=2e-3, substeps=10, velocity=None,
           output_interval=0.01):
    """Debris 900 kg on the x axis at R_ORBIT, chaser 160 kg 3 m (the main tether's natural length)
    from the central node along UP; thrust = (t_on, t_slope, F_max) of the ramp (default: never on)."""
    net, x_body = wrapped
    com_d = np.array([R_ORBIT, 0.0, 0.0])
    v_d = np.zeros(3) if velocity is None else np.asarray(velocity, float)
    omega = np.array([0.0, spin, 0.0])
    node = com_d + x_body[net.central]
    chaser = node + 3.0 * UP + np.array([0.0, 0.5, 0.0])   # attachment 0.5 m below the chaser's CoM
    return FullNetModel(
        net=net, node_positions=com_d + x_body, node_velocities=v_d + np.cross(omega, x_body),
        masses=np.array([160.0, 900.0]), inertia_body=np.array([np.eye(3) * 26.7, np.diag([240.0, 240.0, 112.5])]),
        attach_chaser_body=np.array([0.0, -0.5, 0.0]), main_tether=np.array([3000.0, 300.0, 3.0]),
        geometry=GEOMETRY, contact_law=LAW, mu=mu, attitude=np.zeros(8), thrust_law="ramp",
        thrust_along_body_z=False, thrust_params=np.array(thrust, float), thrust_state=np.zeros(1),
        positions=np.array([chaser, com_d]), velocities=np.array([v_d, v_d]), body_to_inertial=np.array([np.eye(3)] * 2),
        omega_body=np.array([np.zeros(3), omega]), start_time=25.0, end_time=25.0 + end, step=step, substeps=substeps,
        output_interval=output_interval, net_output_interval=0.5, closing_time=15.0)


def test_cylinder_distance_side_cap_and_rim():
    # exact distances of the closed cylinder (radius 0.5, half length 1.5, centre z = -0.1)
    assert cylinder_distance(0.8, 0.0, 0.0, GEOMETRY)[:2] == pytest.approx((0.3, 1.0))
    assert cylinder_distance(0.0, 0.1, 1.9, GEOMETRY)[0] == pytest.approx(0.5)
    assert cylinder_distance(0.0, 0.2, 0.0, GEOMETRY)[0] == pytest.approx(-0.3)
    d, nx, ny, nz = cylinder_distance(0.8, 0.0, 1.8, GEOMETRY)     # beyond the rim: 0.3 out, 0.4 up
    assert (d, nx, nz) == pytest.approx((0.5, 0.6, 0.8))


def test_wrapped_net_encloses_the_cylinder(small_wrapped_net):
    net, x_body = small_wrapped_net
    shape = wrap_summary(x_body, net, GEOMETRY)
    # nodes outside the surface (contact penetration of the settled net is micrometres under Hertz 1e7),
    # net threads at most at their natural length plus the settling sag (1e-3 strain)
    assert shape["min_clearance_m"] > -1e-4
    assert shape["max_net_strain"] < 1e-3
    # the central node lies on the chaser's side (UP) of the cylinder, on its surface
    assert x_body[net.central] @ UP == pytest.approx(GEOMETRY[0] + 0.005, abs=2e-3)
    # the closed loop passes under the cylinder: its lacing points are on the far side
    loop = net.topology.threads[-12:, 0]
    assert np.all(x_body[loop] @ UP < 0.0)


def test_wrapped_net_at_rest_keeps_shape_and_momentum(small_wrapped_net):
    """No gravity, no thrust, common drift 1 m/s: the momentum of chaser + debris + net is exact up to
    the half kick Verlet still owes the last step's force (H/2 |F|, with |F| the contact load of the
    net lying on the cylinder, < 10 N), and the net stays where it settled (mm)."""
    net, x_body = small_wrapped_net
    result = run_exudyn(_model(small_wrapped_net, velocity=[0.0, 0.0, 1.0], end=1.0))
    s = result.series()
    p = s["total_momentum_inertial"]
    assert np.abs(p - p[0]).max() < 2e-3 / 2 * 10.0
    assert p[0] == pytest.approx([0.0, 0.0, 160.0 + 900.0 + 0.5])
    moved = s["net_nodes_inertial"][-1] - s["debris_com_inertial"][-1] - x_body
    assert np.abs(moved).max() < 5e-3
    assert s["main_tether_tension"].max() == 0.0   # the tether starts at its natural length and stays slack


def test_thrust_and_main_tether_impulses_move_the_system(small_wrapped_net):
    """Newton on the towed system, no gravity. Thrust ramp to 50 N (t_on 25 s, 0.2 s slope) against the
    common drift (-UP, so it pulls the chaser away from the debris). (1) The thrust integrates to the
    ramp's F (t - t_on - t_slope/2), and the total momentum changes by the thrust impulse (its direction,
    against the chaser's velocity, taken from the per-step samples) up to the half kick Verlet owes at
    the last sample (H/2 F = 0.05 N s) and 1e-3 for the direction sampled at the step's end. (2) Debris + net change by the main tether's impulse on the central node,
    summed from every step's mean tension (sampled each step) along the sampled tether direction:
    1 % (the direction is taken at the step's end, not averaged over its sub-steps)."""
    model = _model(small_wrapped_net, thrust=(25.0, 0.2, 50.0), end=6.0, velocity=-5.0 * UP, substeps=20,
                   output_interval=2e-3)
    s = run_exudyn(model).series()
    t = s["time"]
    p = s["total_momentum_inertial"]
    # the per-step samples of the ramp sum to its integral up to half a step of F_max
    assert s["thrust"][1:].sum() * model.step == pytest.approx(50.0 * (t[-1] - 25.0 - 0.1), abs=50.0 * model.step / 2 + 1e-9)
    v_c = s["chaser_velocity_inertial"]
    thrust_impulse = model.step * (s["thrust"][1:, None] * -v_c[1:] / np.linalg.norm(v_c[1:], axis=1, keepdims=True)).sum(0)
    assert np.linalg.norm(p[-1] - p[0] - thrust_impulse) < 2e-3 / 2 * 50.0 + 1e-3 * np.linalg.norm(thrust_impulse)
    a_point = s["chaser_com_inertial"] + np.einsum("kij,j->ki", s["chaser_to_inertial"], model.attach_chaser_body)
    u = s["connection_point_inertial"] - a_point
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    tether_impulse = (-s["main_tether_tension"][1:, None] * u[1:]).sum(axis=0) * model.step
    p_debris_net = p - model.masses[0] * s["chaser_velocity_inertial"]
    assert np.linalg.norm(tether_impulse) > 5.0                  # the tether did engage
    assert np.linalg.norm(p_debris_net[-1] - p_debris_net[0] - tether_impulse) < 0.01 * np.linalg.norm(tether_impulse)


def test_free_orbit_stays_circular(small_wrapped_net):
    """Two-body gravity on every body and node, no thrust: debris + net on the circular orbit through
    R_ORBIT for 20 s. The system's CoM follows the analytic circle to 1 mm (Verlet's error at 2 ms over
    20 s is ~1e-9 of the radius; the net's gravity-gradient forces are 1e-5 N) and its radius stays
    constant to 1 mm."""
    speed = np.sqrt(MU_EARTH / R_ORBIT)
    model = _model(small_wrapped_net, mu=MU_EARTH, velocity=[0.0, speed, 0.0], end=20.0, step=4e-3, substeps=20,
                   output_interval=0.02)   # every 5 steps: the 0.5 s net snapshots fall on samples
    net = model.net.topology
    result = run_exudyn(model)
    s = result.series()
    n = speed / R_ORBIT
    t = s["time"] - s["time"][0]
    circle = R_ORBIT * np.c_[np.cos(n * t), np.sin(n * t), np.zeros_like(t)]   # the debris CoM's circle
    # system CoM without the chaser (it is on its own, slightly higher orbit, the tether slack)
    net_com = np.zeros_like(circle)
    k = np.searchsorted(t, s["net_time"] - s["time"][0])
    net_com[k] = np.einsum("i,kij->kj", net.masses, s["net_nodes_inertial"]) / net.masses.sum()
    m_d, m_n = model.masses[1], net.masses.sum()
    com = (m_d * s["debris_com_inertial"][k] + m_n * net_com[k]) / (m_d + m_n)
    offset = com[0] - circle[0]           # the net's share moves the system CoM ~1 mm off the debris CoM
    turn = n * t[k]
    rotated = np.c_[np.cos(turn) * offset[0] - np.sin(turn) * offset[1], np.sin(turn) * offset[0]
                    + np.cos(turn) * offset[1], np.full_like(turn, offset[2])]
    assert np.abs(com - circle[k] - rotated).max() < 1e-3
    assert np.abs(np.linalg.norm(s["debris_com_inertial"], axis=1) - R_ORBIT).max() < 1e-3
    rot = s["debris_to_inertial"][-1]
    assert np.allclose(rot, np.eye(3), atol=1e-6)   # no spin given, no torque from a net at rest


def _free_debris(wrapped, omega_body, end=5.0):
    """The model of :func:`_model` with the net and the chaser moved 50 m off along x (no contact: the debris
    is torque-free; no gravity), the debris (J = diag(240, 240, 112.5) kg m^2, symmetric about body z) turning
    at ``omega_body`` (rad/s) from the identity attitude."""
    model = _model(wrapped, end=end, output_interval=0.05)
    away = np.array([50.0, 0.0, 0.0])
    model.node_positions = model.node_positions + away
    model.positions = model.positions + np.array([away, np.zeros(3)])
    model.omega_body = np.array([np.zeros(3), omega_body], float)
    return model


def _rotation(axis, angle):
    """Rotation matrices (k, 3, 3) about the unit ``axis`` by the angles (k,) (rad): Rodrigues."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    skew = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    angle = np.asarray(angle, float)[:, None, None]
    return np.eye(3) + np.sin(angle) * skew + (1.0 - np.cos(angle)) * skew @ skew


def test_recorded_attitude_of_a_spin_about_the_symmetry_axis(small_wrapped_net):
    """Torque-free spin of 1 rad/s about the debris' symmetry axis (body z) for 5 s: omega stays constant in
    body and in inertial components (Euler's equations: omega x J omega = 0), and the recorded attitude
    (series' ``debris_to_inertial``, the full-net runs' cached attitude) is the rotation about z by omega t.
    Tolerances: 1e-9 rad/s on the rates (round-off of 2500 steps) and 1e-6 rad on the attitude (the Lie-group
    update of a constant rate is exact up to round-off)."""
    omega = np.array([0.0, 0.0, 1.0])
    s = run_exudyn(_free_debris(small_wrapped_net, omega)).series()
    t = s["time"] - s["time"][0]
    rot = s["debris_to_inertial"]
    assert s["net_contacts"].max() == 0 and t[-1] == pytest.approx(5.0)
    assert np.abs(s["debris_omega_body"] - omega).max() < 1e-9
    assert np.abs(np.einsum("kij,kj->ki", rot, s["debris_omega_body"]) - omega).max() < 1e-9
    assert np.abs(rot - _rotation(omega, t)).max() < 1e-6


def _tilted_top_errors(wrapped, step):
    """Largest errors of the recorded body rate (rad/s), attitude (-) and inertial angular momentum (relative)
    of a torque-free axisymmetric top (J_t = 240, J_z = 112.5 kg m^2, omega_body(0) = (0.3, 0, 1.0) rad/s) over
    5 s at ``step`` (s), against the analytic motion (Landau & Lifshitz, Mechanics, Sec. 33): the body-frame
    rate turns about body z at kappa = (J_t - J_z) / J_t omega_z = 0.53125 rad/s (omega_x = 0.3 cos kappa t,
    omega_y = -0.3 sin kappa t), L = J omega(0) is fixed in inertial space, and the attitude is
    R(t) = Rot(L / |L|, |L| t / J_t) Rot(z, kappa t) (body z cones about L at |L| / J_t = 0.5565 rad/s)."""
    j_t, j_z = 240.0, 112.5
    omega0 = np.array([0.3, 0.0, 1.0])
    model = _free_debris(wrapped, omega0)
    model.step = step
    s = run_exudyn(model).series()
    assert s["net_contacts"].max() == 0
    t = s["time"] - s["time"][0]
    kappa = (j_t - j_z) / j_t * omega0[2]
    omega_body = np.column_stack([0.3 * np.cos(kappa * t), -0.3 * np.sin(kappa * t), np.full_like(t, 1.0)])
    momentum = np.array([j_t, j_t, j_z]) * omega0
    analytic = _rotation(momentum, np.linalg.norm(momentum) / j_t * t) @ _rotation([0.0, 0.0, 1.0], kappa * t)
    rot = s["debris_to_inertial"]
    momentum_inertial = np.einsum("kij,kj->ki", rot, np.array([j_t, j_t, j_z]) * s["debris_omega_body"])
    return np.array([np.abs(s["debris_omega_body"] - omega_body).max(), np.abs(rot - analytic).max(),
                     np.abs(momentum_inertial - momentum).max() / np.linalg.norm(momentum)])


def test_recorded_attitude_of_a_tilted_spin_precesses_at_the_analytic_rates(small_wrapped_net):
    """The tilted top of :func:`_tilted_top_errors` at 2 ms and 1 ms. Exudyn's explicit VelocityVerlet on the
    Lie-group rotation nodes is first order in the rotational motion (measured: 3.7e-4 rad/s, 8.1e-4 and
    4.5e-4 at 2 ms; 1.9e-4, 4.0e-4, 2.2e-4 at 1 ms; 9.4e-5, 2.0e-4, 1.1e-4 at 0.5 ms), so the test asks for
    the recorded rates, attitude and inertial momentum within 1e-3 of the analytic motion at 2 ms and for the
    errors to halve with the step (ratio 0.5 +- 0.05: the recorded attitude converges to the analytic one)."""
    coarse, fine = _tilted_top_errors(small_wrapped_net, 2e-3), _tilted_top_errors(small_wrapped_net, 1e-3)
    assert np.all(coarse < 1e-3)
    np.testing.assert_allclose(fine / coarse, 0.5, atol=0.05)
