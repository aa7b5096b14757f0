"""The effect catalog: one interface, stable ids, laws against their physics."""
from __future__ import annotations

import numpy as np
import pytest

from riskassess.diagnosis.plants.dynamics import X_EXTRA, X_W, angular_momentum_inertial, environment, initial_state, integrate
from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.effects.base import own_states
from riskassess.diagnosis.effects.gravity_gradient_torque import gravity_gradient
from riskassess.diagnosis.model import max_step
from multibody.maths.rotations import quaternion_to_matrix
from riskassess.diagnosis.plants.plant import Plant
from tests.riskassess.diagnosis.conftest import HINGED_CASE, TOWING_CASE, TUMBLING_CASE, case_with

REQUIRED = {"hinge_coulomb_friction", "hinge_stiffness_hardening", "hinge_backlash", "internal_energy_dissipation",
            "eddy_current_damping", "gravity_gradient_torque", "j2_perturbation", "tether_viscoelasticity",
            "thrust_misalignment", "com_offset", "sensor_time_delay", "sensor_bias"}


@pytest.mark.parametrize("path", [TUMBLING_CASE, HINGED_CASE, TOWING_CASE])
def test_catalog_has_every_required_effect_with_units_and_bounds(path):
    case = case_with(path)
    assert REQUIRED <= set(CATALOG)
    for effect in CATALOG.values():
        if case.kind == "towing" and case.kind not in effect.scenarios:   # the hinge effects: no hinge to size
            continue
        for p in effect.parameter_specs(case):
            assert p.unit and p.lower <= p.typical <= p.upper, (effect.id, p)


def test_catalog_refuses_an_unknown_effect_listing_the_known_ones():
    """Issue 21: every plug-in family refuses an unknown name with the known ones (multibody/maths/plugins.py)."""
    with pytest.raises(ValueError) as unknown:
        CATALOG["solar_pressure"]
    assert str(unknown.value) == f"unknown effect 'solar_pressure'; the known effects are: {', '.join(sorted(CATALOG))}"
    assert REQUIRED <= set(str(unknown.value).split(": ")[1].split(", "))


def test_towing_effects_are_not_applicable_to_the_free_scenarios(tumbling_rocket_body):
    for effect_id in ("tether_viscoelasticity", "thrust_misalignment"):
        assert "towing" in CATALOG[effect_id].not_applicable(tumbling_rocket_body, ["omega_x"])


def test_towing_scenario_takes_every_effect_but_the_hinge_ones(zenit_tow):
    channels = ["omega_x", "omega_y", "omega_z", "q_w", "q_x", "q_y", "q_z", "rel_x", "rel_y", "rel_z", "tether_tension"]
    open_ = {k for k, e in CATALOG.items() if e.not_applicable(zenit_tow, channels) is None}
    assert open_ == set(CATALOG) - {"hinge_coulomb_friction", "hinge_stiffness_hardening", "hinge_backlash"}
    assert "bias_tether_tension" in [p.name for p in CATALOG["sensor_bias"].parameter_specs(zenit_tow, channels)]


def _run(case, effect_id, values, duration=200.0):
    plant = Plant.from_case(case)
    effect = CATALOG[effect_id]
    specs = effect.parameter_specs(case)
    times = np.linspace(0.0, duration, 201)
    p = np.asarray(values, float)
    states = integrate(effect.law, p, environment(plant), initial_state(plant, own_states(effect, plant)), times,
                       max_step(plant, effect.stiffness_rate(plant, specs)))
    return plant, states


