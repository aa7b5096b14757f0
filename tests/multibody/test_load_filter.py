"""The joints' load filter (multibody.load_filter): the discrete Butterworth against its analogue transfer function,
and a penalty joint under a known load, whose filtered reaction is the ideal constraint's load and converges in
penalty stiffness where the raw reaction does not."""
import math

import numpy as np
import pytest
import trimesh

from multibody.assembly import ContactLaw, ImpactAssembly, JointSpec, RigidBodySpec, SolverSpec
from multibody.hinge import hinge_frame_lvlh
from multibody.impact import ImpactSimulation
from multibody.load_filter import butterworth_sections, filter_bank, filter_signal, section_quality_factors
from multibody.recorded_loads import RecordedBodyLoads
from tests.conftest import single_node

STEP = 1e-4          # (s) the simulation step
CUTOFF_HZ = 20.0


def discrete_gain(sections, f):
    """|H(exp(j 2 pi f h))| of a cascade of biquads."""
    z = np.exp(-2j * math.pi * f * STEP)       # z^-1 on the unit circle
    return np.prod([abs((b0 + b1 * z + b2 * z * z) / (1 + a1 * z + a2 * z * z)) for b0, b1, b2, a1, a2 in sections])


def test_quality_factors_are_butterworths():
    # Butterworth pole pairs: Q = 1/sqrt(2) (order 2); 1 / (2 cos(pi/8)) = 0.5412, 1 / (2 cos(3 pi/8)) = 1.3066 (order 4)
    np.testing.assert_allclose(section_quality_factors(2), [1 / math.sqrt(2)], rtol=1e-14)
    np.testing.assert_allclose(sorted(section_quality_factors(4)), [0.5411961, 1.3065630], rtol=1e-6)


@pytest.mark.parametrize("order", [2, 4])
def test_gain_at_the_cutoff_is_the_analogue_filters(order):
    """Pre-warped bilinear transform: |H| at the cut-off is exactly 1/sqrt(2), as the analogue Butterworth's
    1 / sqrt(1 + (f / fc)^(2 n)); one decade above, 1/sqrt(1 + 10^(2 n)) (the discrete filter is 1-2 % lower
    there per order pair: the warping tan(x) / x at 200 Hz with a 1e-4 s step, second order in f h)."""
    sections = butterworth_sections(CUTOFF_HZ, STEP, order)
    for f, tolerance in ((CUTOFF_HZ, 1e-12), (0.3 * CUTOFF_HZ, 1e-3), (10 * CUTOFF_HZ, 0.03 * order / 2)):
        analogue = 1 / math.sqrt(1 + (f / CUTOFF_HZ) ** (2 * order))
        assert discrete_gain(sections, f) == pytest.approx(analogue, rel=tolerance)
    # the same gain measured on a simulated sinusoid at the cut-off, after the start-up transient (20 periods)
    t = np.arange(int(40 / CUTOFF_HZ / STEP)) * STEP
    out = filter_signal(sections, np.sin(2 * math.pi * CUTOFF_HZ * t))
    # 1e-3: the sampled crest misses the true one by at most 1 - cos(pi f h) = 2e-5; the transient has decayed by
    # exp(-zeta omega_c t) = exp(-0.707 * 125.7 * 1 s) ~ 1e-38
    assert np.abs(out[t > 20 / CUTOFF_HZ]).max() == pytest.approx(1 / math.sqrt(2), rel=1e-3)


def test_step_response_is_the_analogue_butterworths():
    """Unit step through the filter against the analogue 2nd-order Butterworth's closed form (zeta = 1/sqrt(2)):
    y = 1 - exp(-zeta w t) (cos(w_d t) + zeta / sqrt(1 - zeta^2) sin(w_d t)); overshoot exp(-pi) = 4.32 %."""
    t = np.arange(int(0.5 / STEP)) * STEP
    values = np.ones_like(t)
    values[0] = 0.0                          # at rest at 0, the step at the second sample
    out = filter_signal(butterworth_sections(CUTOFF_HZ, STEP, 2), values)
    w, zeta = 2 * math.pi * CUTOFF_HZ, 1 / math.sqrt(2)
    wd, tau = w * math.sqrt(1 - zeta**2), t - STEP
    analogue = np.where(tau >= 0, 1 - np.exp(-zeta * w * tau) * (np.cos(wd * tau) + zeta / math.sqrt(1 - zeta**2)
                                                                   * np.sin(wd * tau)), 0.0)
    # 3e-3: the bilinear transform's error on a step is of order omega_c h = 0.013 over the first sample (the
    # response's slope there is 0); measured 1.0e-3
    np.testing.assert_allclose(out, analogue, atol=3e-3)
    assert out.max() == pytest.approx(1 + math.exp(-math.pi), abs=1e-3)


