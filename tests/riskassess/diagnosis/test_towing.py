"""The towing scenario of the diagnosis: the fast model against the towing twin and Exudyn, the two
towing effects' laws against their physics, and hidden effects in towing data.

The hidden-effect data come from the fast model at the towing case's 4 ms step (the Exudyn model
gives the same channels to round-off at equal steps: test below); the fit runs at the diagnosis
case's 20 ms, so data and fit differ by the step as with an independent simulation (20 ms vs 4 ms:
<= 0.2 sigma of the default noise, docs/diagnosis.md).
"""
from __future__ import annotations

import os
import shutil

import numpy as np
import pytest
from numba import njit
from scipy.spatial.transform import Rotation

from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.effects.base import Effect
from riskassess.diagnosis.effects.tether_viscoelasticity import branch_after, step_gain
from riskassess.diagnosis.effects.thrust_misalignment import misaligned_thrust, thrust_direction_eci
from riskassess.products.measured import write_measured
from riskassess.diagnosis.model import predict
from riskassess.diagnosis.plants.scenario import plant_of
from riskassess.diagnosis.synthetic import channel_noise, sample_times
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE, last_diagnostics
from riskassess.diagnosis.towing_exudyn import simulate_towing_exudyn
from multibody.orbit import lvlh_to_eci
from riskassess.diagnosis.plants.towing_plant import simulate
from multibody.towing import run_twin
from multibody.towing_kernel import CHASER, THRUST
from riskassess.cases.impact import read_toml
from riskassess.stages.diagnose import diagnose_case
from riskassess.cases.diagnosis import toml_text
from tests.riskassess.diagnosis.conftest import TOWING_CASE, case_with
from tests.riskassess.diagnosis.test_diagnose import _check_named, draw_effect

SEED = int(os.environ.get("DIAGNOSIS_SEED", "0"))
#: Data step (s): the towing case's Exudyn step.
DATA_STEP = 4e-3
#: Fast-test record (s at 10 Hz): engagement of the tether (~2-12 s after thrust-on) and the ramp after it.
DURATION = 24.0


def test_fast_model_without_effect_is_the_towing_twin(zenit_tow):
    """No effect: the fast model (multibody.towing_kernel.verlet_run with the effect hook) runs as the twin (multibody.towing.run_twin)
    with zero further forces: the same numbers up to round-off (1e-9 of each channel's range)."""
    plant = plant_of(zenit_tow)
    times = np.arange(0.0, 8.0 + 1e-9, 0.1)
    fast = simulate(plant, times, step=DATA_STEP)
    model = plant.model(8.0 + 2 * DATA_STEP, DATA_STEP)
    model.output_interval = 0.1
    series = run_twin(model).series()
    k = len(times)
    omega = series["debris_omega_body"][:k]
    rel_eci = series["debris_com_inertial"][:k] - series["chaser_com_inertial"][:k]
    to_lvlh = np.transpose(lvlh_to_eci(series["chaser_com_inertial"][:k], series["chaser_velocity_inertial"][:k]),
                           (0, 2, 1))
    rel = np.einsum("kij,kj->ki", to_lvlh, rel_eci)
    quat = Rotation.from_matrix(to_lvlh @ series["debris_to_inertial"][:k]).as_quat()[:, [3, 0, 1, 2]]
    quat *= np.sign(np.sum(quat * np.column_stack([fast[f"q_{a}"] for a in "wxyz"]), axis=1))[:, None]
    for i, a in enumerate("xyz"):
        assert np.abs(fast[f"omega_{a}"] - omega[:, i]).max() < 1e-9 * max(np.ptp(omega[:, i]), 1e-3)
        assert np.abs(fast[f"rel_{a}"] - rel[:, i]).max() < 1e-9 * max(np.ptp(rel[:, i]), 1.0)
    for i, a in enumerate("wxyz"):
        assert np.abs(fast[f"q_{a}"] - quat[:, i]).max() < 1e-9
    tension = series["main_tether_tension"][:k]      # round-off of c e' in ECI velocities: see the next test
    assert np.abs(fast["tether_tension"] - tension).max() < 1e-6 * max(tension.max(), 1.0)