def test_nutation_damper_keeps_total_momentum_and_dissipates_energy():
    case = case_with(TUMBLING_CASE, orbit={"kind": "none"})
    damper_inertia = 20.0
    plant, states = _run(case, "internal_energy_dissipation", [damper_inertia, 20.0])
    rot = [quaternion_to_matrix(x[:4]) for x in states]
    rotor = states[:, X_EXTRA:X_EXTRA + 3]         # the damper's own states, the first after the base state
    total = angular_momentum_inertial(plant, states) + damper_inertia * np.array(
        [r @ w for r, w in zip(rot, rotor)])
    energy = np.array([0.5 * x[X_W:X_W + 3] @ plant.inertia_main @ x[X_W:X_W + 3]
                       + 0.5 * damper_inertia * w @ w for x, w in zip(states, rotor)])
    # Internal torques only: total momentum constant to the RK4 error (1e-6 of |H|, as torque-free).
    assert np.abs(total - total[0]).max() < 1e-6 * np.linalg.norm(total[0])
    assert np.all(np.diff(energy) <= 1e-9 * energy[0]) and energy[-1] < (1 - 1e-3) * energy[0]


def test_eddy_currents_brake_the_spin_normal_to_the_field():
    case = case_with(TUMBLING_CASE, orbit={"kind": "none"})
    plant, states = _run(case, "eddy_current_damping", [5.0, 0.0, np.pi / 2])   # field along I z
    h = angular_momentum_inertial(plant, states)
    # torque -c (omega - (omega.b) b) has no component along b: H_z constant (RK4 error, 1e-6 of |H|);
    # the normal part decays
    assert abs(h[-1, 2] - h[0, 2]) < 1e-6 * np.linalg.norm(h[0])
    assert np.linalg.norm(h[-1, :2]) < 0.9 * np.linalg.norm(h[0, :2])


def test_gravity_gradient_torque_of_a_tilted_body():
    """Hughes eq. 8.1.13: body tilted by a about z from the radial direction: tau_z = 3 n^2 (Jx - Jy) sin 2a / 2
    (sign: the torque turns the minimum axis towards the radial direction)."""
    n, a = 1.1e-3, 0.3
    inertia = np.diag([100.0, 300.0, 350.0])
    radial_body = np.array([np.cos(a), -np.sin(a), 0.0])
    torque = np.array(gravity_gradient(radial_body, inertia @ radial_body, n))
    assert torque == pytest.approx([0.0, 0.0, 3 * n * n * (inertia[1, 1] - inertia[0, 0]) * np.sin(2 * a) / 2 * -1],
                                   abs=1e-15)


def test_j2_acceleration_is_the_gradient_of_the_j2_potential():
    """J2 term of the (positive) geopotential U = -mu J2 R^2 / (2 r^3) (3 z^2 / r^2 - 1) (Vallado
    eq. 8-24, a = +grad U): gradient by central differences (step 1 m at 7e6 m: truncation ~1e-12
    relative, rounding ~1e-9 of 1e-2 m/s^2)."""
    from riskassess.diagnosis.effects.j2_perturbation import J2_EARTH, j2_acceleration
    from multibody.orbit import MU_EARTH, R_EARTH

    def potential(r):
        rn = np.linalg.norm(r)
        return -MU_EARTH * J2_EARTH * R_EARTH ** 2 / (2 * rn ** 3) * (3 * r[2] ** 2 / rn ** 2 - 1)

    r = np.array([4.1e6, -3.3e6, 4.6e6])
    gradient = np.array([(potential(r + e) - potential(r - e)) / 2.0 for e in np.eye(3)])
    assert j2_acceleration(r, J2_EARTH) == pytest.approx(gradient, rel=1e-6)


def test_sensor_effects_transform_the_channels():
    times = np.array([0.0, 0.5, 1.0, 3.0])
    assert np.allclose(CATALOG["sensor_time_delay"].sample_times(times, [0.7]), [0.0, 0.0, 0.3, 2.3])
    out = CATALOG["sensor_bias"].measure({"omega_x": np.zeros(2), "q_w": np.ones(2)}, [0.01], ["bias_omega_x"])
    assert np.allclose(out["omega_x"], 0.01) and np.allclose(out["q_w"], 1.0)