def test_fourth_order_step_response_is_the_analogue_butterworths():
    """Unit step through the 4th-order filter against the analogue Butterworth's, summed from its partial fractions
    (poles p_k = omega_c exp(j pi (2k + n - 1) / (2 n)), k = 1..4: y = 1 + sum_k Re(r_k exp(p_k t) / p_k) with
    r_k = omega_c^4 / prod_{m != k} (p_k - p_m)); its overshoot is 10.8 %."""
    t = np.arange(int(0.5 / STEP)) * STEP
    values = np.ones_like(t)
    values[0] = 0.0
    out = filter_signal(butterworth_sections(CUTOFF_HZ, STEP, 4), values)
    w = 2 * math.pi * CUTOFF_HZ
    poles = w * np.exp(1j * np.pi * (2 * np.arange(1, 5) + 3) / 8)
    tau = np.maximum(t - STEP, 0.0)
    analogue = np.ones_like(t, dtype=complex)
    for k, p in enumerate(poles):
        residue = w**4 / np.prod([p - q for m, q in enumerate(poles) if m != k])
        analogue += residue * np.exp(p * tau) / p
    analogue = np.where(t >= STEP, analogue.real, 0.0)
    # 3e-3: the bilinear transform's error, of order omega_c h = 0.013 over the first sample (measured below 1e-3)
    np.testing.assert_allclose(out, analogue, atol=3e-3)
    assert out.max() == pytest.approx(analogue.max(), abs=1e-3)
    assert analogue.max() == pytest.approx(1.108, abs=1e-3)


def test_a_bank_starts_at_rest_and_a_zero_cutoff_passes_through():
    bank = filter_bank([0.0, CUTOFF_HZ, CUTOFF_HZ], STEP, [4, 4, 2])
    assert bank.shape == (3, 6, 2, 8)
    np.testing.assert_array_equal(bank[0, :, :, :5], [[[1.0, 0.0, 0.0, 0.0, 0.0]] * 2] * 6)
    np.testing.assert_array_equal(bank[2, :, 1, :5], [[1.0, 0.0, 0.0, 0.0, 0.0]] * 6)   # order 2: one section
    signal = np.full(100, 3.7)
    np.testing.assert_allclose(filter_signal(bank[1, 0, :, :5], signal), signal, rtol=1e-12)   # at rest: no transient
    with pytest.raises(ValueError, match="cut-off must be in"):
        butterworth_sections(600.0, STEP)       # above 1/10 of the step's 5 kHz Nyquist frequency
    with pytest.raises(ValueError, match="order is one of"):
        butterworth_sections(CUTOFF_HZ, STEP, 3)


# -- a penalty joint under a known load ----------------------------------------------------------------------------
BUS_MASS, BOOM_MASS = 500.0, 50.0       # (kg)
FORCE = 1000.0                          # (N) on the bus's CoM along LVLH x
RISE = 0.005                            # (s) the force's linear rise (a contact's rise time)
RATE = 1000.0                           # (Hz) output and recorded-load rate


def _box(mass, size):
    return RigidBodySpec(name=f"box{mass:g}", mass=mass, inertia_body=np.eye(3) * mass * size**2 / 6,
                         com_lvlh=np.zeros(3), meshes_body=[trimesh.creation.box(extents=[size] * 3)])