def test_exudyn_and_fast_model_agree_with_a_towing_effect(zenit_tow):
    """Same plant, effect and step: Exudyn's VelocityVerlet on the coupled object and the compiled
    loop apply the same scheme, so they agree to round-off: 1e-8 of each channel's size over 10 s
    (measured <= 1e-9 m on rel_*, differences of 7e6 m Earth-centred positions), 1e-6 for the
    tension (its damper term c e' takes the difference of 7.5 km/s velocities: 1e-11 relative
    round-off there is 2e-6 N at c = 300 N s/m; measured 1.1e-5 N of 38 N). The viscoelastic
    branch is the effect that acts inside the connection point's implicit step (thrust, torque and
    force laws go through the same further-forces path)."""
    plant = plant_of(zenit_tow)
    effect, values = CATALOG["tether_viscoelasticity"], [6000.0, 30.0]
    names = [p.name for p in effect.parameter_specs(zenit_tow)]
    times = np.arange(0.0, 10.0 + 1e-9, 0.1)
    exudyn = simulate_towing_exudyn(plant, times, effect, values, names, step=DATA_STEP)
    fast = predict(plant, times, effect, values, names, step=DATA_STEP)
    nominal = predict(plant, times, step=DATA_STEP)
    for c in fast:
        size = max(np.ptp(fast[c]), np.abs(fast[c]).max(), 1e-3)
        assert np.abs(exudyn[c] - fast[c]).max() < (1e-6 if c == "tether_tension" else 1e-8) * size, c
    assert max(np.abs(fast[c] - nominal[c]).max() / channel_noise(c) for c in fast) > 1.0


def test_maxwell_branch_relaxes_and_creeps_as_the_standard_linear_solid():
    """Standard linear solid (Lakes 2009, Sec. 2.6): at constant elongation the branch's tension decays
    as exp(-t/tau) (exact per step: 1e-12); at a constant elongation rate it tends to k_m tau e'
    (the viscous limit) and its stiffness over a step h is k_m tau (1 - exp(-h/tau)) / h -> k_m for
    h << tau (the elastic limit)."""
    k_m, tau, h = 2000.0, 5.0, 0.02
    t_m = 100.0
    for _ in range(500):                                   # 10 s at constant elongation 0.1 m
        t_m = branch_after(t_m, 0.1, 0.1, k_m, tau, h)
    assert t_m == pytest.approx(100.0 * np.exp(-10.0 / tau), rel=1e-12)
    e, t_m, rate = 0.0, 0.0, 1e-3
    for _ in range(5000):                                  # 100 s at 1 mm/s: 20 relaxation times
        t_m = branch_after(t_m, e, e + rate * h, k_m, tau, h)
        e += rate * h
    assert t_m == pytest.approx(k_m * tau * rate * (1 - np.exp(-100.0 / tau)), rel=1e-9)
    assert step_gain(tau, 1e-6) == pytest.approx(1.0, abs=1e-6)
    assert branch_after(0.0, 0.0, -0.05, k_m, tau, h) == 0.0      # a strand: compression gives no tension


def test_tilted_thrust_keeps_its_magnitude_and_turns_by_the_tilts():
    """R_y(beta) R_x(alpha) e_z = (cos a sin b, -sin a, cos a cos b): the thrust keeps its magnitude and
    turns by arccos(cos a cos b); no torque with the thrust line through the CoM."""
    alpha, beta = 0.03, -0.05
    force, torque = misaligned_thrust(200.0, np.array([0.0, 0.0, 1.0]), np.zeros(3), alpha, beta)
    assert force == pytest.approx(200.0 * np.array([np.cos(alpha) * np.sin(beta), -np.sin(alpha),
                                                    np.cos(alpha) * np.cos(beta)]), abs=1e-12)
    assert np.linalg.norm(torque) == 0.0


def _noisy(plant, times, nominal, effect, values, rng):
    """(chi^2 of the effect's clean difference from the ``nominal`` channels at the noise, noisy channels):
    the record of ``effect`` at ``values`` (dict) with noise drawn at 0.1-1 x NOISE (log-uniform)."""
    clean = predict(plant, times, effect, list(values.values()), list(values), step=DATA_STEP)
    scale = 10 ** rng.uniform(-1.0, 0.0)
    chi2 = sum(np.sum((clean[c] - nominal[c]) ** 2) / channel_noise(c, scale) ** 2 for c in clean)
    return chi2, {c: v + rng.normal(0.0, channel_noise(c, scale), v.shape) for c, v in clean.items()}


