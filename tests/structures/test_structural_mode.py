"""A weak location read through its structure's first mode (``structural_mode_hz``): the case checks,
the mode grid of a range, and the release monitor filtering the same loads the verdict judges."""
from pathlib import Path

import numpy as np
import pytest

from riskassess.cases.impact import CaseError, load_case
from riskassess.models.impact import model_inputs, weak_locations
from structures.criteria import Allowable
from structures.modal_load import MODE_GRID_RATIO, mode_grid, modal_load
from structures.release import ReleaseMonitor
from structures.weak_location import WeakLocation, assess

CASES = Path(__file__).resolve().parents[2] / "cases"
SMALL = (CASES / "envisat_small.toml").read_text()
ARRAY_LOCATION = 'allowable_moment = [200.0, 1000.0]    # N m, hinge-panel interface [paper Sec. 3.3.3, ref. 18]'


def _write(tmp_path, text):
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_a_range_of_first_modes_becomes_a_grid_and_reaches_the_location(tmp_path):
    text = SMALL.replace(ARRAY_LOCATION, ARRAY_LOCATION + "\nstructural_mode_hz = [0.5, 2.0]\nstructural_damping_ratio = 0.01")
    case = load_case(_write(tmp_path, text))
    location = weak_locations(case, model_inputs(case, CASES).assembly)[0]
    modes = np.asarray(location.structural_modes_hz)
    assert modes[0] == 0.5 and modes[-1] == pytest.approx(2.0, rel=1e-12)
    assert np.all(modes[1:] / modes[:-1] <= MODE_GRID_RATIO * (1 + 1e-12))
    assert location.structural_damping_ratio == 0.01
    assert mode_grid(3.0, 3.0).tolist() == [3.0]


@pytest.mark.parametrize("new, expected", [
    ("structural_mode_hz = [2.0, 0.5]", "structural_mode_hz is [low, high] with low <= high"),
    ("structural_mode_hz = 60.0", "needs simulation.output_rate >= 1200 Hz"),
    ("structural_mode_hz = 1.0\nstructural_damping_ratio = 1.0", "structural_damping_ratio: Input should be less than 1"),
])
def test_bad_structural_modes_are_refused(tmp_path, new, expected):
    with pytest.raises(CaseError) as info:
        load_case(_write(tmp_path, SMALL.replace(ARRAY_LOCATION, ARRAY_LOCATION + "\n" + new)))
    assert expected in str(info.value)


def test_a_mode_given_twice_is_refused(tmp_path):
    text = SMALL.replace(ARRAY_LOCATION, ARRAY_LOCATION + "\nstructural_mode_hz = 1.0")
    text = text.replace('torsional_damping = 1.4e3     # N m s/rad [assumed]: 2 % of critical',
                        'torsional_damping = 1.4e3\nfirst_mode_hz = 20.0')
    with pytest.raises(CaseError) as info:
        load_case(_write(tmp_path, text))
    assert "already has first_mode_hz = 20 Hz in the dynamics; give the structure's mode in one place" in str(info.value)


def test_release_monitor_judges_the_modal_load_as_the_verdict_does():
    # a 1 kN m moment applied suddenly at 0.2 s on a 5 Hz, 2 % mode: the mode carries up to
    # 1 + exp(-0.02 pi / sqrt(1 - 0.02^2)) = 1.94 kN m (step response), first at half a period, 0.3 s.
    # With a 1.5 kN m allowable the recorded load never fails, the modal load does.
    dt = 1e-3
    t = np.arange(0.0, 1.0, dt)
    moment = np.zeros((t.size, 3))
    moment[t >= 0.2, 0] = 1000.0
    location = WeakLocation(name="root", joint=0, section_to_joint=np.eye(3), offset_joint=np.zeros(3),
                            allowable_moment=Allowable.of(1500.0), structural_modes_hz=(5.0,),
                            structural_damping_ratio=0.02)
    verdict = assess(location, t, np.zeros_like(moment), moment, skip_until=0.1)
    peak = verdict["criteria"]["moment"]
    assert peak["peak"] == pytest.approx(1000.0 * (1 + np.exp(-0.02 * np.pi / np.sqrt(1 - 0.02 ** 2))), rel=2e-3)
    assert peak["peak_time_s"] == pytest.approx(0.3, abs=2 * dt)
    expected = np.abs(modal_load(t, moment, 5.0, 0.02)[:, 0])
    first = t[np.argmax(expected >= 1500.0)]
    assert verdict["first_exceedance_s"] == pytest.approx(first, abs=1e-12)

    monitor = ReleaseMonitor([location], system=None, skip_until=0.1, policy="low", interval_s=dt)
    # no Exudyn system here: the release itself only records the event
    monitor.release = lambda loc, time, criterion, demand, stored_energy=0.0: monitor.events.append((time, demand))
    for k, time in enumerate(t):
        monitor.check(time, np.zeros((1, 3)), moment[k][None, :], np.zeros(1))
        if monitor.events:
            break
    # released at the sample the verdict finds first, on the same modal demand
    assert monitor.events[0][0] == pytest.approx(first, abs=1e-12)
    assert monitor.events[0][1] == pytest.approx(expected[np.argmax(expected >= 1500.0)], rel=1e-9)
    # without the mode the recorded 1 kN m holds
    plain = WeakLocation(name="root", joint=0, section_to_joint=np.eye(3), offset_joint=np.zeros(3),
                         allowable_moment=Allowable.of(1500.0))
    assert not assess(plain, t, np.zeros_like(moment), moment, skip_until=0.1)["fails"]