def pushed_pair(penalty: float, cutoff_hz: float, end_time=0.1, order=2):
    """A 50 kg boom clamped to a 500 kg bus by a penalty joint (translational stiffness ``penalty`` N/m), the bus
    pushed along the line of the two CoMs through the joint, so the ideal joint carries no moment and its force is
    the boom's share of the push, m_boom / (m_bus + m_boom) F(t)."""
    bus, boom = _box(BUS_MASS, 1.0), _box(BOOM_MASS, 0.5)
    bus.com_lvlh, boom.com_lvlh = np.array([0.0, 30.0, 0.0]), np.array([1.25, 30.0, 0.0])
    point = np.array([0.5, 30.0, 0.0])
    joint = JointSpec(name="root", kind="clamped", parent=0, child=1, point_lvlh=point,
                      hinge_to_lvlh=hinge_frame_lvlh(np.array([0.0, 0.0, 1.0]), point, boom.com_lvlh),
                      penalty_translational=penalty, penalty_rotational=penalty, load_filter_hz=cutoff_hz,
                      load_filter_order=order)
    time = np.arange(1, int(round(end_time * RATE)) + 1) / RATE
    force_lvlh = np.zeros((time.size, 2, 3))
    force_lvlh[:, 0, 0] = FORCE * np.minimum(time / RISE, 1.0)     # held over each output interval
    loads = RecordedBodyLoads(time=time, force_lvlh=force_lvlh, moment_body=np.zeros_like(force_lvlh),
                              reference_energy=10.0)
    assembly = ImpactAssembly(net=single_node([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]), net_velocity=np.zeros((1, 3)),
                              bodies=[bus, boom], joints=[joint], contact=ContactLaw(stiffness=1e8),
                              solver=SolverSpec(end_time=end_time, step=STEP, output_rate=RATE), body_loads=loads)
    return ImpactSimulation(assembly).run().series, loads


def ideal_force_filtered(loads, times):
    """The ideal (rigid) joint's force on the boom, m_boom / M F(t) with F held over each output interval, through
    the same filter at the simulation step, read at ``times``."""
    steps = np.arange(1, int(round(times[-1] / STEP)) + 1) * STEP
    held = loads.force_lvlh[np.minimum(np.searchsorted(loads.time, steps - 1e-9), loads.time.size - 1), 0, 0]
    ideal = BOOM_MASS / (BUS_MASS + BOOM_MASS) * held
    out = filter_signal(butterworth_sections(CUTOFF_HZ, STEP, 2), np.concatenate([[0.0], ideal]))
    return np.interp(times, np.concatenate([[0.0], steps]), out)


@pytest.fixture(scope="module")
def pushed_pairs():
    # penalty 1e8 N/m: the pair's axial mode sqrt(k (m1 + m2) / (m1 m2)) / 2 pi = 236 Hz; / 4: 118 Hz
    return {k: pushed_pair(k, CUTOFF_HZ) for k in (1e8, 2.5e7)}


def test_filtered_penalty_load_is_the_ideal_constraints(pushed_pairs):
    ideal_plateau = BOOM_MASS / (BUS_MASS + BOOM_MASS) * FORCE     # 90.9 N
    for series, loads in pushed_pairs.values():
        t = series["time"]
        filtered = np.linalg.norm(series["joint_force_filtered_joint"][:, 0], axis=1)
        # 3 % of the plateau: the penalty mode's ringing passes the 20 Hz filter with (20 / 118)^2 = 2.9 % at most
        # (k / 4), damped at 0.05 of critical; the held force is read half a step apart (0.1 % of the rise)
        np.testing.assert_allclose(filtered, np.abs(ideal_force_filtered(loads, t)), rtol=0, atol=0.03 * ideal_plateau)
        # the filter is a recording: the raw reaction is still there, and rings above the ideal's plateau
        raw = np.linalg.norm(series["joint_force_joint"][:, 0], axis=1)
        assert raw.max() > 1.1 * ideal_plateau


def test_filtered_peak_converges_in_penalty_stiffness_where_the_raw_one_does_not(pushed_pairs):
    stiff, soft = (pushed_pairs[k][0] for k in (1e8, 2.5e7))
    peak = lambda s, key: np.linalg.norm(s[key][:, 0], axis=1).max()
    filtered_change = peak(soft, "joint_force_filtered_joint") / peak(stiff, "joint_force_filtered_joint") - 1
    raw_change = peak(soft, "joint_force_joint") / peak(stiff, "joint_force_joint") - 1
    # undamped amplification of a 5 ms ramp, 1 + |2 sin(w tau / 2) / (w tau)|: 1.14 at 236 Hz, 1.52 at 118 Hz
    assert abs(filtered_change) < 0.05
    assert abs(raw_change) > 0.2


