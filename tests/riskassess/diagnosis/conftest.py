"""Diagnosis scenarios for the tests (SI), built from the sample case files in cases/."""
from __future__ import annotations

from pathlib import Path

import pytest

from riskassess.diagnosis.cases import diagnosis_case_from_dict
from riskassess.cases.impact import read_toml

CASES = Path(__file__).parents[3] / "cases"
TUMBLING_CASE = CASES / "diagnose_tumbling_rigid.toml"
HINGED_CASE = CASES / "diagnose_hinged_appendage.toml"
TOWING_CASE = CASES / "diagnose_towing.toml"


def case_with(path: Path, **changes):
    """The case file's content with top-level tables updated (``initial={...}`` merges into [initial])."""
    raw = read_toml(path)
    for key, value in changes.items():
        raw[key] = {**raw.get(key, {}), **value} if isinstance(value, dict) and key != "orbit" else value
    return diagnosis_case_from_dict(raw, path.parent)   # a towing case names its file relative to it


@pytest.fixture
def tumbling_rocket_body():
    """cases/diagnose_tumbling_rigid.toml: 1500 kg body at ~0.2 rad/s, circular 780 km orbit."""
    return case_with(TUMBLING_CASE)


@pytest.fixture
def panel_on_hinge():
    """cases/diagnose_hinged_appendage.toml: 800 kg body, 60 kg panel released at 0.4 rad."""
    return case_with(HINGED_CASE)


@pytest.fixture
def zenit_tow():
    """cases/diagnose_towing.toml: the Zenit-2 lower-order tow of cases/zenit2_towing.toml (Boonrath,
    Singh & Botta 2024, Tables 1-3), record from thrust-on."""
    return case_with(TOWING_CASE)
