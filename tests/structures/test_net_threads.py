"""Net integrity: thread tension by the simulation's law against the thread's breaking load."""
import numpy as np
import pytest

from multibody.net import thread_tension_strain
from structures.net_threads import net_integrity


def test_thread_tension_from_a_hand_computed_stretch():
    """One thread of the reference net (k = E A / l0 = 62308.25 N/m, c = 1.6 N s/m [paper T1]) stretched
    by 1 mm and opening at 2 mm/s: T = k s + c v = 62.30825 + 0.0032 N; a slack one carries nothing."""
    k, c, l0 = 62308.25, 1.6, 0.8824
    x = np.array([[[0.0, 0.0, 0.0], [l0 + 1e-3, 0.0, 0.0], [l0 + 1e-3, l0 - 1e-3, 0.0]]])
    v = np.array([[[0.0, 0.0, 0.0], [2e-3, 0.0, 0.0], [2e-3, 0.0, 0.0]]])
    threads = np.array([[0, 1], [1, 2]])
    tension, _ = thread_tension_strain(x, v, threads, np.full(2, l0), np.full(2, k), np.full(2, c))
    assert tension[0] == pytest.approx([k * 1e-3 + c * 2e-3, 0.0], rel=1e-9, abs=1e-12)
    judged = net_integrity(tension, np.array([0.5]), breaking_load=60.0)
    assert judged.over.tolist() == [0] and judged.margin_of_safety == pytest.approx(60.0 / 62.31145 - 1, rel=1e-6)
    assert not net_integrity(tension, np.array([0.5]), None).assessed


def test_threads_over_the_load_are_listed_highest_first_with_their_peak_time():
    tension = np.array([[0.0, 10.0, 70.0], [80.0, 5.0, 60.0], [20.0, 0.0, 90.0]])   # (3 snapshots, 3 threads), N
    judged = net_integrity(tension, np.array([0.0, 0.1, 0.2]), breaking_load=75.0)
    assert judged.over.tolist() == [2, 0]
    assert judged.peak_tension.tolist() == [80.0, 10.0, 90.0] and judged.peak_time.tolist() == [0.1, 0.0, 0.2]
    with pytest.raises(ValueError, match="tension must be"):
        net_integrity(tension[:, 0], np.zeros(3), None)
