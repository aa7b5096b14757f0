"""The chaser's lateral station-keeping law (multibody/control/lateral.py): its closed loop on a point-mass chaser
held by a pendulum tether (the lateral error decays as exp(-zeta_L omega_L t) at the damped frequency of
e'' + 2 zeta_L omega_L e' + (omega_L^2 + g / L) e = 0), the target lines' geometry (on the tow-point line the main
tether's line passes through the debris CoM), the error rate against a difference quotient, the side thrusters'
plane and limit, and the case checks."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from multibody.control.lateral import (L_MASS, L_MAX, L_ON, L_SIZE, TARGETS, lateral_error, lateral_params,
                                       lateral_thrust, side_thrust, target_axis, tow_point_line_force)
from multibody.towing import packed
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing import towing_model
from riskassess.models.towing_fullnet import case_lateral
from tests.multibody.control.notch_cases import CASE

M_C = 1600.0          # chaser mass (kg), Boonrath et al. 2024 Table 1
L_TETHER = 15.5       # tow point -> chaser (m): the wrapped start of the shipped case (|C - P| = 15.50 m)
D_TOW = 1.97          # debris CoM -> tow point (m): the same start (|P - G| = 1.967 m)
G_TOW = 141.0 / (1600.0 + 9000.0)   # tow acceleration (m/s^2): the laws' steady 141 N on chaser + debris
OMEGA_L, ZETA_L = 0.2, 0.7          # an underdamped loop, so that both the decay and the frequency are tested


def _chaser_on_pendulum(theta, theta_rate):
    """Chaser CoM, velocity and attitude (body z along the tether, away from the tow point at the origin) at angle
    ``theta`` (rad) from the x axis, in the plane z = 0."""
    c, s = math.cos(theta), math.sin(theta)
    com = L_TETHER * np.array([c, s, 0.0])
    vel = L_TETHER * theta_rate * np.array([-s, c, 0.0])
    rot = np.column_stack([[0.0, 0.0, 1.0], [s, -c, 0.0], [c, s, 0.0]])   # body x, y, z in inertial columns
    return com, vel, rot


def _pendulum_rate(target, params):
    """theta'' of the pendulum chaser (tether of fixed length L to the tow point at the origin, the tow's
    acceleration g along +x as its gravity, the debris CoM at (-D, 0, 0) at rest) under the lateral law."""
    com_d, zero = np.array([-D_TOW, 0.0, 0.0]), np.zeros(3)
    momentum_d = np.array([-4.8e4, 0.0, 0.0])   # along -x: the law turns it towards the chaser

    def rate(t, y):
        com, vel, rot = _chaser_on_pendulum(y[0], y[1])
        force = lateral_thrust(t, params, com, vel, rot, com_d, zero, zero, zero, momentum_d)
        tangent = np.array([-math.sin(y[0]), math.cos(y[0]), 0.0])
        return [y[1], -G_TOW / L_TETHER * math.sin(y[0]) + force @ tangent / (M_C * L_TETHER)]
    return rate


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_lateral_error_decays_at_the_stated_rate(target):
    params = lateral_params(True, target, OMEGA_L, ZETA_L, 50.0, 0.0, M_C)
    theta0 = 1e-3                                       # rad: 15.5 mm off the line, the law's force ~1 N
    t = np.linspace(0.0, 60.0, 601)
    run = solve_ivp(_pendulum_rate(target, params), (0.0, 60.0), [theta0, 0.0], t_eval=t, method="DOP853",
                    rtol=1e-12, atol=1e-16)
    sigma = ZETA_L * OMEGA_L                            # decay rate (1/s) of the linearised loop (module doc)
    omega_d = math.sqrt(OMEGA_L ** 2 + G_TOW / L_TETHER - sigma ** 2)
    linear = theta0 * np.exp(-sigma * t) * (np.cos(omega_d * t) + sigma / omega_d * np.sin(omega_d * t))
    # the nonlinear pendulum and law differ from the linear solution by O(theta^2) = 1e-6 relative; the integrator's
    # error is below 1e-10 relative
    assert np.max(np.abs(run.y[0] - linear)) < 2e-6 * theta0
    envelope = theta0 * math.hypot(1.0, sigma / omega_d) * np.exp(-sigma * t)   # the stated decay, e^{-8.4} by 60 s
    assert np.all(np.abs(run.y[0]) <= envelope * (1.0 + 1e-3))


def test_on_the_tow_point_line_the_tether_passes_through_the_debris_com():
    com_d, tow_point = np.zeros(3), np.array([0.217, -1.953, 0.074])   # the shipped start's P - G (body frame, m)
    n, _ = target_axis(TARGETS["tow_point"], com_d, np.zeros(3), tow_point, np.zeros(3), np.ones(3), np.ones(3))
    chaser = com_d + 17.4 * n
    e, _ = lateral_error(n, np.zeros(3), chaser, np.zeros(3), com_d, np.zeros(3))
    assert np.linalg.norm(e) < 1e-12
    # moment arm of the tension (along chaser - P) about the debris CoM: |(P - G) x u| = 0 on the line
    u = (chaser - tow_point) / np.linalg.norm(chaser - tow_point)
    assert np.linalg.norm(np.cross(tow_point - com_d, u)) < 1e-12
    side = np.cross(n, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    e, _ = lateral_error(n, np.zeros(3), chaser + 0.3 * side + 2.0 * n, np.zeros(3), com_d, np.zeros(3))
    np.testing.assert_allclose(e, 0.3 * side, atol=1e-12)   # the along-line part is not an error


@pytest.mark.parametrize("seed", range(5))
def test_error_rate_is_the_derivative_of_the_error(seed):
    """The tow-point target turns with the debris: e' (with n') against a central difference quotient of e along a
    motion where P turns about the debris CoM and both bodies move (h = 1e-5 s: truncation ~h^2 e''' ~ 1e-10 m/s)."""
    rng = np.random.default_rng(seed)
    w, r0, c0, vc, vd = rng.normal(size=3), rng.normal(size=3), 17.0 * rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    r0 += 2.0 * c0 / np.linalg.norm(c0)                # P on the chaser's side, ~2 m out

    def error(t):
        rot = Rotation.from_rotvec(w * t).as_matrix()
        com_d, com_c = vd * t, c0 + vc * t
        p, p_vel = com_d + rot @ r0, vd + np.cross(w, rot @ r0)
        n, n_rate = target_axis(TARGETS["tow_point"], com_d, vd, p, p_vel, np.ones(3), com_c)
        return lateral_error(n, n_rate, com_c, vc, com_d, vd)

    h = 1e-5
    quotient = (error(h)[0] - error(-h)[0]) / (2.0 * h)
    np.testing.assert_allclose(error(0.0)[1], quotient, atol=1e-7)


@pytest.mark.parametrize("seed", range(5))
def test_side_thrust_stays_in_the_body_plane_and_within_its_limit(seed):
    rng = np.random.default_rng(seed)
    rot = Rotation.random(random_state=seed).as_matrix()
    force = 100.0 * rng.normal(size=3)
    side = side_thrust(force, rot, 30.0)
    assert abs(side @ rot[:, 2]) < 1e-12 * np.linalg.norm(force)      # nothing along the tether (body z)
    in_plane = force - (force @ rot[:, 2]) * rot[:, 2]
    expected = in_plane * min(1.0, 30.0 / np.linalg.norm(in_plane))
    np.testing.assert_allclose(side, expected, atol=1e-12 * np.linalg.norm(force))


def test_off_and_before_t_on_no_force():
    args = (np.array([0.0, 17.0, 1.0]), np.ones(3), np.eye(3), np.zeros(3), np.zeros(3), np.array([0.0, 2.0, 0.2]),
            np.zeros(3), np.array([0.0, 1.0, 0.0]))
    assert np.array_equal(lateral_params(False, "tow_point", 0.2, 1.0, 50.0, 25.0, M_C), np.zeros(L_SIZE))
    off = lateral_params(False, "tow_point", 0.2, 1.0, 50.0, 25.0, M_C)
    on = lateral_params(True, "momentum_axis", 0.2, 1.0, 50.0, 25.0, M_C)
    assert np.array_equal(lateral_thrust(30.0, off, *args), np.zeros(3))
    assert np.array_equal(lateral_thrust(24.9, on, *args), np.zeros(3))
    assert np.linalg.norm(lateral_thrust(25.0, on, *args)) > 0.0
    with pytest.raises(ValueError, match="known: \\['momentum_axis', 'tow_point'\\]"):
        lateral_params(True, "spin", 0.2, 1.0, 50.0, 25.0, M_C)


def _case_data(**lateral):
    data = load_model(CASE, TowingCase).model_dump()
    data["lateral"] = {"enabled": True, **lateral}
    return data


def test_case_checks():
    shipped = load_model(CASE, TowingCase).lateral
    assert shipped.enabled and shipped.target == "momentum_axis"        # on in the shipped case (docs/towing.md)
    assert shipped.thrust_laws == ["mrac1", "mrac2"]                    # with the elongation laws only
    data = _case_data()
    data["attitude_control"]["enabled"] = False
    with pytest.raises(ValueError, match="attitude_control.enabled"):
        TowingCase.model_validate(data)
    with pytest.raises(ValueError, match="momentum_axis"):
        TowingCase.model_validate(_case_data(target="centre"))
    with pytest.raises(ValueError, match="max_force"):
        TowingCase.model_validate(_case_data(max_force=-5.0))
    with pytest.raises(ValueError, match="thrust_laws"):
        TowingCase.model_validate(_case_data(thrust_laws=["mrac3"]))
    with pytest.raises(ValueError, match="thrust_laws"):
        TowingCase.model_validate(_case_data(thrust_laws=[]))


def _with_law(kind: str, enabled: bool) -> TowingCase:
    """The shipped case with ``thrust.kind = kind`` and the lateral law on or off (other keys as shipped)."""
    case = load_model(CASE, TowingCase)
    return case.model_copy(update=dict(thrust=case.thrust.model_copy(update=dict(kind=kind)),
                                       lateral=case.lateral.model_copy(update=dict(enabled=enabled))))


@pytest.mark.parametrize("kind, acts", [("ramp", False), ("mrac1", True), ("mrac2", True)])
def test_the_law_acts_with_the_elongation_laws_only(kind, acts):
    """``lateral.thrust_laws`` (default mrac1, mrac2): with the ramp, the papers' open-loop thrust of the
    identification runs, the full-net kernel gets the all-zero vector it skips (the runs, and the identification cache
    keyed on rate and end time, stay what they were); with either elongation law it gets the law's constants."""
    params = case_lateral(_with_law(kind, True))
    assert np.array_equal(params, np.zeros(L_SIZE)) is not acts
    if acts:
        assert params[L_ON] == 1.0 and params[L_MAX] == 50.0 and params[L_MASS] == M_C


@pytest.mark.parametrize("kind", ["ramp", "mrac1", "mrac2"])
def test_the_lower_order_model_is_the_same_with_the_law_on(kind):
    """The lateral law is the full-net plant's: the lower-order model (no lateral thrust on its chaser) packs the same
    array, bit for bit, with ``[lateral]`` on and off, so its runs of the shipped case do not change."""
    on, off = (packed(towing_model(_with_law(kind, enabled), 29.01)).work for enabled in (True, False))
    assert np.array_equal(on, off)


def test_tow_point_line_force_of_the_shipped_case():
    """What following the tow-point line costs at 29.01 deg/s: the shipped wrapped start has the tow point 0.232 m
    off the spin axis (body x 0.074, z -0.220 m) at |P - G| = 1.967 m, the chaser at |C - G| = 17.46 m -> a 2.06 m
    circle at 0.506 rad/s: m_C omega^2 r = 1600 x 0.2563 x 2.06 = 845 N (hand arithmetic; four times the 200 N
    tether-axis thrust)."""
    omega = math.radians(29.01)
    force = tow_point_line_force(0.2321, 1.9673, 17.463, omega, M_C)
    assert force == pytest.approx(M_C * omega ** 2 * 0.2321 * 17.463 / 1.9673, rel=1e-15)
    assert 835.0 < force < 855.0
