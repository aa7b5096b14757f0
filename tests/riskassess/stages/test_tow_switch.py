"""Switch from the full-net to the lower-order towing model at quasi-steady state (multibody/tow_switch.py,
riskassess/models/towing_fullnet.py::lower_order_after_switch): the switch happens when the criterion says,
and the state is continuous across it (system momentum, main-tether elongation and rate)."""
import numpy as np
import pytest

from multibody.net_towing import run_exudyn
from multibody.towing import run_exudyn as run_lower_order
from multibody.net import net_kinetic_energy_relative_to_body
from multibody.tow_switch import SwitchCriterion, net_internal_kinetic_energy, switch_time
from riskassess.cases.impact import load_model
from riskassess.cases.inputs import CaseError
from riskassess.cases.towing import TowingCase
from riskassess.models.towing_fullnet import full_net_model, lower_order_after_switch, switch_criterion
from riskassess.stages.tow_fullnet import joined_series

CASE = "cases/zenit2_towing.toml"


def test_criterion_needs_the_whole_window():
    # samples every 0.5 s; the conditions hold from 26.0 s on except a slack sample at 27.0 s: the 2 s window
    # restarts at 27.5 s and is full at 29.5 s; before thrust-on (earliest 25.5 s) nothing counts
    t = np.arange(25.0, 32.0, 0.5)
    kinetic = np.where(t < 26.0, 5.0, 0.1)
    tension = np.where(t == 27.0, 0.0, 100.0)
    criterion = SwitchCriterion(earliest=25.5, window=2.0, kinetic_energy_max=0.2, tension_rel_tol=0.2)
    assert switch_time(t, kinetic, tension, criterion) == pytest.approx(29.5)
    # a net energy above the calm bound that keeps growing (1 J/s: peak-to-peak 1 J over every window, above
    # 20 % of its window mean, which stays below 5 J until 34 s) is not stationary: no switch
    growing = 1.0 + 0.5 * (t - 25.0) / 0.5
    assert switch_time(t, growing, tension, criterion) is None
    # the same energy level held constant is stationary: the net moves, but the same way in every window
    assert switch_time(t, np.where(t < 26.0, 5.0, 1.1), tension, criterion) == pytest.approx(29.5)
    # a tension swinging +-15 % of its mean (peak-to-peak 30 %) is not steady at 20 %, is at 40 %
    swinging = tension * (1.0 + 0.15 * np.cos(np.pi * (t - 25.0)))
    assert switch_time(t, kinetic, swinging, criterion) is None
    loose = SwitchCriterion(earliest=25.5, window=2.0, kinetic_energy_max=0.2, tension_rel_tol=0.4)
    assert switch_time(t, kinetic, swinging, loose) == pytest.approx(29.5)


def test_block_means_accept_a_tension_that_repeats_every_revolution():
    # tension 100 N +- 75 N at the spin period P = 4 s, sampled every 0.1 s from 25 s, never slack: sample-wise it
    # varies by 150 % of its mean and never switches; averaged over blocks of one period (40 samples spread evenly
    # over the period: the sine's discrete mean is 0 to round-off) every block mean is 100 N, so the criterion
    # holds as soon as the window (two blocks, 8 s) lies after thrust-on: at 25 + 8 = 33 s
    t = 25.0 + 0.1 * np.arange(301)
    tension = 100.0 + 75.0 * np.sin(2.0 * np.pi * (t - 25.0) / 4.0)
    kinetic = np.full_like(t, 12.0)       # a net that flaps the same way every revolution: stationary, not calm
    sample_wise = SwitchCriterion(earliest=25.0, window=8.0, kinetic_energy_max=0.5, tension_rel_tol=0.2)
    assert switch_time(t, kinetic, tension, sample_wise) is None
    per_period = SwitchCriterion(earliest=25.0, window=8.0, kinetic_energy_max=0.5, tension_rel_tol=0.2, averaging=4.0)
    assert switch_time(t, kinetic, tension, per_period) == pytest.approx(33.0, abs=1e-9)
    # a mean that grows by 30 % from one period to the next is not quasi-steady: any two consecutive blocks (aligned
    # with the steps or not) have means in the ratio 1.3, peak-to-peak 0.3 / 1.15 = 26 % of their mean
    drifting = 100.0 * 1.3 ** np.floor((t - 25.0) / 4.0 + 1e-9)
    assert switch_time(t, kinetic, drifting, per_period) is None
    # the window must hold two blocks
    with pytest.raises(ValueError, match="at least two averaging blocks"):
        SwitchCriterion(earliest=25.0, window=6.0, kinetic_energy_max=0.5, tension_rel_tol=0.2, averaging=4.0)


