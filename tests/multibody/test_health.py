"""Numerical health checks (multibody/health.py) and their use in the impact run."""
import math

import numpy as np
import pytest

from multibody.health import (ENERGY_DRIFT_HARD_LIMIT, ENERGY_DRIFT_LIMIT, ENERGY_PERSISTENCE_S, HealthWatch,
                              SimulationFailed, check_finite, energy_drift, stable_step_estimate)
from multibody.impact import ImpactSimulation, net_stable_step
from multibody.recorder import ENERGY_TERMS


def test_stable_step_is_half_the_central_difference_limit():
    # central difference: h < 2/omega, omega = sqrt(k/m); k = 4e4 N/m on 1 kg -> omega = 200 rad/s,
    # limit 0.01 s, with the 0.5 margin 5e-3 s
    assert stable_step_estimate(4e4, 1.0) == pytest.approx(5e-3, rel=1e-12)
    assert stable_step_estimate(0.0, 1.0) == math.inf


def test_check_finite_names_the_first_bad_entry():
    check_finite(0.1, np.ones(5), "state", "cause")
    with pytest.raises(SimulationFailed, match=r"t = 0.1 s: state is not finite \(entry 3\); why") as info:
        check_finite(0.1, [0.0, 1.0, 2.0, np.nan, np.inf], "state", "why")
    assert info.value.time == 0.1 and info.value.exit_code == 5


def test_failure_survives_pickling():
    """Sweep workers send it back to the scheduler process."""
    import pickle
    failure = pickle.loads(pickle.dumps(SimulationFailed(0.25, "state is not finite", "step too large")))
    assert (failure.time, failure.quantity, failure.cause) == (0.25, "state is not finite", "step too large")
    assert str(failure) == "simulation failed at t = 0.25 s: state is not finite; step too large"


def test_energy_drift_is_relative_to_the_reference():
    assert energy_drift(103.0, 100.0, 60.0) == pytest.approx(0.05)
    assert energy_drift(np.nan, 100.0, 60.0) == math.inf


def test_watch_tolerates_a_brief_excursion_and_fails_a_lasting_one():
    reference = 100.0
    watch = HealthWatch("cause", reference)
    assert watch.energy(0.0, 100.0)
    over = 100.0 + 2 * ENERGY_DRIFT_LIMIT * reference      # twice the limit, below the hard limit
    assert watch.energy(1e-4, over)                          # a single sample over the limit: tolerated
    assert watch.energy(2e-4, 100.0)                         # back: the excursion is forgotten
    t = 1e-3
    while watch.energy(t, over):
        t += 1e-4
        assert t < 1.0
    # fails once the drift has stayed above the limit for ENERGY_PERSISTENCE_S
    assert t - 1e-3 == pytest.approx(ENERGY_PERSISTENCE_S, abs=1.5e-4)
    assert "energy balance drifted by 10 %" in str(watch.failure)
    assert watch.summary()["failure"]["time_s"] == pytest.approx(t)


def test_watch_fails_at_once_past_the_hard_limit_and_at_the_end():
    watch = HealthWatch("cause", 10.0)
    watch.energy(0.0, 10.0)
    assert not watch.energy(1e-4, 10.0 + 10.0 * (ENERGY_DRIFT_HARD_LIMIT + 0.01))
    ending = HealthWatch("cause", 10.0)
    ending.energy(0.0, 10.0)
    assert ending.energy(1e-4, 11.0)  # 10 %: tolerated for now ...
    assert not ending.finish()        # ... but the run ends with it
    assert not HealthWatch("c").state(0.0, np.array([1.0, np.nan]))


def test_net_stable_step_of_the_reference_thread():
    # envisat_small: 0.04223 kg nodes, 62308 N/m threads -> sqrt(m/k) = 8.23e-4 s
    class Net:
        masses = np.array([0.04223, 1.786])
        stiffness = np.array([62308.25])
    assert net_stable_step(Net) == pytest.approx(np.sqrt(0.04223 / 62308.25), rel=1e-12)


