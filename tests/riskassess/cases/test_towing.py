"""Towing case schema (riskassess/cases/towing.py) and the tow stage's run folder."""
import json
import tomllib

import numpy as np
import pytest

from riskassess.cases.impact import CaseError, load_model
from riskassess.models.towing import case_decision_vector, towing_model
from riskassess.cases.towing import TowingCase

CASE = "cases/zenit2_towing.toml"


def test_case_holds_the_paper_tables():
    case = load_model(CASE, TowingCase)
    # Boonrath et al. 2024 Table 1, Table 3, eq. (24), Sec. 4.3
    assert (case.chaser.mass, case.debris.nominal_mass, case.main_tether.stiffness) == (1600.0, 9000.0, 3000.0)
    assert case.rates.training_deg_s[0] == 10.71 and case.rates.validation_deg_s[-1] == 27.26
    assert case.identification.lower_bounds == [1.0, 5.0, 0.0, 0.1]
    np.testing.assert_allclose(case_decision_vector(case), [2.0, 7.0, 2.0, 1.0], rtol=1e-15)
    model = towing_model(case)
    # m_D = m_D,nom + m_net (1 - s4), m_P = m_net s4 (Sec. 4.1)
    assert model.masses[0] == pytest.approx(2.7326) and model.masses[2] == pytest.approx(9000.0)


def test_bad_value_names_file_and_key(tmp_path):
    raw = tomllib.loads(open(CASE).read())
    raw["identification"]["lower_bounds"] = [1.0, 5.0, 0.0, 0.0]
    raw["main_tether"]["stiffness"] = -3.0
    bad = tmp_path / "bad.toml"
    bad.write_text(_toml(raw))
    with pytest.raises(CaseError) as error:
        load_model(bad, TowingCase)
    message = str(error.value)
    assert f"{bad}: main_tether.stiffness" in message and "greater than 0" in message


def _toml(raw: dict) -> str:
    """Minimal TOML writer for the case's tables, arrays and scalars."""
    lines, tables = [], []
    for key, value in raw.items():
        (tables if isinstance(value, dict) else lines).append((key, value))
    out = [f"{k} = {json.dumps(v)}" for k, v in lines]
    for name, table in tables:
        sub = {k: v for k, v in table.items() if isinstance(v, dict)}
        out.append(f"[{name}]")
        out += [f"{k} = {json.dumps(v)}" for k, v in table.items() if not isinstance(v, dict)]
        for sub_name, sub_table in sub.items():
            out.append(f"[{name}.{sub_name}]")
            out += [f"{k} = {json.dumps(v)}" for k, v in sub_table.items()]
    return "\n".join(out) + "\n"
