"""Case kinds: every shipped case says its kind; files written before kinds were explicit still read."""
from pathlib import Path

import pytest

from riskassess.cases.impact import read_toml
from riskassess.stages.kinds import case_kind, load_any_case

CASES = Path(__file__).resolve().parents[3] / "cases"
SHIPPED = sorted(CASES.glob("*.toml"))
# The legacy form (a diagnosis file's scenario in ``kind``) predates the impact diagnosis scenario, whose
# scenario name is also the impact case kind: no file of that form can exist, so it is not converted.
LEGACY_SHIPPED = [p for p in SHIPPED if read_toml(p).get("scenario") != "impact"]


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_every_shipped_case_names_its_kind(path):
    raw = read_toml(path)
    assert raw["kind"] in ("impact", "towing", "approach", "diagnosis")
    assert case_kind(raw) == raw["kind"]


def _legacy(raw: dict) -> dict:
    """The file as written before the explicit kind: no kind, a diagnosis file's scenario in ``kind``."""
    raw = dict(raw)
    kind = raw.pop("kind")
    if kind == "diagnosis":
        raw["kind"] = raw.pop("scenario")
    return raw


@pytest.mark.parametrize("path", LEGACY_SHIPPED, ids=lambda p: p.name)
def test_files_without_the_explicit_kind_read_the_same(path, tmp_path):
    from riskassess.cases.diagnosis import toml_text

    raw = read_toml(path)
    legacy = tmp_path / path.name
    legacy.write_text(toml_text(_legacy(raw)))
    for name in ("zenit2_towing.toml",):          # the towing diagnosis names its towing case beside it
        (tmp_path / name).write_bytes((CASES / name).read_bytes())
    kind_new, case_new = load_any_case(path)
    kind_old, case_old = load_any_case(legacy)
    assert kind_new == kind_old == raw["kind"]
    assert case_new.model_dump() == case_old.model_dump()


def test_an_unknown_kind_names_the_kinds_and_the_scenarios():
    with pytest.raises(ValueError) as err:
        case_kind({"kind": "tow"})
    message = str(err.value)
    assert "'tow' is not a case kind" in message and "impact, towing, diagnosis, approach" in message
    assert "hinged_appendage" in message
