"""Thrust laws as plug-ins (multibody/control/thrust_laws): one file each, found by NAME, an unknown
name refused with the known ones, and a new law's compiled command driving the towing kernel."""
import importlib
import pkgutil
import shutil
from pathlib import Path

import numpy as np
import pytest

import multibody.control.thrust_laws as thrust_laws_package
from multibody.control.thrust_laws import LAWS
from multibody.towing import TowingModel, packed
from multibody.towing_kernel import CHASER, THRUST, no_load, tow_kernel, verlet_run
from riskassess.cases.impact import read_toml
from riskassess.cases.towing import TowingCase

CASE = Path(__file__).parents[3] / "cases" / "zenit2_towing.toml"

#: A law written as a user would add one: a constant thrust params[0] (N) against the velocity.
CONSTANT_LAW = '''
import numpy as np
from numba import njit

from multibody.control.thrust import THRUST_SIGNATURE

NAME = "constant"
ALONG_BODY_Z = False
CASE_SECTIONS = ()


@njit(THRUST_SIGNATURE)
def command(t, z, z_rate, range_rate, params, state, step, advance):
    return params[0]


def arrays(case, tether, z0, z_rate0):
    return np.array([case.thrust.max_force]), np.zeros(1)
'''


def test_every_law_file_is_discovered_by_its_name():
    files = [m.name for m in pkgutil.iter_modules(thrust_laws_package.__path__)]
    names = {importlib.import_module(f"multibody.control.thrust_laws.{f}").NAME: f for f in files}
    assert set(LAWS) == set(names) >= {"ramp", "mrac1", "mrac2"}
    for name, module in LAWS.items():
        assert module.NAME == name and LAWS[name] is module
        assert callable(module.command) and callable(module.arrays) and isinstance(module.ALONG_BODY_Z, bool)


def test_a_new_law_file_is_found_and_drives_the_towing_kernel(tmp_path, monkeypatch):
    """Adding a law is adding one file: a package with the catalog's __init__ and one new file finds
    it by NAME; its compiled command, passed to the twin as a first-class function, pushes a free
    chaser (tethers without stiffness, no gravity) with exactly its constant force: Verlet
    integrates a constant force exactly, so v_x(T) = v_x(0) + F T / m_C to round-off."""
    package = tmp_path / "thrust_laws_plus"
    package.mkdir()
    shutil.copy(Path(thrust_laws_package.__file__), package / "__init__.py")
    (package / "constant.py").write_text(CONSTANT_LAW)
    monkeypatch.syspath_prepend(str(tmp_path))
    plus = importlib.import_module("thrust_laws_plus")
    assert list(plus.LAWS) == ["constant"]
    law = plus.LAWS["constant"]

    force, m_c, speed, duration = 7.0, 4.0, -1000.0, 2.0
    velocities = np.array([[speed, 0.0, 0.0]] * 3)
    model = TowingModel(
        masses=np.array([1.0, m_c, 1.0]), inertia_body=np.array([np.eye(3), np.eye(3)]) * 10.0,
        attach_chaser_body=np.zeros(3), attach_debris_body=np.zeros((0, 3)),
        tether=np.array([0.0, 0.0, 5.0, 0.0, 0.0, 1.0]), mu=0.0, attitude=np.zeros(8), thrust_law="ramp",
        thrust_along_body_z=law.ALONG_BODY_Z, thrust_params=np.array([force]), thrust_state=np.zeros(1),
        positions=np.array([[-4.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 100.0, 0.0]]), velocities=velocities,
        body_to_inertial=np.array([np.eye(3), np.eye(3)]), omega_body=np.zeros((2, 3)),
        start_time=0.0, end_time=duration, step=1e-2, output_interval=1e-2)
    tow = tow_kernel(packed(model).work, law.command)
    q, v = model.initial_state()
    record = np.array([0, model.n_steps], dtype=np.int64)
    out_q, out_v, out_diag = np.zeros((2, 15)), np.zeros((2, 15)), np.zeros((2, 10))
    verlet_run(tow, no_load, np.zeros(1), q, v, 0.0, model.n_steps, np.zeros(1), record, out_q, out_v, out_diag,
               np.zeros((2, 1)))
    assert out_diag[1, THRUST] == force
    assert out_v[1, CHASER] == pytest.approx(speed + force * duration / m_c, abs=1e-9)   # thrust against v: +x
    assert out_v[1, 9] == pytest.approx(speed, abs=1e-12)                                 # the debris is not pushed


def test_an_unknown_thrust_law_is_refused_listing_the_known_ones():
    with pytest.raises(ValueError) as unknown:
        LAWS["bang_bang"]
    assert str(unknown.value) == f"unknown thrust law 'bang_bang'; the known thrust laws are: {', '.join(sorted(LAWS))}"
    raw = read_toml(CASE)
    raw["thrust"]["kind"] = "bang_bang"
    with pytest.raises(ValueError) as refused:
        TowingCase.model_validate(raw)
    assert "thrust.kind" in str(refused.value) and all(f"'{name}'" in str(refused.value) for name in LAWS)


def test_the_elongation_rate_estimate_is_the_backward_euler_dirty_derivative():
    """multibody.control.mrac.elongation_rate_estimate: r_k = (tau r_{k-1} + z_k - z_{k-1}) / (tau + h) is
    s / (tau s + 1) discretized with s = (1 - q^-1) / h: exact for a ramp from the first sample, and on a
    sampled sine of frequency w its steady amplitude is |H| of that transfer function (both to round-off);
    tau = 0 hands the measured rate through."""
    from multibody.control.mrac import N_COMMON, RATE_TAU, Z_LAST, RATE_LAST, elongation_rate_estimate, store_rate

    tau, h = 0.06, 2e-3
    params, state = np.zeros(N_COMMON), np.zeros(4)
    params[RATE_TAU] = tau
    state[Z_LAST], state[RATE_LAST] = 0.01, 0.3                    # a ramp z = 0.01 + 0.3 t, started on it
    for k in range(1, 50):
        z = 0.01 + 0.3 * k * h
        rate = elongation_rate_estimate(params, state, z, 99.0, h)   # the measured rate is not used
        store_rate(state, z, rate)
        assert rate == pytest.approx(0.3, rel=1e-12)
    w = 20.0                                                       # rad/s, above the corner 1/tau = 16.7 rad/s
    state[:] = 0.0
    rates = []
    for k in range(1, 20001):
        z = np.sin(w * k * h)
        rate = elongation_rate_estimate(params, state, z, 0.0, h)
        store_rate(state, z, rate)
        rates.append(rate)
    s = (1.0 - np.exp(-1j * w * h)) / h
    expected = abs(s / (tau * s + 1.0))
    assert np.max(np.abs(rates[-2000:])) == pytest.approx(expected, rel=2e-3)   # sampled peak: (w h)^2/8 below
    params[RATE_TAU] = 0.0
    assert elongation_rate_estimate(params, state, 1.0, 0.123, h) == 0.123