# -- a rigid appendage's torsion under a known torque: the ASAR mount of envisat_small (helper asar20) -------------------
# envisat_small's main body and ASAR plate (cases/envisat_small.toml): masses (kg), inertias about the CoMs (kg m^2,
# body frame = LVLH at rest), the ASAR's CoM 1.953 m and its mount 1.875 m from the main body's CoM along -y; the
# ASAR's beam axis (the section's axis 1) is z. The mount keeps the automatic penalty, capped at 1e9 N/m and
# 1e8 N m/rad as in the run: its modes (185-203 Hz translations, 20.5 / 126.7 / 20.6 Hz rotations) do not follow the
# step, as docs/structures.md measures for the ASAR's judged shear.
MAIN_MASS, MAIN_INERTIA = 6621.0, np.diag([41976.11, 40501.90, 14043.76])
ASAR_MASS, ASAR_INERTIA = 832.0, np.diag([6935.02, 7089.33, 157.69])
ASAR_COM_Y, ASAR_MOUNT_Y = -1.953, -1.875          # (m) from the main body's CoM
ASAR_CUTOFF_HZ, ASAR_ORDER = 3.0, 4                # the study's load filter on the ASAR mount
TWIST_END = 1.2                                     # (s): the 3 Hz filter's step response settles (10.8 % overshoot)


def twisted_mount(step: float, torque_main: float, torque_asar: float):
    """The main body and the ASAR clamped at their mount, torques about LVLH z (N m) rising over RISE on each (the
    net's contact moment on the ASAR, a strike's on the main body); returns the run's series and the applied loads."""
    y0 = 30.0
    main = RigidBodySpec(name="main_body", mass=MAIN_MASS, inertia_body=MAIN_INERTIA, com_lvlh=np.array([0.0, y0, 0.0]),
                         meshes_body=[trimesh.creation.box(extents=[3.375, 3.75, 7.875])])
    asar = RigidBodySpec(name="asar", mass=ASAR_MASS, inertia_body=ASAR_INERTIA,
                         com_lvlh=np.array([0.0, y0 + ASAR_COM_Y, 0.0]),
                         meshes_body=[trimesh.creation.box(extents=[1.5, 0.156, 10.0])])
    point = np.array([0.0, y0 + ASAR_MOUNT_Y, 0.0])
    joint = JointSpec(name="asar_mount", kind="clamped", parent=0, child=1, point_lvlh=point,
                      hinge_to_lvlh=hinge_frame_lvlh(np.array([0.0, 0.0, 1.0]), point, asar.com_lvlh),
                      load_filter_hz=ASAR_CUTOFF_HZ, load_filter_order=ASAR_ORDER)
    time = np.arange(1, int(round(TWIST_END * RATE)) + 1) / RATE
    moment_body = np.zeros((time.size, 2, 3))
    ramp = np.minimum(time / RISE, 1.0)                 # held over each output interval
    moment_body[:, 0, 2], moment_body[:, 1, 2] = torque_main * ramp, torque_asar * ramp
    loads = RecordedBodyLoads(time=time, force_lvlh=np.zeros_like(moment_body), moment_body=moment_body,
                              reference_energy=10.0)
    assembly = ImpactAssembly(net=single_node([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]), net_velocity=np.zeros((1, 3)),
                              bodies=[main, asar], joints=[joint], contact=ContactLaw(stiffness=1e8),
                              solver=SolverSpec(end_time=TWIST_END, step=step, output_rate=RATE), body_loads=loads)
    series = ImpactSimulation(assembly).run().series
    return series, loads, joint.hinge_to_lvlh