def test_shipped_case_judges_the_tow_per_revolution(tmp_path):
    # cases/zenit2_towing_from_capture.toml leaves the averaging and window at their defaults: one debris spin period,
    # 360 / 17.52 deg/s = 20.548 s, and three of them; a window shorter than two blocks is a case error naming the key
    case = load_model("cases/zenit2_towing_from_capture.toml", TowingCase)
    criterion = switch_criterion(case)
    assert criterion.averaging == pytest.approx(360.0 / 17.52, rel=1e-12)
    assert criterion.window == pytest.approx(3.0 * 360.0 / 17.52, rel=1e-12)
    assert criterion.earliest == case.thrust.t_on and criterion.tension_rel_tol == 0.2
    text = open("cases/zenit2_towing_from_capture.toml", encoding="utf-8").read()
    short = tmp_path / "short_window.toml"
    short.write_text(text.replace("switch_tension_variation = 0.2", "switch_tension_variation = 0.2\nswitch_window = 30.0"))
    with pytest.raises(CaseError, match="full_net.switch_window must hold at least two averaging blocks"):
        load_model(short, TowingCase)


def test_internal_kinetic_energy_ignores_a_common_drift():
    # two nodes of 1 and 3 kg moving apart at 4 m/s relative: CoM frame energy m1 m2 / (m1 + m2) dv^2 / 2 = 6 J
    m = np.array([1.0, 3.0])
    v = np.array([[7000.0, 3.0, 0.0], [7000.0, -1.0, 0.0]])
    assert net_internal_kinetic_energy(m, v) == pytest.approx(6.0, rel=1e-9)


def test_a_net_turning_with_the_debris_carries_no_relative_kinetic_energy():
    # nodes on a ring of radius 2 m about a body spinning at 0.3 rad/s about z (axis through its CoM), the body
    # drifting at 7 km/s: riding on the body, each node moves at v_B + omega x r. About the net's own CoM (the
    # ring's centre) that is rigid rotation, sum m (omega r)^2 / 2 = 4 x 0.01 x 0.36 / 2 = 7.2e-3 J; relative to the
    # body's velocity field it is 0 (round-off of 7 km/s). A ring at rest in the drifting frame instead: 7.2e-3 J.
    com, v_body, omega = np.array([1.0, -2.0, 0.5]), np.array([7000.0, 100.0, -3.0]), np.array([0.0, 0.0, 0.3])
    angles = np.arange(4) * np.pi / 2
    arm = 2.0 * np.c_[np.cos(angles), np.sin(angles), np.zeros(4)]
    m = np.full(4, 0.01)
    riding = v_body + np.cross(omega, arm)
    assert net_internal_kinetic_energy(m, riding) == pytest.approx(7.2e-3, rel=1e-6)
    assert net_kinetic_energy_relative_to_body(m, com + arm, riding, com, v_body, omega) == pytest.approx(0.0, abs=1e-12)
    at_rest = np.tile(v_body, (4, 1))
    assert net_kinetic_energy_relative_to_body(m, com + arm, at_rest, com, v_body, omega) == pytest.approx(7.2e-3, rel=1e-9)