def test_a_nan_initial_rate_stops_before_the_first_step(small_net_on_box):
    """A NaN body rate (issue 20, item 2): the run raises at t = 0 instead of simulating NaNs."""
    assembly = small_net_on_box(end_time=0.01)
    assembly.bodies[0].omega_body[:] = [np.nan, 0.0, 0.0]
    with pytest.raises(SimulationFailed, match="t = 0 s: state is not finite"):
        ImpactSimulation(assembly).run()


def test_a_step_too_large_for_the_threads_fails_with_the_stable_step(small_net_on_box):
    """7 x 7 net over 6 m: 1 m threads of EA = 54.98 kN, so k = 54.98 kN/m on 0.05 kg nodes and
    sqrt(m/k) = 9.54e-4 s; at 5e-3 s the explicit integration is unstable and the check names
    half the limit, 4.8e-4 s, as the step to use."""
    assembly = small_net_on_box(end_time=0.6, step=5e-3)
    simulation = ImpactSimulation(assembly)
    with pytest.raises(SimulationFailed, match=r"sqrt\(m/k\) = 0.000954 s.*use simulation.step <= 0.00048 s") as info:
        simulation.run()
    assert info.value.time < 0.6
    assert not simulation.health.ok and simulation.recorder.series["time"][-1] < info.value.time


def test_a_healthy_run_reports_its_drift(small_net_on_box):
    simulation = ImpactSimulation(small_net_on_box(end_time=0.1))
    recorder = simulation.run()
    health = simulation.health.summary()
    assert health["healthy"] and health["failure"] is None
    # the drift the watch saw is the recorder's own energy balance, against the initial kinetic energy
    e = recorder.series["energy_total"]
    assert health["energy_max_drift"] == pytest.approx(np.abs(e - e[0]).max() / health["energy_reference_J"],
                                                       rel=1e-9)
    assert health["energy_max_drift"] < 0.01
    # the total is the recorded terms added in ENERGY_TERMS order from 0.0, as Python's sum of them: to the bit
    total = np.zeros_like(e)
    for key in ENERGY_TERMS:
        total = total + recorder.series["energy_" + key]
    assert np.array_equal(total, e)
    # the last step is always sampled
    assert recorder.series["time"][-1] == pytest.approx(0.1, abs=1e-9)


@pytest.mark.slow  # envisat_small for 7.5 s with the threads' contact on: 24-29 s of CPU
def test_envisat_small_with_the_threads_contact_closes_its_balance_once_the_joints_dampers_are_booked(tmp_path):
    """Helper thread14 found envisat_small's key-on balance losing 1.94 % of the reference energy, the solar-array
    hinge's torsional damper's work (about 2.2 %, estimated from the samples: docs/model.md, "Where envisat_small's
    steady loss goes"). Booked every step (``energy_dissipated_joints``), the dampers take more than 1.5 % and the
    balance stays within the 1 % the rule thread_contact_energy asks (structures.verdict.THREAD_CONTACT_DRIFT_LIMIT;
    measured 0.42 % largest, +0.30 % at the end, on this machine at 2026-11-27; chaotic: another CPU's round-off
    gives another trajectory, hence the margin)."""
    from pathlib import Path

    from riskassess.cases.impact import load_case
    from riskassess.models.impact import model_inputs
    from structures.verdict import THREAD_CONTACT_DRIFT_LIMIT

    case = Path(__file__).resolve().parents[2] / "cases" / "envisat_small.toml"
    text = case.read_text().replace("[contact]\n", "[contact]\nthread_segments = true\n", 1)
    (tmp_path / case.name).write_text(text)
    simulation = ImpactSimulation(model_inputs(load_case(tmp_path / case.name), case.parent).assembly)
    series = simulation.run().series
    health = simulation.health.summary()
    assert health["healthy"]
    assert series["energy_dissipated_joints"][-1] > 0.015 * health["energy_reference_J"]
    assert health["energy_max_drift"] < THREAD_CONTACT_DRIFT_LIMIT
