"""Measured data made by simulation: the Exudyn model of a case with one effect switched on (or an
out-of-catalog disturbance), sampled and with white Gaussian noise added. Used by the tests'
fixtures, the sample data in cases/data/ and the benchmark."""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.exudyn_model import ExudynScenario, simulate_exudyn
from riskassess.diagnosis.plants.plant import Plant, is_towing
from riskassess.diagnosis.plants.scenario import plant_of
from riskassess.diagnosis.towing_exudyn import simulate_towing_exudyn

#: Default 1-sigma noise per channel group (channel units): a MEMS gyro at 10 Hz (2e-4 rad/s), a
#: star tracker (~1e-3 per quaternion component, ~7 arcmin), an encoder (1e-3 rad), its rate
#: (1e-3 rad/s), relative navigation (1 cm; its velocity 1 mm/s), a tether load cell (0.5 N: 0.25 % of a 200 N range).
NOISE = {"omega": 2e-4, "q": 1e-3, "hinge_angle": 1e-3, "hinge_rate": 1e-3, "rel": 0.01, "tether": 0.5, "vel": 1e-3}


def channel_noise(channel: str, scale: float = 1.0) -> float:
    """Default 1-sigma noise of a channel (channel units), times ``scale``.

    Parameters
    ----------
    channel : str
        Channel name (:mod:`riskassess.diagnosis.plants.channels`).
    scale : float
        Factor on the defaults of ``NOISE`` (-).

    Returns
    -------
    sigma : float
        (rad/s, -, rad, m or N: the channel's unit).
    """
    key = channel if channel in NOISE else channel.split("_")[0]
    return scale * NOISE[key]


def sample_times(duration: float, rate: float) -> np.ndarray:
    """Uniform sample times from 0 to ``duration``.

    Parameters
    ----------
    duration : float
        Record length (s).
    rate : float
        Sampling rate (Hz).

    Returns
    -------
    times : (round(duration rate) + 1,) float
        (s).
    """
    return np.arange(int(round(duration * rate)) + 1) / rate


def noisy(clean: dict, rng, noise_scale: float = 1.0) -> tuple[dict, dict]:
    """``clean`` channels plus white Gaussian noise; returns (noisy channels, sigma per channel).

    Parameters
    ----------
    clean : dict of str to (k,) float
        Simulated channels (channel units).
    rng : numpy.random.Generator
        Random generator.
    noise_scale : float
        Factor on the default noise (-).

    Returns
    -------
    noisy : dict of str to (k,) float
        Channels with noise (channel units).
    sigma : dict of str to float
        1-sigma noise per channel (channel units).
    """
    sigma = {c: channel_noise(c, noise_scale) for c in clean}
    return {c: v + rng.normal(0.0, sigma[c], v.shape) for c, v in clean.items()}, sigma


def simulate_effect(case, times, effect_id: str | None = None, values=None) -> dict:
    """Clean channels of the case's Exudyn model with ``effect_id`` at ``values`` (dict name -> SI); the
    towing scenario's is :func:`riskassess.diagnosis.towing_exudyn.simulate_towing_exudyn`.

    Parameters
    ----------
    case : DiagnosisCase
        Validated diagnosis case.
    times : (k,) float
        Sample times (s) from the record's t = 0.
    effect_id : str, optional
        Catalog effect id; None: the nominal model.
    values : dict of str to float, optional
        The effect's parameters by name (SI).

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    plant = plant_of(case)
    simulate = simulate_exudyn
    if is_towing(plant):
        simulate = simulate_towing_exudyn
    if effect_id is None:
        return simulate(plant, times)
    effect = CATALOG[effect_id]
    names = list(values)
    return simulate(plant, times, effect, np.array([values[n] for n in names]), names)


def simulate_constant_body_torque(case, times, torque_body) -> dict:
    """Clean channels with a constant torque (N m) fixed in the main body's frame (an outgassing jet,
    not in the catalog): the out-of-catalog check of the tests.

    Parameters
    ----------
    case : TumblingRigidCase or HingedAppendageCase
        Validated diagnosis case.
    times : (k,) float
        Sample times (s) from t = 0.
    torque_body : (3,) float
        Torque on the main body, B (N m).

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    scenario = ExudynScenario(Plant.from_case(case))
    torque = np.asarray(torque_body, float)
    scenario.add_body_torque(lambda t, body, rot, omega: torque if body == 0 else np.zeros(3))
    return scenario.simulate(np.asarray(times, float))