def small_tow(**full_net) -> TowingCase:
    """A small towing system built from the shipped case: 160 kg chaser, 900 kg debris (3 m x 1 m cylinder,
    spinning at 2 deg/s), 6 m net of 7 x 7 nodes, 0.5 kg, EA 5 kN (as tests/multibody/test_net_towing.py),
    3 m main tether, thrust ramp to 50 N over 2 s from 25 s; wrapped start."""
    case = load_model(CASE, TowingCase)
    ch = case.chaser.model_copy(update=dict(mass=160.0, principal_inertia=[26.7, 26.7, 26.7]))
    de = case.debris.model_copy(update=dict(nominal_mass=900.0, principal_inertia=[240.0, 240.0, 112.5], length=3.0,
                                            diameter=1.0, spin_rate_deg_s=2.0))
    st = case.sub_tethers.model_copy(update=dict(
        attachment_points_body=[[-0.5, 0, -1.6], [-0.5, 0, 1.4], [0.5, 0, -1.6], [0.5, 0, 1.4]], natural_length=2.0))
    fn = case.full_net.model_copy(update=dict(
        side_length=6.0, nodes_per_side=7, corner_mass=0.02, thread_axial_rigidity=5000.0, thread_damping=0.5,
        closing_axial_rigidity=5000.0, closed_fraction=0.2,
        contact=case.full_net.contact.model_copy(update=dict(stiffness=1e7)), **full_net))
    return case.model_copy(update=dict(
        chaser=ch, debris=de, sub_tethers=st, main_tether=case.main_tether.model_copy(update=dict(natural_length=3.0)),
        full_net=fn, thrust=case.thrust.model_copy(update=dict(max_force=50.0, t_slope=2.0)), net_mass=0.5))


@pytest.fixture(scope="module")
def switched():
    """The small tow with the switch on: window 0.5 s, net internal kinetic energy at most 0.01 J, tension
    peak-to-peak at most 50 % of its mean, from thrust-on (25 s); full-net run to at most 30 s. The thresholds
    are this test's: measured on this system (1 s windows), the tether is taut at 26-27 s (26-37 N, peak-to-peak
    0.32 of the mean) with the net at 2e-3 J, before the first snap at ~27.5 s; the test is about when and how
    the switch happens, not about the shipped thresholds (docs/towing.md: the shipped case never settles)."""
    case = small_tow(switch_to_lower_order=True, switch_window=0.5, switch_averaging=0.0, switch_kinetic_energy=0.01,
                     switch_tension_variation=0.5)
    model = full_net_model(case, end_time=30.0)
    return case, model, run_exudyn(model)


def _first_quasi_steady(time, kinetic, tension, criterion):
    """Brute force over the samples (sample-wise criterion): the first t whose window [t - w, t] lies after
    ``earliest``, holds only samples with T > 0, a tension peak-to-peak within rel_tol of its mean, and an energy
    (relative to the debris) either at most E_max everywhere or within rel_tol of its mean (independent of the
    watch's bookkeeping)."""
    for t in time:
        inside = (time >= t - criterion.window - 1e-9) & (time <= t)
        if t - criterion.window < criterion.earliest - 1e-9 or t - criterion.window < time[0] - 1e-9:
            continue
        f, e = tension[inside], kinetic[inside]
        calm_or_steady = e.max() <= criterion.kinetic_energy_max or np.ptp(e) <= criterion.tension_rel_tol * e.mean()
        if calm_or_steady and f.min() > 0.0 and np.ptp(f) <= criterion.tension_rel_tol * np.abs(f).mean():
            return t
    return None


def test_switch_happens_when_the_criterion_says(switched):
    case, model, result = switched
    assert result.switch is not None, "the small tow never met the criterion by 30 s"
    s = result.series()
    t_switch = result.switch["time"]
    # the run stopped at the switch: its last sample is the switch time
    assert s["time"][-1] == pytest.approx(t_switch, abs=1e-9)
    criterion = switch_criterion(case)
    assert _first_quasi_steady(s["time"], s["net_kinetic_energy_relative_to_debris"], s["main_tether_tension"],
                               criterion) == \
        pytest.approx(t_switch, abs=1e-9)


