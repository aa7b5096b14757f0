"""The fast compiled model against conservation laws, the Clohessy-Wiltshire solution and a halved step."""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.plants.dynamics import (X_W, angular_momentum_inertial, appendage_state, environment, initial_state, integrate,
                                no_load)
from riskassess.diagnosis.model import max_step, predict
from riskassess.diagnosis.plants.plant import Plant
from tests.riskassess.diagnosis.conftest import HINGED_CASE, TUMBLING_CASE, case_with

NO_ORBIT = {"kind": "none"}


def _states(plant, times, step=None):
    return integrate(no_load, np.zeros(1), environment(plant), initial_state(plant), times, step or max_step(plant))


def _kinetic_energy(plant, x):
    env = environment(plant)
    w = x[X_W:X_W + 3]
    energy = 0.5 * w @ plant.inertia_main @ w
    if plant.hinged:
        s, d, ja = appendage_state(env, x[7])
        mr = plant.mass_main * plant.mass_appendage / plant.total_mass
        om = w + x[8] * plant.axis
        v = np.cross(w, d) + x[8] * np.cross(plant.axis, s)
        energy += 0.5 * om @ ja @ om + 0.5 * mr * v @ v + 0.5 * plant.stiffness * x[7] ** 2
    return energy


def test_torque_free_rigid_body_keeps_momentum_and_energy():
    plant = Plant.from_case(case_with(TUMBLING_CASE, orbit=NO_ORBIT))
    states = _states(plant, np.linspace(0.0, 300.0, 301))
    h = angular_momentum_inertial(plant, states)
    energy = np.array([_kinetic_energy(plant, x) for x in states])
    # RK4 at 0.1 rad per step: relative drift ~ (0.1)^4 / 120 per step x 1200 steps ~ 1e-6;
    # 1e-6 of |H| and of the energy bound it.
    assert np.abs(h - h[0]).max() < 1e-6 * np.linalg.norm(h[0])
    assert np.abs(energy - energy[0]).max() < 1e-6 * energy[0]


def test_hinged_bodies_keep_momentum_and_energy_without_damping():
    plant = Plant.from_case(case_with(HINGED_CASE, orbit=NO_ORBIT)).replace(damping=0.0)
    states = _states(plant, np.linspace(0.0, 300.0, 301))
    assert np.ptp(states[:, 7]) > 0.7          # the panel swings through +-0.4 rad
    h = angular_momentum_inertial(plant, states)
    energy = np.array([_kinetic_energy(plant, x) for x in states])
    # The step is 0.1 rad of the hinge mode (as for the tumble); RK4's energy error grows with the
    # ~30 hinge periods: measured 1.2e-5 of the energy and 3e-7 of |H| over 300 s; bounds 3e-5, 1e-6.
    assert np.abs(h - h[0]).max() < 1e-6 * np.linalg.norm(h[0])
    assert np.abs(energy - energy[0]).max() < 3e-5 * energy[0]


def test_step_halving_changes_the_channels_by_less_than_a_tenth_of_sensor_noise():
    plant = Plant.from_case(case_with(HINGED_CASE))
    times = np.linspace(0.0, 300.0, 3001)
    coarse = predict(plant, times)
    fine = predict(plant, times, step=max_step(plant) / 2)
    # Sensor noise of the sample data: 2e-4 rad/s gyro, 1e-3 quaternion / rad, 1 cm (riskassess.diagnosis.synthetic.NOISE).
    tolerance = {"omega": 2e-5, "q": 1e-4, "hinge": 1e-4, "rel": 1e-3}
    for channel, values in coarse.items():
        assert np.abs(values - fine[channel]).max() < tolerance[channel.split("_")[0]], channel


def test_centre_of_mass_follows_clohessy_wiltshire():
    """A rigid body with its CoM at the tracked point: rel_x..z is the CW solution (Curtis (7.53))."""
    case = case_with(TUMBLING_CASE, main_body={"center_of_mass": [0.0, 0.0, 0.0]},
                     initial={"position_lvlh": [5.0, 30.0, -4.0], "velocity_lvlh": [0.01, -0.02, 0.005]})
    plant = Plant.from_case(case)
    n = plant.mean_motion
    t = np.linspace(0.0, 3000.0, 61)
    (x0, y0, z0), (u0, v0, w0) = plant.position0, plant.velocity0
    s, c = np.sin(n * t), np.cos(n * t)
    expected = np.column_stack([(4 - 3 * c) * x0 + s / n * u0 + 2 / n * (1 - c) * v0,
                                6 * (s - n * t) * x0 + y0 - 2 / n * (1 - c) * u0 + (4 * s - 3 * n * t) / n * v0,
                                z0 * c + w0 / n * s])
    out = predict(plant, t)
    rel = np.column_stack([out[k] for k in ("rel_x", "rel_y", "rel_z")])
    # The model integrates the same linear equations in inertial axes by RK4: 1e-6 m over 3000 s.
    assert np.abs(rel - expected).max() < 1e-6