def _tow_data(case, effect_id, rng, times):
    """(values, noisy channels): the effect drawn as in the free scenarios' tests (draw_effect: around
    its typical size, random signs, random field direction) until its signal stands out (chi^2 of the
    clean difference >= 400 at the drawn noise: far beyond the BIC's penalty for 2 parameters,
    2 ln 3000 = 16, and the decisive 10), noise scale log-uniform 0.1-1 x NOISE."""
    plant = plant_of(case)
    nominal = predict(plant, times, step=DATA_STEP)
    for _ in range(30):
        values = draw_effect(case, effect_id, rng)
        chi2, channels = _noisy(plant, times, nominal, CATALOG[effect_id], values, rng)
        if chi2 >= 400.0:
            return values, channels
    raise AssertionError(f"{effect_id}: no visible draw in 30 tries")


def _diagnose(tmp_path, channels, times, candidates=None, uncertain=None):
    """Diagnose a copy of the sample case, by default with the debris' attitude and rate uncertain (its
    position and velocity known: 6 fitted nominal parameters instead of 12 keep the fast tests' diagnoses
    at a few seconds each on 2 idle cores); ``candidates``: the effects fitted (default: the catalog). No
    plots (test_diagnose.py checks them): they took 40 % of a fast diagnosis."""
    data = tmp_path / "measured.csv"
    write_measured(data, times, channels)
    raw = read_toml(TOWING_CASE)
    shutil.copy(TOWING_CASE.parent / raw["towing"], tmp_path / raw["towing"])  # case files name no absolute path
    raw["uncertain"] = {"attitude": 0.01, "angular_velocity": 2e-3} if uncertain is None else uncertain
    case = tmp_path / TOWING_CASE.name
    case.write_text(toml_text(raw))
    return diagnose_case(case, data, tmp_path / "out", candidates=candidates, figures=False)


#: Candidates of the fast hidden-effect tests (each is about one law): the two towing-only effects and the
#: generic ones nearest to them in these records (a bias absorbs a tension offset, a CoM offset moves the
#: sub-tethers' lever arms); the fast no-effect test fits every effect a tow can show (SLOW_EFFECTS), the
#: slow tests the whole catalog.
FAST_CANDIDATES = ["tether_viscoelasticity", "thrust_misalignment", "sensor_bias", "com_offset"]
#: Effects a 300 s tow of the 9 t Zenit-2 shows above typical noise (gravity gradient, J2 and a nutation
#: damper on its major-axis spin do not: docs/diagnosis.md); the slow test hides one of them.
SLOW_EFFECTS = ["tether_viscoelasticity", "thrust_misalignment", "com_offset", "sensor_bias", "sensor_time_delay",
                "eddy_current_damping"]


@pytest.mark.parametrize("effect_id", ["tether_viscoelasticity", "thrust_misalignment"])
def test_hidden_towing_effect_is_named_with_a_gain(tmp_path, zenit_tow, effect_id):
    rng = np.random.default_rng(SEED + (4000 if effect_id == "thrust_misalignment" else 5000))
    times = sample_times(DURATION, 10.0)
    values, channels = _tow_data(zenit_tow, effect_id, rng, times)
    answer = _diagnose(tmp_path, channels, times, FAST_CANDIDATES)
    assert answer["cause"] == effect_id, (values, answer["statement"])
    assert answer["confidence"] > 0.99
    # the held-out prediction is better: the extended model removes at least half of the nominal
    # model's excess residual power (as tests/diagnosis/test_diagnose.py::_check_named)
    after = next(r for r in answer["candidates"] if r["id"] == effect_id)["holdout_rms_sigma"]
    before = answer["nominal"]["holdout_rms_sigma"]
    assert after ** 2 - 1.0 <= 0.5 * (before ** 2 - 1.0) + 0.05, (before, after)
    assert answer["gain_percent"]["overall"] > 0.0
    assert not (tmp_path / "diagnose_towing.extended.toml").exists()   # nothing beside the input case
    extended = case_with(tmp_path / "out" / "diagnose_towing.extended.toml")
    assert extended.effects[0].id == effect_id


