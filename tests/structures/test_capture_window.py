"""The capture as the judged window (structures/capture_window.py): the net's kinetic energy relative to the debris,
the settle test, and a run capped before the capture is over never reading "no debris"."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from riskassess.cases.impact import CaseError, load_case
from riskassess.stages.run import run_case
from multibody.net import net_kinetic_energy_relative_to_body
from structures.capture_window import (CAPTURE_ENERGY_FRACTION, CAPTURE_HOLD_TRAVEL_M, capture_gap, energy_threshold,
                                       first_settled, hold_time, omega_lvlh, rise_times, settle_time)

CASES = Path(__file__).resolve().parents[2] / "cases"
SNAPSHOT_S = 0.02   # s, the shipped cases' net snapshots (50 Hz): the settle test's time resolution


def _net_and_body(rng, n=40):
    masses = rng.uniform(0.02, 2.0, n)
    com_lvlh = rng.normal(0.0, 5.0, 3)
    positions_lvlh = com_lvlh + rng.normal(0.0, 8.0, (n, 3))
    velocity_lvlh = rng.normal(0.0, 3.0, 3)
    omega_body_lvlh = rng.normal(0.0, 0.5, 3)
    return masses, positions_lvlh, com_lvlh, velocity_lvlh, omega_body_lvlh


@pytest.mark.parametrize("seed", range(5))
def test_a_net_moving_rigidly_with_a_spinning_body_has_no_relative_energy(seed):
    rng = np.random.default_rng(seed)
    masses, x, c, vc, w = _net_and_body(rng)
    v = vc + np.cross(w, x - c)             # every node on the body's velocity field
    energy = net_kinetic_energy_relative_to_body(masses, x, v, c, vc, w)
    absolute = 0.5 * np.sum(masses * np.sum(v ** 2, axis=1))
    # round-off of the subtraction: a few ulp of the nodes' own kinetic energy
    assert abs(energy) <= 1e-13 * absolute


@pytest.mark.parametrize("seed", range(5))
def test_a_known_relative_motion_has_half_m_v_squared(seed):
    rng = np.random.default_rng(seed)
    masses, x, c, vc, w = _net_and_body(rng)
    u = rng.normal(0.0, 1.0, 3)             # the same drift of every node past the spinning body
    v = vc + np.cross(w, x - c) + u
    expected = 0.5 * masses.sum() * u @ u   # 1/2 m v^2 of the drift alone
    assert net_kinetic_energy_relative_to_body(masses, x, v, c, vc, w) == pytest.approx(expected, rel=1e-12)
    # over several instants at once (k, n, 3), the same per instant
    energies = net_kinetic_energy_relative_to_body(masses, np.stack([x, x]), np.stack([v, vc + np.cross(w, x - c)]),
                                                   np.stack([c, c]), np.stack([vc, vc]), np.stack([w, w]))
    np.testing.assert_allclose(energies, [expected, 0.0], rtol=1e-12, atol=1e-12 * expected)


def test_the_body_rate_is_rotated_into_lvlh():
    rng = np.random.default_rng(7)
    body_to_lvlh = Rotation.from_rotvec(rng.normal(0.0, 1.0, 3)).as_matrix()
    omega_body = rng.normal(0.0, 1.0, 3)
    np.testing.assert_allclose(omega_lvlh(body_to_lvlh, omega_body), body_to_lvlh @ omega_body, rtol=1e-14)


def test_mismatched_masses_are_refused():
    with pytest.raises(ValueError, match=r"masses must have shape \(3,\)"):
        net_kinetic_energy_relative_to_body(np.ones(2), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3),
                                            np.zeros(3), np.zeros(3))


def test_a_running_peak_rises_only_above_every_earlier_judged_value():
    t = np.arange(8) * 0.1
    d = np.array([5.0, 1.0, 2.0, 6.0, 6.0, 3.0, 7.0, 1.0])
    # judged from 0.15 s: 2.0 is the first judged value (a rise), then 6.0 and 7.0
    np.testing.assert_allclose(rise_times(t, d[:, None], 0.15), [0.2, 0.3, 0.6])
    np.testing.assert_allclose(rise_times(t, d[:, None], 0.0), [0.0, 0.3, 0.6])


def test_a_decaying_energy_settles_one_hold_after_it_crosses_the_threshold():
    # E = E0 exp(-t / tau) crosses the threshold at t_c = tau ln(E0 / threshold) (analytic)
    e0, tau, threshold, hold = 168.5, 15.0, 10.0, 7.0
    t = np.arange(0.0, 80.0, SNAPSHOT_S)
    t_c = tau * np.log(e0 / threshold)
    t_s = settle_time(t, e0 * np.exp(-t / tau), rise_times(t, np.full((t.size, 1), 3.0)), threshold, hold)
    # the first snapshot more than one hold after the last one at or above the threshold
    assert t_c + hold <= t_s <= t_c + hold + 2 * SNAPSHOT_S


def test_a_decaying_swing_settles_one_hold_after_its_last_lobe_above_the_threshold():
    # E = E0 exp(-t / tau) cos^2(pi t / P): lobes every P; the last time E >= threshold is a root on the last lobe
    e0, tau, period, threshold, hold = 120.0, 6.0, 6.2, 10.0, 7.0
    t = np.arange(0.0, 60.0, SNAPSHOT_S)

    def energy(time):
        return e0 * np.exp(-time / tau) * np.cos(np.pi * time / period) ** 2

    last_lobe = int(np.floor(tau * np.log(e0 / threshold) / period))      # lobe peaks near k P, envelope above
    peak = brentq(lambda s: -np.pi / period * np.tan(np.pi * s / period) - 1 / (2 * tau),
                  last_lobe * period - period / 2 + 1e-9, last_lobe * period)   # dE/dt = 0 on that lobe
    assert energy(peak) > threshold
    t_last = brentq(lambda s: energy(s) - threshold, peak, last_lobe * period + period / 2)
    t_s = settle_time(t, energy(t), np.zeros(1), threshold, hold)
    assert t_last + hold <= t_s <= t_last + hold + 2 * SNAPSHOT_S


def test_a_demand_still_rising_keeps_the_capture_open():
    # the energy is below the threshold from 2 s, but a running peak rises until 30 s (a late pass): t_s = 30 s + hold
    t = np.arange(0.0, 60.0, SNAPSHOT_S)
    energy = np.where(t < 2.0, 100.0, 1.0)
    demand = np.minimum(t, 30.0)
    t_s = settle_time(t, energy, rise_times(t, demand[:, None]), 10.0, 7.0)
    assert 37.0 <= t_s <= 37.0 + 2 * SNAPSHOT_S
    # and never before the judged window's start plus the hold
    assert settle_time(t, np.ones_like(t), np.zeros(0), 10.0, 7.0, judged_from_s=5.0) == pytest.approx(12.0, abs=1e-9)


def test_a_capture_that_never_settles_has_no_settle_time_and_a_reason():
    t = np.arange(0.0, 16.25, SNAPSHOT_S)
    energy = 168.5 * np.exp(-t / 15.0)        # 57 J at the end: above a 10 J threshold
    assert settle_time(t, energy, np.zeros(0), 10.0, 7.0) is None
    # a NaN energy is never "below"
    assert settle_time(t, np.full_like(t, np.nan), np.zeros(0), 10.0, 7.0) is None
    window = {"settled": False, "end_time_s": 16.25, "net_energy_relative_end_J": 57.2, "energy_threshold_J": 10.0,
              "hold_s": 7.0, "last_rise_s": 13.931, "last_rise_demand": "solar_array_hinge_panel moment"}
    gap = capture_gap(window)
    assert gap.rule == "capture_not_over"
    assert gap.reason.startswith("capture not over at end_time = 16.250 s (relative energy 57.2 J")
    assert "demand rising at 13.931 s (solar_array_hinge_panel moment)" in gap.reason
    assert capture_gap(window | {"settled": True}) is None


def _swinging_history(rng, duration=60.0):
    """Snapshot times (s), a decaying relative energy with lobes and noise (J) and rising running peaks (s): a
    capture that settles at a time the seed decides, or not at all."""
    t = np.arange(0.0, duration, SNAPSHOT_S)
    e0, tau, period = rng.uniform(20.0, 400.0), rng.uniform(3.0, 20.0), rng.uniform(2.0, 9.0)
    energy = e0 * np.exp(-t / tau) * np.cos(np.pi * t / period) ** 2 * rng.uniform(0.5, 1.5, t.size)
    demand = np.maximum.accumulate(rng.gamma(0.3, 1.0, t.size) * np.exp(-t / rng.uniform(5.0, 40.0)))
    return t, energy, rise_times(t, demand[:, None], rng.uniform(0.0, 2.0))


@pytest.mark.parametrize("seed", range(20))
def test_the_settle_rule_checked_in_pieces_answers_as_on_the_whole_history(seed):
    # the running monitor applies settle_time's rule to the instants since its last check only (first_settled,
    # carrying the latest time at or above the threshold): the answer must be the whole history's, to the bit, with
    # the rises known at each check (those up to its time: a later rise cannot change an earlier instant's answer)
    rng = np.random.default_rng(seed)
    t, energy, rises = _swinging_history(rng)
    threshold, hold, judged_from = rng.uniform(0.5, 10.0), rng.uniform(0.5, 8.0), rng.uniform(0.0, 2.0)
    whole = settle_time(t, energy, rises, threshold, hold, judged_from)
    cuts = np.sort(rng.choice(np.arange(1, t.size), size=rng.integers(1, 40), replace=False))
    start, last_above, found = max(judged_from, t[0]), -np.inf, None
    for first, last in zip(np.r_[0, cuts], np.r_[cuts, t.size]):
        known = rises[rises <= t[last - 1]]
        found, last_above = first_settled(t[first:last], energy[first:last], known, threshold, hold, start,
                                          last_above)
        if found is not None:
            break
    assert found == whole


def _capture_case(tmp_path, end_time, extra=""):
    text = (CASES / "envisat_small.toml").read_text().replace("end_time = 7.5", f"end_time = {end_time}")
    text = text.replace('release = "low"', 'release = "never"\nwindow = "capture"' + extra)
    # an array 100x stronger, so that the short run holds everywhere on its loads
    text = text.replace("allowable_moment = [200.0, 1000.0]", "allowable_moment = [20000.0, 100000.0]")
    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_a_run_capped_before_the_capture_is_over_is_indeterminate_never_no_debris(tmp_path):
    # envisat_small at 20 m/s for 0.6 s: the net is still moving past the body (relative energy ~ kJ)
    verdict = run_case(_capture_case(tmp_path, 0.6), tmp_path / "run").structures
    window = verdict["capture_window"]
    assert window["settled"] is False and window["settled_at_s"] is None and window["stopped_early"] is False
    assert window["end_time_s"] == pytest.approx(0.6)
    assert window["net_energy_relative_end_J"] > window["energy_threshold_J"]
    assert verdict["debris_state"] != "no_debris" and verdict["secondary_debris"] is not True
    for row in verdict["locations"]:
        assert row["state"] in ("fails", "indeterminate")
        if row["state"] == "indeterminate":
            assert "capture_not_over" in row["indeterminate_rules"]
            assert "capture not over at end_time = 0.600 s" in row["indeterminate_reason"]


def test_a_settled_capture_stops_the_run_and_its_series_is_the_uncapped_runs_prefix(tmp_path):
    # a threshold no net reaches (1e9 J) and a 0.05 s hold: the capture is "over" at the first 0.05 s without a
    # new running peak after skip_initial; the run must stop there, bit-identical to the run to the cap up to it
    extra = "\ncapture_energy_J = 1e9\ncapture_hold_s = 0.05"
    stopped = run_case(_capture_case(tmp_path / "a", 0.6, extra), tmp_path / "a" / "run")
    window = stopped.structures["capture_window"]
    assert window["settled"] and window["stopped_early"]
    fixed = _capture_case(tmp_path / "b", 0.6).read_text().replace('window = "capture"', 'window = "fixed"')
    (tmp_path / "b" / "case.toml").write_text(fixed)
    full = run_case(tmp_path / "b" / "case.toml", tmp_path / "b" / "run")
    series_stopped = np.load(stopped.run_dir / "timeseries.npz")
    series_full = np.load(full.run_dir / "timeseries.npz")
    k = series_stopped["time"].size
    assert series_stopped["time"][-1] < 0.6 - 1e-9
    # stopped at the first settle check (every 0.1 s of snapshots) at or after t_s
    assert window["settled_at_s"] <= series_stopped["time"][-1] <= window["settled_at_s"] + 0.1 + 1e-9
    for key in ("time", "joint_moment_joint", "body_com_lvlh", "energy_total"):
        np.testing.assert_array_equal(series_stopped[key], series_full[key][:k])


def test_the_threshold_is_a_share_of_the_launch_energy_and_the_hold_a_travel_unless_the_case_gives_them():
    # defaults scale with the launch: the capture keeps its shape in units of net travel and its strikes' demand
    # grows with the launch speed (docs/structures.md); an explicit value wins
    assert energy_threshold(74.91, CAPTURE_ENERGY_FRACTION) == pytest.approx(74.91 * 0.005, rel=1e-15)
    assert energy_threshold(74.91, CAPTURE_ENERGY_FRACTION, threshold_J=3.0) == 3.0
    assert hold_time(None, 4.5) == pytest.approx(7.0, rel=1e-15)           # 31.5 m at 4.5 m/s: window19's 7 s
    assert hold_time(None, 2.0) == pytest.approx(CAPTURE_HOLD_TRAVEL_M / 2.0, rel=1e-15)
    assert hold_time(12.0, 2.0) == 12.0


def test_coupled_cases_judge_the_capture_and_sequential_ones_their_fixed_window_by_default():
    # a hold seen over part of a coupled capture is not a hold: the default window is "capture" for coupled runs
    coupled = load_case(CASES / "envisat_small.toml").structures
    assert coupled.window == "capture" and coupled.capture_energy_J is None and coupled.capture_hold_s is None
    assert coupled.capture_energy_fraction == CAPTURE_ENERGY_FRACTION
    assert load_case(CASES / "envisat_paper_sequential.toml").structures.window == "fixed"


def test_a_capture_window_of_a_sequential_run_is_refused(tmp_path):
    path = _capture_case(tmp_path, 0.6)
    path.write_text(path.read_text().replace('integrator = "VelocityVerlet"',
                                             'integrator = "VelocityVerlet"\ncoupling = "sequential"'))
    with pytest.raises(CaseError, match="window = 'capture' follows the net's motion"):
        load_case(path)


def test_a_twin_of_a_run_stopped_by_the_capture_covers_the_same_window(tmp_path):
    # the capture "over" early (threshold 1e9 J, hold 0.05 s): the twin runs to the run's own end, not to the cap,
    # so every judged peak gets its label (a twin to the cap had a longer series than the run)
    extra = "\ncapture_energy_J = 1e9\ncapture_hold_s = 0.05\ntwin = true"
    verdict = run_case(_capture_case(tmp_path, 0.6, extra), tmp_path / "run").structures
    assert verdict["capture_window"]["stopped_early"]
    assert verdict["twin"]["ran"] is True, verdict["twin"]
    for row in verdict["locations"]:
        assert all(c["twin"] is not None for c in row["criteria"].values() if c["peak"] is not None)