def rigid_mount_loads(torque_main: float, torque_asar: float) -> tuple[float, float]:
    """The ideal (rigid) mount's torsion about z (N m, about the mount point) and force along x (N) on the ASAR under
    steady torques about z (a couple on a free pair: its CoM stays, it spins up at alpha = T / I_zz about the pair's
    CoM; small angles): Newton-Euler on the ASAR,

        F_j = m_a a_C = -m_a alpha d_a x,    M_j,z = I_a,zz alpha - T_asar + [(C - P) x F_j]_z

    with d_a the ASAR's CoM from the pair's CoM along y and C - P = (ASAR_COM_Y - ASAR_MOUNT_Y) y."""
    total = MAIN_MASS + ASAR_MASS
    d_main, d_asar = -ASAR_MASS * ASAR_COM_Y / total, MAIN_MASS * ASAR_COM_Y / total      # along y, from the pair's CoM
    inertia_zz = MAIN_INERTIA[2, 2] + ASAR_INERTIA[2, 2] + MAIN_MASS * d_main**2 + ASAR_MASS * d_asar**2
    alpha = (torque_main + torque_asar) / inertia_zz
    force_x = -ASAR_MASS * alpha * d_asar
    lever_y = ASAR_COM_Y - ASAR_MOUNT_Y
    return ASAR_INERTIA[2, 2] * alpha - torque_asar - lever_y * force_x, force_x     # [(C - P) x F]_z = -lever_y F_x


def held_ramp_filtered(times, step: float) -> np.ndarray:
    """The torques' unit ramp, held over each output interval, through the mount's load filter at ``step``, at
    ``times`` (the ideal mount's loads are this times their plateau)."""
    steps = np.arange(1, int(round(times[-1] / step)) + 1) * step
    held = np.minimum(np.ceil(steps * RATE - 1e-6) / RATE / RISE, 1.0)      # the output interval holding each step
    out = filter_signal(butterworth_sections(ASAR_CUTOFF_HZ, step, ASAR_ORDER), np.concatenate([[0.0], held]))
    return np.interp(times, np.concatenate([[0.0], steps]), out)


@pytest.mark.parametrize("torque_main, torque_asar", [(1000.0, 0.0), (0.0, 10.0)], ids=["strike on the main body",
                                                                                        "contact on the asar"])
def test_asar_mount_torsion_is_the_rigid_appendages_independent_of_the_step(torque_main, torque_asar):
    """The ASAR mount's filtered torsion and transverse force under a known torque equal the rigid appendage's
    (Newton-Euler, :func:`rigid_mount_loads`) through the same filter, at the run's step and at a quarter of it:
    the joint model and the load extraction do not make the judged ASAR shear follow the step."""
    torsion_plateau, force_plateau = rigid_mount_loads(torque_main, torque_asar)
    peaks = {}
    for step in (1e-4, 2.5e-5):
        series, _, hinge_to_lvlh = twisted_mount(step, torque_main, torque_asar)
        t = series["time"]
        torsion = series["joint_moment_filtered_joint"][:, 0] @ (hinge_to_lvlh.T @ [0.0, 0.0, 1.0])
        force_x = series["joint_force_filtered_joint"][:, 0] @ (hinge_to_lvlh.T @ [1.0, 0.0, 0.0])
        ideal = held_ramp_filtered(t, step)
        # 2e-3 of the plateau: the mount's rotation modes (20.5 Hz and up), excited by the 5 ms rise about as much as
        # the load itself, pass the 4th-order 3 Hz filter with (3 / 20.5)^4 = 4.6e-4 of their ringing; the spin-up's
        # centripetal and gyroscopic terms are (alpha t)^2 = 5e-7 of the load at 1.2 s (measured: 1.4e-4 and 2.7e-4
        # at every step, 2026-11-27)
        np.testing.assert_allclose(torsion, torsion_plateau * ideal, rtol=0, atol=2e-3 * abs(torsion_plateau))
        np.testing.assert_allclose(force_x, force_plateau * ideal, rtol=0, atol=2e-3 * abs(force_plateau))
        peaks[step] = np.abs(torsion).max()
    # the filtered peak (10.8 % over the plateau: the 4th-order filter's overshoot) does not follow the step: within
    # the tolerance above, far inside Deliver 1's 5 % (measured: the same to 7 digits at 1e-4, 5e-5 and 2.5e-5 s)
    assert peaks[2.5e-5] == pytest.approx(peaks[1e-4], rel=2e-3)
