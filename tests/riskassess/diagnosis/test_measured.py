"""Reading measured data: checks with file/column messages, quaternion signs, noise estimate."""
from __future__ import annotations

import numpy as np
import pytest

from riskassess.diagnosis.measured import MeasuredDataError, difference_noise, read_measured
from riskassess.products.measured import write_measured


def _write(path, text):
    path.write_text(text)
    return path


def test_unknown_channels_are_reported_and_quaternion_signs_made_continuous(tmp_path):
    t = np.arange(100) * 0.1
    angle = 0.3 * t
    q = np.column_stack([np.cos(angle / 2), np.sin(angle / 2), 0 * t, 0 * t])
    q[1::2] *= -1                                   # every other sample with the other sign
    path = tmp_path / "m.csv"
    write_measured(path, t, {"q_w": q[:, 0], "q_x": q[:, 1], "q_y": q[:, 2], "q_z": q[:, 3], "sun_angle": t})
    m = read_measured(path)
    assert m.unknown == ["sun_angle"] and "sun_angle" not in m.values
    assert np.all(m.values["q_w"] > 0)             # cos(angle / 2) > 0 over 0..3 rad: one sign throughout


def test_noise_estimate_of_noise_on_a_tumble_signal():
    """Differences remove a 0.2 rad/s, 0.3 Hz signal at 10 Hz; the estimate of a 1e-3 white noise
    from 3000 samples is within 10 % (its own scatter is ~2 %, 1 / sqrt(2 n))."""
    for seed in range(5):
        rng = np.random.default_rng(seed)
        t = np.arange(3000) * 0.1
        y = 0.2 * np.sin(2 * np.pi * 0.3 * t) + 0.05 * t / 300 + rng.normal(0, 1e-3, t.size)
        assert difference_noise(y) == pytest.approx(1e-3, rel=0.1)


def test_given_noise_overrides_the_estimate(tmp_path):
    path = tmp_path / "m.csv"
    t = np.arange(50) * 0.1
    write_measured(path, t, {"omega_x": np.sin(t)})
    m = read_measured(path, {"omega_x": 0.01})
    assert m.noise["omega_x"] == 0.01 and m.noise_source["omega_x"] == "given"


@pytest.mark.parametrize("text, message", [
    ("t,omega_x\n" + "".join(f"{k},0\n" for k in range(40)), "first column must be 'time'"),
    ("time,omega_x\n" + "".join(f"{40 - k},0\n" for k in range(40)), "strictly increasing"),
    ("time,q_w,q_x\n" + "".join(f"{k},1,0\n" for k in range(40)), "needs all of q_w, q_x, q_y, q_z"),
    ("time,omega_x\n" + "".join(f"{k},abc\n" for k in range(40)), "'abc' is not a number"),
    ("time,foo\n" + "".join(f"{k},1\n" for k in range(40)), "no known channel"),
    ("time,omega_x\n0,1\n", "at least 30 are needed"),
])
def test_bad_files_name_the_file_and_the_problem(tmp_path, text, message):
    path = _write(tmp_path / "bad.csv", text)
    with pytest.raises(MeasuredDataError, match=message) as info:
        read_measured(path)
    assert str(path) in str(info.value)
