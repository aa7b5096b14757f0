"""The "none of these" alternative (riskassess.diagnosis.discrepancy): effects outside the catalog are
not pinned on a catalog cause with confidence, and the alternative's law is what it says."""
from __future__ import annotations

import numpy as np
import pytest

from riskassess.diagnosis.discrepancy import Discrepancy
from riskassess.diagnosis.exudyn_model import ExudynScenario
from riskassess.diagnosis.model import predict
from riskassess.diagnosis.plant import Plant
from riskassess.diagnosis.synthetic import channel_noise, sample_times
from tests.riskassess.diagnosis.conftest import HINGED_CASE, TUMBLING_CASE
from tests.riskassess.diagnosis.test_diagnose import DURATION, _diagnose


def test_discrepancy_torque_is_its_legendre_series(tumbling_rocket_body):
    # a constant body torque written as the P0 term equals the same torque added through Exudyn's
    # body-torque hook (the data generator): the compiled and Exudyn models agree to their usual
    # difference (checked in test_exudyn_model at 1e-3 of the motion)
    case = tumbling_rocket_body
    plant = Plant.from_case(case)
    times = sample_times(20.0, 10.0)
    discrepancy = Discrepancy(times[0], times[-1])
    names = [p.name for p in discrepancy.parameter_specs(case)]
    torque = np.array([0.5, -0.3, 0.2])           # N m: moves the rates by ~10 gyro sigmas in 20 s
    values = np.zeros(len(names))
    values[[0, 3, 6]] = torque                    # the P0 term of x, y, z
    fast = predict(plant, times, discrepancy, values, names)
    scenario = ExudynScenario(plant)
    scenario.add_body_torque(lambda t, k, rot, omega: torque if k == 0 else np.zeros(3))
    reference = scenario.simulate(times)
    nominal = predict(plant, times)
    for c in ("omega_x", "omega_y", "omega_z"):
        change = np.abs(reference[c] - nominal[c]).max()
        assert change > 1e-3                      # the torque moves the rates ...
        assert np.abs(fast[c] - reference[c]).max() < 0.02 * change   # ... and both models agree


@pytest.mark.parametrize("family, case_path", [("inertial_torque", TUMBLING_CASE),
                                               ("quadratic_hinge_damping", HINGED_CASE)])
def test_out_of_catalog_effects_get_no_confident_catalog_cause(tmp_path, family, case_path, request):
    """A torque fixed in inertial space (a solar-pressure-like load) and a quadratic hinge damping are
    in no catalog entry: 20 sigma of departure, default noise."""
    from tests.riskassess.diagnosis.conftest import case_with
    case = case_with(case_path)
    plant = Plant.from_case(case)
    rng = np.random.default_rng(7)
    times = sample_times(DURATION, 10.0)
    direction = np.array([0.3, -0.8, 0.52]) / np.linalg.norm([0.3, -0.8, 0.52])
    strength = 0.08 if family == "inertial_torque" else 400.0
    scenario = ExudynScenario(plant)
    if family == "inertial_torque":
        scenario.add_body_torque(lambda t, k, rot, omega: strength * rot.T @ direction if k == 0 else np.zeros(3))
    else:
        scenario.add_hinge_torque(lambda t, angle, rate: -strength * rate * abs(rate))
    clean = scenario.simulate(times)
    measured = {c: v + rng.normal(0.0, channel_noise(c), v.shape) for c, v in clean.items()}
    answer = _diagnose(tmp_path, case_path, measured, times)
    assert answer["cause"] != "none", answer["statement"]        # the departure is seen
    assert answer["cause"] == "unexplained" or answer["confidence"] < 0.5, answer["statement"]
    assert answer["none_of_these"] is not None
