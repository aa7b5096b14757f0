"""``riskassess schema --kind``: the JSON schema of every case kind."""
import json

import pytest

from riskassess.stages.kinds import KINDS, load_any_case
from riskassess.cli import main
from tests.riskassess.conftest import CASES

#: Keys a case of each kind must have (the top-level tables of the shipped cases).
REQUIRED = {
    "impact": {"name", "simulation", "net", "bullets", "launch", "contact", "target"},
    "towing": {"name", "simulation", "main_tether", "sub_tethers", "thrust"},
    "approach": {"name", "model", "debris", "thrust", "objective"},
}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_schema_of_every_kind(kind, capsys):
    assert main(["schema", "--kind", kind]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert kind in schema["description"]
    if kind == "diagnosis":   # kind = "diagnosis", one of the scenarios told by the 'scenario' key
        assert schema["discriminator"]["propertyName"] == "scenario"
        assert {"tumbling_rigid", "hinged_appendage"} <= set(schema["discriminator"]["mapping"])
        for ref in schema["discriminator"]["mapping"].values():
            variant = schema["$defs"][ref.rsplit("/", 1)[-1]]
            assert {"kind", "scenario", "name"} <= set(variant["required"])
            assert variant["properties"]["kind"]["const"] == "diagnosis"
    else:
        assert REQUIRED[kind] <= set(schema["required"])
        assert schema["additionalProperties"] is False   # unknown keys are refused


def test_schema_default_is_impact(capsys):
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out)["title"] == "Case"


@pytest.mark.parametrize("path", sorted(CASES.glob("*.toml")), ids=lambda p: p.name)
def test_shipped_cases_validate_against_their_kind_schema(path, capsys):
    jsonschema = pytest.importorskip("jsonschema")
    import tomllib

    kind, _ = load_any_case(path)
    assert main(["schema", "--kind", kind]) == 0
    jsonschema.validate(tomllib.loads(path.read_text()), json.loads(capsys.readouterr().out))