def test_states_are_continuous_across_the_switch(switched):
    case, model, result = switched
    lower, balance = lower_order_after_switch(case, result, end_time=result.switch["time"] + 1.0)
    sw = result.switch
    # linear momentum of chaser + debris + net equals that of chaser + debris + P by construction (the debris
    # takes the net's momentum that P does not carry); tolerance: round-off of sums of ~8e7 N s, 1e-6 N s
    np.testing.assert_allclose(balance["momentum_lower_order_Ns"], balance["momentum_full_net_Ns"], rtol=0, atol=1e-6)
    # that correction is small: the net's momentum relative to its central node, m_net |v_com - v_node|, bounded by
    # the net's kinetic energy about its CoM at the switch (m_node |v_node - v_com|^2 / 2 <= E_int), spread over the
    # debris mass
    m = model.net.topology.masses
    e_int = result.series()["net_internal_kinetic_energy"][-1]
    assert balance["net_relative_momentum_Ns"] <= m.sum() * np.sqrt(2.0 * e_int / m[model.net.central]) * (1 + 1e-9)
    assert balance["debris_velocity_change_m_s"] <= balance["net_relative_momentum_Ns"] / case.debris.nominal_mass * 1.01
    # the lower-order model starts where the net was: chaser, debris attitude and rates copied, P at the
    # central node with its velocity (main-tether elongation and rate continuous)
    np.testing.assert_array_equal(lower.positions[0], sw["node_positions"][model.net.central])
    np.testing.assert_array_equal(lower.velocities[0], sw["node_velocities"][model.net.central])
    np.testing.assert_array_equal(lower.omega_body, [sw["v"][3:6], sw["v"][9:12]])
    assert lower.start_time == sw["time"]
    low = run_lower_order(lower).series()
    full = result.series()
    assert low["main_tether_elongation"][0] == pytest.approx(full["main_tether_elongation"][-1], abs=1e-9)
    # the elongation rate from the switch state itself: u . (v_node - v_A), v_A = v_C + R_C (omega_C x r_A)
    node_x, node_v = sw["node_positions"][model.net.central], sw["node_velocities"][model.net.central]
    rot_c = full["chaser_to_inertial"][-1]
    a_point = full["chaser_com_inertial"][-1] + rot_c @ model.attach_chaser_body
    a_velocity = sw["v"][0:3] + rot_c @ np.cross(sw["v"][3:6], model.attach_chaser_body)
    u = (node_x - a_point) / np.linalg.norm(node_x - a_point)
    assert low["main_tether_elongation_rate"][0] == pytest.approx(u @ (node_v - a_velocity), abs=1e-9)
    # the full-net sample is the rate inside the net's last sub-step (chaser attachment predicted to the step's
    # end from its half-step velocity): measured 4e-4 m/s apart here, 0.1 N of the 300 N s/m damper
    assert low["main_tether_elongation_rate"][0] == pytest.approx(full["main_tether_elongation_rate"][-1], abs=1e-3)
    np.testing.assert_allclose(low["chaser_com_inertial"][0], full["chaser_com_inertial"][-1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(low["debris_com_inertial"][0], full["debris_com_inertial"][-1], rtol=0, atol=1e-9)
    joined = joined_series({k: v for k, v in full.items() if not k.startswith("net_") or k == "net_internal_kinetic_energy"},
                           low)
    assert np.all(np.diff(joined["time"]) > 0) and joined["lower_order"].sum() == len(low["time"]) - 1


def test_tow_stage_writes_the_joined_run(tmp_path):
    # `riskassess tow` on the small tow with the switch: towing.npz holds the full-net samples, then the
    # lower-order ones (lower_order says which); towing.json the switch record
    import json

    from riskassess.stages.tow import tow_case

    case = small_tow(switch_to_lower_order=True, switch_window=0.5, switch_averaging=0.0, switch_kinetic_energy=0.01,
                     switch_tension_variation=0.5)
    case = case.model_copy(update=dict(simulation=case.simulation.model_copy(update=dict(model="full-net", end_time=30.0))))
    summary = tow_case(CASE, tmp_path / "tow", case=case)
    record = json.loads((tmp_path / "tow" / "towing.json").read_text())["switch"]
    assert record is not None and record["time_s"] == summary["switch"]["time_s"]
    data = np.load(tmp_path / "tow" / "towing.npz")
    switched_at = data["time"][np.argmax(data["lower_order"])]
    assert data["time"][-1] == pytest.approx(30.0) and switched_at == pytest.approx(record["time_s"] + 0.1)
    assert np.all(np.isnan(data["sub_tether_tension"][~data["lower_order"]]))
    assert np.all(np.isfinite(data["main_tether_tension"]))
