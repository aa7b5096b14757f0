"""The Exudyn scenarios against the compiled model the fit uses, and an extended case in Exudyn."""
from __future__ import annotations

import numpy as np
import pytest

from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.exudyn_model import simulate_case, simulate_exudyn
from riskassess.diagnosis.model import predict
from riskassess.diagnosis.plants.plant import Plant
from riskassess.cases.diagnosis import toml_text
from riskassess.diagnosis.cases import load_diagnosis_case
from riskassess.cases.impact import read_toml
from tests.riskassess.diagnosis.conftest import HINGED_CASE, TUMBLING_CASE, case_with

TIMES = np.arange(0.0, 10.01, 0.1)


def _max_difference(a: dict, b: dict) -> dict:
    sign = np.sign(sum(a[c] * b[c] for c in ("q_w", "q_x", "q_y", "q_z")))
    return {c: np.abs(a[c] - (sign * b[c] if c.startswith("q_") else b[c])).max() for c in a}


def _range(channels: dict) -> dict:
    return {c: max(np.ptp(v), 1e-3) for c, v in channels.items()}


@pytest.mark.parametrize("path, effect_id, values", [
    (HINGED_CASE, None, []),
    (HINGED_CASE, "hinge_coulomb_friction", [1.5]),
    (TUMBLING_CASE, "eddy_current_damping", [20.0, 0.4, 0.6]),
    (TUMBLING_CASE, "internal_energy_dissipation", [20.0, 10.0]),
    (TUMBLING_CASE, "com_offset", [0.1, -0.2, 0.05]),
])
def test_exudyn_and_compiled_models_agree(path, effect_id, values):
    """Same case, same effect. With a hinge, the penalty hinge (mode at 125 rad/s) and the ideal hinge
    of the compiled model differ by the penalty's compliance, (0.5 rad/s / 125 rad/s)^2 ~ 1e-5 of the
    motion; measured <= 6e-5 of each channel's range. The rigid body differs by the two RK4 errors
    only. Tolerance 2e-4 of the range."""
    case = case_with(path)
    plant = Plant.from_case(case)
    effect = CATALOG[effect_id] if effect_id else None
    names = [p.name for p in effect.parameter_specs(case)] if effect else []
    fast = predict(plant, TIMES, effect, values, names)
    exudyn = simulate_exudyn(plant, TIMES, effect, values, names)
    nominal = predict(plant, TIMES)
    spans = _range(fast)
    for channel, diff in _max_difference(fast, exudyn).items():
        assert diff < 2e-4 * spans[channel], (channel, diff, spans[channel])
    if effect is not None:   # and the effect itself is far larger than the difference
        change = max(np.abs(fast[c] - nominal[c]).max() / spans[c] for c in fast)
        assert change > 20 * 2e-4


def test_a_finished_exudyn_scenario_is_freed():
    """The scenario's recorder held the Exudyn system while Exudyn held the recorder's post-step function from C++:
    a cycle the collector cannot see, so every simulated scenario stayed in memory (6 after this module's runs,
    2026-11-28). Cleared after the run (multibody.impact.detach_step_functions): exact, no recorder is left."""
    import gc

    plant = Plant.from_case(case_with(HINGED_CASE))
    channels = simulate_exudyn(plant, TIMES[:11])
    assert len(channels["q_w"]) == 11                       # the run happened: 1 s sampled at 10 Hz
    gc.collect()
    assert [o for o in gc.get_objects() if type(o).__name__ == "_Recorder"
            and type(o).__module__ == "riskassess.diagnosis.exudyn_model"] == []


def test_extended_case_loads_and_simulates_in_exudyn(tmp_path):
    raw = read_toml(HINGED_CASE)
    raw["effects"] = [{"id": "hinge_stiffness_hardening", "parameters": {"cubic_stiffness": 200.0}}]
    path = tmp_path / "extended.toml"
    path.write_text(toml_text(raw))
    case = load_diagnosis_case(path)
    out = simulate_case(case, TIMES[:51])
    plant = Plant.from_case(case)
    fast = predict(plant, TIMES[:51], CATALOG["hinge_stiffness_hardening"], [200.0], ["cubic_stiffness"])
    # as above: the penalty hinge's compliance, 2e-4 of the range
    assert np.abs(out["hinge_angle"] - fast["hinge_angle"]).max() < 2e-4 * np.ptp(fast["hinge_angle"])
