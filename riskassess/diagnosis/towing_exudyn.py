"""The towing scenario in Exudyn with an effect: the reference of the fast model and the generator
of the tests' and samples' measured data.

:func:`multibody.towing.build_towing_system` (chaser and debris Exudyn rigid bodies, one generic
object whose force user function evaluates the compiled towing forces with P stepped implicitly);
its force user function here first evaluates the effect's towing law at the state Exudyn passes
(:func:`multibody.towing_kernel.apply_loads`), as the fast model does. Sampled on a fine grid and
interpolated linearly to the requested times (sensor delays shift them off the grid).
"""
from __future__ import annotations

import exudyn as exu
import numpy as np

from riskassess.diagnosis.effects.base import own_states
from riskassess.diagnosis.plants.towing_dynamics import no_towing_load
from riskassess.diagnosis.plants.towing_plant import TowingPlant, channels
from multibody.impact import _object_state_index, explicit_settings
from multibody.towing import build_towing_system, packed
from multibody.towing_kernel import N_COORDINATES, apply_loads, body_forces, sampled_state
from multibody.solver_output import solver_chatter_captured

#: Exudyn step (s): the towing case's default (docs/towing.md: step study, 1.3e-4 m and 3.5e-5 rad/s
#: from a 0.25 ms run over 275 s); the fast model runs at 20 ms.
EXUDYN_STEP = 4e-3
#: Spacing of the recorded samples (s) before interpolation: every step (the main-tether tension
#: carries the connection point's fast modes: interpolated over 20 ms it was off by up to 5 N).
RECORD_INTERVAL = EXUDYN_STEP


class _EffectForces:
    """Force user function: the effect's loads, then :func:`multibody.towing_kernel.body_forces`."""

    def __init__(self, model, law, p, xe):
        self.model, self.law = model, law
        self.p = np.zeros(1) if len(p) == 0 else np.ascontiguousarray(p, float)
        self.tow = packed(model)
        self.work = self.tow.work      # the same array (the effect laws read it)
        self.xe = np.ascontiguousarray(xe, float)     # the effect's own states, advanced by its law
        self.load = np.zeros(N_COORDINATES)
        self.last_time = None

    def __call__(self, mbs, t, item, q, q_t):
        advance = self.last_time is None or t > self.last_time
        h = 0.0 if self.last_time is None or not advance else t - self.last_time
        self.last_time = t if advance else self.last_time
        full_q, full_v = np.zeros(N_COORDINATES), np.zeros(N_COORDINATES)
        full_q[3:], full_v[3:] = q, q_t
        apply_loads(self.law, self.model.start_time + t, full_q, full_v, self.p, self.work, self.xe, h, self.load)
        return body_forces(np.asarray(q), np.asarray(q_t), self.model.start_time + t, self.tow, advance)


def simulate_towing_exudyn(plant: TowingPlant, times, effect=None, values=(), names=(), step: float = EXUDYN_STEP) -> dict:
    """Channels at ``times`` (s from the record's t = 0) of ``plant`` with ``effect`` at ``values``, by Exudyn.

    Parameters
    ----------
    plant : TowingPlant
        The towing plant.
    times : (k,) float
        Sample times (s from the record's t = 0).
    effect : Effect, optional
        The effect (its towing law); None: the nominal model.
    values : (m,) float
        Its physical parameter values (SI).
    names : sequence of str
        Their names.
    step : float, optional
        Exudyn Verlet step (s), a divisor of ``RECORD_INTERVAL``.

    Returns
    -------
    channels : dict of str to (k,) float
        See :mod:`riskassess.diagnosis.plants.towing_plant` (rad/s, D; D -> LVLH; m, LVLH; N).
    """
    values = np.asarray(values, float)
    sample_times = np.asarray(times, float)
    law, p = no_towing_load, np.zeros(1)
    if effect is not None:
        plant = effect.modify_plant(plant, values)
        sample_times = effect.sample_times(sample_times, values)
        law, p = effect.towing_law, effect.towing_law_parameters(plant, values)
    every = int(round(RECORD_INTERVAL / step))
    model = plant.model(float(sample_times.max()) + 2 * RECORD_INTERVAL, step)
    forces = _EffectForces(model, law, p, np.zeros(0) if effect is None else own_states(effect, model, towing=True))
    sc, mbs, nodes = build_towing_system(model, forces)
    index = _object_state_index(mbs, nodes, [6, 6])
    rows = []

    def record(mbs_, t):
        if len(rows) < model.n_steps // every + 1 and round(t / step) % every == 0:
            data = mbs_.systemData
            q, v = np.asarray(data.GetODE2Coordinates())[index], np.asarray(data.GetODE2Coordinates_t())[index]
            rows.append((*sampled_state(q, v, model.start_time + t, forces.tow), forces.xe.copy()))
        return True

    mbs.SetPostStepUserFunction(record)      # Exudyn also calls it at the initial time
    with solver_chatter_captured():
        exu.SolveDynamic(mbs, explicit_settings(step, model.n_steps), solverType=exu.DynamicSolverType.VelocityVerlet)
    grid = every * step * np.arange(len(rows))
    out = channels(plant, model, *(np.array([r[k] for r in rows]) for k in range(4)))
    out = {c: np.interp(sample_times, grid, y) for c, y in out.items()}
    return effect.measure(out, values, names) if effect is not None else out