def test_towing_without_effect_gives_no_significant_discrepancy(tmp_path, zenit_tow):
    rng = np.random.default_rng(SEED + 6000)
    times = sample_times(DURATION, 10.0)
    clean = predict(plant_of(zenit_tow), times, step=DATA_STEP)
    scale = 10 ** rng.uniform(-1.0, 0.0)
    channels = {c: v + rng.normal(0.0, channel_noise(c, scale), v.shape) for c, v in clean.items()}
    answer = _diagnose(tmp_path, channels, times, SLOW_EFFECTS)
    assert answer["cause"] == "none", answer["statement"]
    assert answer["extended_case"] is None
    assert {"hinge_coulomb_friction", "hinge_backlash", "hinge_stiffness_hardening"} <= set(answer["not_applicable"])



@njit(TOWING_LAW_SIGNATURE)
def _thrust_ripple_law(t, q, v, p, work, xe, h, load):
    """The thrust law's force modulated, F (1 + a sin(2 pi f t + phase)) (p = a, f, phase), on the chaser."""
    thrust = last_diagnostics(work)[THRUST]
    if thrust != 0.0:
        change = thrust * p[0] * np.sin(2.0 * np.pi * p[1] * t + p[2]) * thrust_direction_eci(q, v, work)
        for i in range(3):
            load[CHASER + i] += change[i]


class _ThrustRipple(Effect):
    """An engine whose thrust oscillates (combustion or valve cycling): in no catalog entry."""
    id = "thrust_ripple"
    scenarios = ("towing",)
    towing_law = staticmethod(_thrust_ripple_law)


def test_towing_effect_outside_the_catalog_is_not_pinned_on_a_catalog_cause(tmp_path, zenit_tow):
    """A thrust ripple of 5-20 % at 0.1-0.3 Hz (out of the catalog: no catalog effect changes the thrust's
    magnitude over time) must not be named as a catalog cause with high confidence, nor called noise."""
    rng = np.random.default_rng(SEED + 9000)
    times = sample_times(DURATION, 10.0)
    plant = plant_of(zenit_tow)
    nominal = predict(plant, times, step=DATA_STEP)
    for _ in range(30):
        values = {"amplitude": rng.uniform(0.05, 0.2), "frequency": rng.uniform(0.1, 0.3),
                  "phase": rng.uniform(0.0, 2 * np.pi)}
        chi2, channels = _noisy(plant, times, nominal, _ThrustRipple(), values, rng)
        if chi2 >= 400.0:        # as _tow_data: far beyond the BIC's penalties
            break
    answer = _diagnose(tmp_path, channels, times, SLOW_EFFECTS)
    assert answer["cause"] == "unexplained" or answer["confidence"] < 0.9, (values, answer["statement"])
    assert answer["cause"] != "none", (values, answer["statement"])


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
def test_hidden_towing_effect_any_seed_full_length(tmp_path, zenit_tow, seed):
    """A 300 s tow with an effect drawn at random (size 0.5-3 x typical, random signs, noise 0.1-1 x the
    default), the sample case as it stands (12 fitted nominal parameters) and the whole catalog: the
    hidden effect is named and its parameters land within 5 of their standard deviations or 20 %
    (tests/diagnosis/test_diagnose.py::_check_named, the free scenarios' slow test)."""
    rng = np.random.default_rng(7000 + seed)
    effect_id = str(rng.choice(SLOW_EFFECTS))
    times = sample_times(300.0, 10.0)
    values, channels = _tow_data(zenit_tow, effect_id, rng, times)
    answer = _diagnose(tmp_path, channels, times, uncertain=read_toml(TOWING_CASE)["uncertain"])
    _check_named(answer, effect_id, values)


@pytest.mark.slow
def test_towing_without_effect_full_length_gives_no_significant_discrepancy(tmp_path, zenit_tow):
    """300 s, the whole catalog, 12 fitted nominal parameters: no effect is named."""
    rng = np.random.default_rng(SEED + 8000)
    times = sample_times(300.0, 10.0)
    clean = predict(plant_of(zenit_tow), times, step=DATA_STEP)
    channels = {c: v + rng.normal(0.0, channel_noise(c), v.shape) for c, v in clean.items()}
    answer = _diagnose(tmp_path, channels, times, uncertain=read_toml(TOWING_CASE)["uncertain"])
    assert answer["cause"] == "none", answer["statement"]
