"""Lower-order towing model (multibody/towing.py): tether physics, orbit, Exudyn against its twin."""
import numpy as np
import pytest

from multibody.net import tension_only_kelvin_voigt
from multibody.orbit import two_body_specific_energy
from multibody.towing import TowingModel, run_exudyn, run_twin

MU = 3.986004418e14   # m^3/s^2
R_ORBIT = 7.218e6     # m, the seed paper's 840 km orbit (Boonrath et al. 2024, Sec. 4.1)


def _model(positions, velocities, masses, tether, mu=0.0, thrust=(0.0, 1e-9, 0.0), attach_debris=np.zeros((0, 3)),
           step=1e-3, end_time=1.0, output_interval=1e-3) -> TowingModel:
    """Connection point, chaser and debris with the attitude controller off; ``thrust`` = (t_on, t_slope, F_max)."""
    return TowingModel(
        masses=np.asarray(masses, float), inertia_body=np.array([np.eye(3), np.eye(3)]) * 10.0,
        attach_chaser_body=np.zeros(3), attach_debris_body=np.asarray(attach_debris, float),
        tether=np.asarray(tether, float), mu=mu, attitude=np.zeros(8), thrust_law="ramp", thrust_along_body_z=False,
        thrust_params=np.asarray(thrust, float), thrust_state=np.zeros(1),
        positions=np.asarray(positions, float), velocities=np.asarray(velocities, float),
        body_to_inertial=np.array([np.eye(3), np.eye(3)]), omega_body=np.zeros((2, 3)),
        start_time=0.0, end_time=end_time, step=step, output_interval=output_interval)


@pytest.fixture
def towed_mass_on_taut_tether():
    """P (1 kg) towed on the main tether (k = 100 N/m, no damping) by the chaser (3 kg) under a
    constant 10 N thrust, no gravity, released 2 cm beyond its steady stretch: the stretch
    oscillates about T0/k with omega = sqrt(k (1/m_P + 1/m_C)) and never slackens."""
    m_p, m_c, k, force, rest = 1.0, 3.0, 100.0, 10.0, 5.0
    tension0 = force * m_p / (m_p + m_c)                 # P's share of the thrust (N)
    stretch = tension0 / k + 0.02                        # amplitude 2 cm < steady stretch 2.5 cm
    speed = np.array([-1000.0, 0.0, 0.0])                # thrust acts against the velocity: along +x
    positions = [[-(rest + stretch), 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 100.0, 0.0]]
    model = _model(positions, [speed, speed, speed], [m_p, m_c, 1.0], [k, 0.0, rest, 0.0, 0.0, 1.0],
                   thrust=(-1.0, 1e-6, force), step=1e-3, end_time=4.0)
    return model, np.sqrt(k * (1 / m_p + 1 / m_c)), tension0 / k


def _zero_crossing_times(t, x):
    k = np.nonzero(np.sign(x[:-1]) != np.sign(x[1:]))[0]
    return t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])


def test_taut_tether_oscillates_at_analytic_frequency(towed_mass_on_taut_tether):
    model, omega, steady = towed_mass_on_taut_tether
    s = run_exudyn(model).series()
    stretch = s["main_tether_elongation"]
    assert stretch.min() > 0.0, "the tether must stay taut for the linear frequency to hold"
    crossings = _zero_crossing_times(s["time"], stretch - steady)
    measured = np.pi / np.mean(np.diff(crossings))
    # Verlet's frequency error is (omega h)^2 / 24 = 1e-5 here; linear interpolation of the
    # 1 ms samples at the crossings adds < 1e-4 over 5 periods: 5e-4 leaves room for both.
    assert measured == pytest.approx(omega, rel=5e-4)


def test_slack_tether_carries_no_force():
    """P 1 m inside the natural length, drifting towards the chaser at 0.1 m/s for 5 s: the tether
    stays slack, its tension is exactly zero and P moves on a straight line."""
    v = np.array([0.0, 0.0, 0.0])
    model = _model([[-4.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 100.0, 0.0]], [[0.05, 0.0, 0.0], v, v], [1.0, 3.0, 1.0],
                   [1e4, 100.0, 5.0, 0.0, 0.0, 1.0], end_time=5.0, output_interval=0.1)
    s = run_exudyn(model).series()
    assert np.all(s["main_tether_tension"] == 0.0)
    expected = np.outer(s["time"], [0.05, 0.0, 0.0]) + [-4.0, 0.0, 0.0]
    # no force at all: only round-off of the position updates (1e-12 m)
    np.testing.assert_allclose(s["connection_point_inertial"], expected, atol=1e-12)
    np.testing.assert_allclose(s["chaser_com_inertial"], 0.0, atol=1e-12)


def test_tension_law_pulls_only():
    # Kelvin-Voigt while stretched and pulling (Boonrath et al. eqs. 5a, 14a); exact arithmetic.
    assert tension_only_kelvin_voigt(0.1, 0.2, 100.0, 10.0) == pytest.approx(12.0, rel=1e-15)
    assert tension_only_kelvin_voigt(-0.1, 5.0, 100.0, 10.0) == 0.0     # slack: no force even when opening fast
    assert tension_only_kelvin_voigt(0.1, -2.0, 100.0, 10.0) == 0.0     # the damper would push: no force


