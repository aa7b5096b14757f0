"""One prediction of the measured channels: plant + at most one effect, by the fast model."""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.plants.dynamics import environment, initial_state, integrate, no_load
from riskassess.diagnosis.effects.base import Effect, own_states
from riskassess.diagnosis.observation import outputs
from riskassess.diagnosis.plants.plant import Plant, is_towing
from riskassess.diagnosis.plants.towing_plant import simulate as simulate_towing

#: RK4 step as a fraction of the fastest motion's period / 2 pi (rad): 0.1 rad per step keeps the
#: RK4 error of a 300 s record near 1e-4 of the signal's range, a tenth of typical sensor noise
#: (checked against a halved step in tests/diagnosis/test_dynamics.py).
ANGLE_PER_STEP = 0.1
#: Longest RK4 step (s).
MAX_STEP = 0.25


def max_step(plant: Plant, stiffness_rate: float = 0.0) -> float:
    """The RK4 step (s) for a plant and an effect's fastest decay rate (1/s); the towing model's
    Verlet step is the case's ``fit_step``.

    Parameters
    ----------
    plant : Plant or TowingPlant
        The plant (its fastest motion rate, rad/s, or its ``fit_step``, s).
    stiffness_rate : float
        The effect's fastest decay rate (1/s); 0: none.

    Returns
    -------
    step : float
        (s).
    """
    step = plant.fit_step if is_towing(plant) else min(MAX_STEP, ANGLE_PER_STEP / plant.rate_scale())
    return min(step, 1.5 / stiffness_rate) if stiffness_rate > 0 else step


def predict(plant: Plant, times, effect: Effect | None = None, values=(), names=(), step: float | None = None) -> dict:
    """Channels (dict of (k,) arrays) at ``times`` (s) of ``plant`` with ``effect`` at ``values``.

    Parameters
    ----------
    plant : Plant or TowingPlant
        The plant (nominal parameters already set).
    times : (k,) float
        Sample times (s) from the record's t = 0, non-decreasing.
    effect : Effect, optional
        The effect; None: the nominal model.
    values : (m,) float
        Its physical parameter values (SI, order of its ``parameter_specs``).
    names : sequence of str
        Their names.
    step : float, optional
        Integration step (s); default :func:`max_step`.

    Returns
    -------
    channels : dict of str to (k,) float
        Units and frames of :mod:`riskassess.diagnosis.plants.channels`.
    """
    times = np.asarray(times, float)
    values = np.asarray(values, float)
    if is_towing(plant):
        return _predict_towing(plant, times, effect, values, names, step)
    if effect is None:
        law, p, sample_times, x0 = no_load, np.zeros(1), times, initial_state(plant)
    else:
        plant = effect.modify_plant(plant, values)
        law, p, sample_times = effect.law, effect.law_parameters(plant, values), effect.sample_times(times, values)
        x0 = initial_state(plant, own_states(effect, plant))     # the effect's states after the base state
    step = step or max_step(plant, effect.parameter_free_stiffness_rate(plant) if effect is not None else 0.0)
    states = integrate(law, np.ascontiguousarray(p if p.size else np.zeros(1), float), environment(plant),
                       x0, np.ascontiguousarray(sample_times, float), step)
    out = outputs(plant, sample_times, states)
    return effect.measure(out, values, names) if effect is not None else out


def _predict_towing(plant, times, effect, values, names, step) -> dict:
    """:func:`predict` of the towing scenario (:func:`riskassess.diagnosis.plants.towing_plant.simulate`)."""
    if effect is None:
        return simulate_towing(plant, times, step=step)
    plant = effect.modify_plant(plant, values)
    out = simulate_towing(plant, effect.sample_times(times, values), effect.towing_law,
                          effect.towing_law_parameters(plant, values), step,
                          lambda model: own_states(effect, model, towing=True))
    return effect.measure(out, values, names)