@pytest.fixture
def free_bodies_on_circular_orbit():
    """P, chaser and debris 10 m apart on the seed paper's 840 km circular orbit, tethers without
    stiffness or damping, no thrust, no control: three Keplerian orbits of one period."""
    v_circ = np.sqrt(MU / R_ORBIT)
    period = 2 * np.pi * np.sqrt(R_ORBIT**3 / MU)
    angles = np.array([-10.0, 0.0, 10.0]) / R_ORBIT
    positions = R_ORBIT * np.c_[np.cos(angles), np.sin(angles), np.zeros(3)]
    velocities = v_circ * np.c_[-np.sin(angles), np.cos(angles), np.zeros(3)]
    step = period / 30000
    model = _model(positions, velocities, [1.0, 1600.0, 9000.0], np.zeros(6) + [0, 0, 15.0, 0, 0, 7.0], mu=MU,
                   step=step, end_time=period, output_interval=step * 100)
    return model, 2 * np.pi / 30000


def test_circular_orbit_stays_circular_over_one_orbit(free_bodies_on_circular_orbit):
    model, nh = free_bodies_on_circular_orbit
    s = run_exudyn(model).series()
    for key, velocity in (("chaser_com_inertial", "chaser_velocity_inertial"),
                          ("debris_com_inertial", "debris_velocity_inertial")):
        energy = two_body_specific_energy(s[key], s[velocity], MU)
        radius = np.linalg.norm(s[key], axis=1)
        # On a circular orbit Verlet follows a circle of its shadow Hamiltonian: no O(h^2) energy
        # oscillation, round-off only (1.7e-14 measured); 1e-12 fails on any force error of that size.
        assert np.abs(energy - energy[0]).max() / abs(energy[0]) < 1e-12
        # The shadow circle's radius and the phase lag are second order in n h = 2 pi / steps per
        # orbit: measured 0.500 (n h)^2 and 2.094 (n h)^2 at 15000, 30000 and 60000 steps per orbit
        # alike (so the error is the scheme's, not a drift); bounds 1 and 3 (n h)^2.
        assert np.abs(radius - R_ORBIT).max() / R_ORBIT < 1.0 * nh**2
        assert np.linalg.norm(s[key][-1] - s[key][0]) / R_ORBIT < 3.0 * nh**2


def test_exudyn_and_twin_agree(towed_mass_on_taut_tether):
    """The compiled twin integrates with Exudyn's own VelocityVerlet scheme: same samples to round-off."""
    model, _, _ = towed_mass_on_taut_tether
    exudyn, twin = run_exudyn(model), run_twin(model)
    np.testing.assert_allclose(exudyn.time, twin.time, rtol=0, atol=1e-12)
    # positions ~1e3 m from the origin after 4 s at 1 km/s: round-off 1e-13 relative
    np.testing.assert_allclose(exudyn.q, twin.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(exudyn.v, twin.v, rtol=0, atol=1e-9)
    np.testing.assert_allclose(exudyn.diag, twin.diag, rtol=0, atol=1e-8)


def test_stiff_damped_connection_point_follows_the_slow_mode_at_a_large_step():
    """A light P (10 g) on a strongly damped main tether (k = 100 N/m, c = 1000 N s/m) towed by a
    3 kg chaser under 10 N: gamma = c/m_P = 1e5 1/s, so an explicit step for P would have to stay
    below 2/gamma = 20 us; the implicit P (multibody/connection_point.py) runs at 1 ms. The stretch
    obeys mu z'' + c z' + k z = mu F/m_C (mu the reduced mass); started on the slow mode
    (z' = lambda (z - z_s)) it decays as z_s + delta exp(lambda t) exactly, with
    lambda = (-c + sqrt(c^2 - 4 mu k)) / (2 mu) = -0.1 1/s, and the tether stays taut."""
    m_p, m_c, k, c, force, rest, delta = 0.01, 3.0, 100.0, 1000.0, 10.0, 5.0, 0.02
    mu = m_p * m_c / (m_p + m_c)
    rate = (-c + np.sqrt(c * c - 4.0 * mu * k)) / (2.0 * mu)
    steady = mu * force / (m_c * k)
    speed = np.array([-1000.0, 0.0, 0.0])                # thrust acts against the velocity: along +x
    model = _model([[-(rest + steady + delta), 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 100.0, 0.0]],
                   [speed - [rate * delta, 0.0, 0.0], speed, speed], [m_p, m_c, 1.0], [k, c, rest, 0.0, 0.0, 1.0],
                   thrust=(-1.0, 1e-6, force), step=1e-3, end_time=20.0, output_interval=0.01)
    s = run_exudyn(model).series()
    assert s["main_tether_tension"].min() > 0.0
    exact = steady + delta * np.exp(rate * s["time"])
    # measured max error 1.24e-4 delta at 1 ms and 3.1e-5 delta at 0.5 ms (second order, BDF2 for
    # P with the chaser's predicted velocity); 5e-4 delta fails on a first-order coupling error
    # (~1e-2 delta) or an unstable P.
    assert np.abs(s["main_tether_elongation"] - exact).max() < 5e-4 * delta
