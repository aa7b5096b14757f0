"""Property-based fuzz of every case loader (issue 20): mutated shipped cases give either a valid
case or a CaseError naming the file, never another exception.

The documents are the shipped cases (impact, towing, diagnosis, approach) with up to four
mutations: a value replaced by a random float (NaN, inf, huge, subnormal), integer, string
(numbers and booleans as text, markup such as ``[link=x]`` and ``$x^{$``, paths with '..',
absolute paths, /dev/zero), boolean, table or array; a key deleted or added; a list item
duplicated (duplicate names); a line of the TOML text repeated (a duplicate key). The case folder
holds the towing case the diagnosis case names, a symlink to /dev/zero, a directory and a garbage
mesh, so that file references meet each kind of file.
"""
import copy
import math
import re
import tempfile
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from riskassess.cases.approach import ApproachCase
from riskassess.cases.impact import CaseError, load_case, load_model
from riskassess.cases.inputs import read_toml
from riskassess.stages.kinds import load_any_case
from riskassess.diagnosis.cases import load_diagnosis_case
from riskassess.cases.towing import TowingCase

CASES = Path(__file__).resolve().parents[3] / "cases"
LOADERS = {"impact": load_case, "towing": lambda p: load_model(p, TowingCase), "diagnosis": load_diagnosis_case,
           "approach": lambda p: load_model(p, ApproachCase)}
SEEDS = {"envisat_small.toml": "impact", "tang2023_debris_perception.toml": "impact", "zenit2_towing.toml": "towing",
         "diagnose_hinged_appendage.toml": "diagnosis", "diagnose_tumbling_rigid.toml": "diagnosis",
         "diagnose_towing.toml": "diagnosis", "approach_mu_min_time.toml": "approach",
         "approach_rod_ic1_combined.toml": "approach"}
PARSED = {name: read_toml(CASES / name) for name in SEEDS}

# ---------------------------------------------------------------------------- values
FLOATS = st.one_of(st.floats(), st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, 5e-324, 1e18, 1e19,
                                                  0.0, -0.0, 1e-300]))
INTS = st.one_of(st.integers(-3, 300), st.sampled_from([2 ** 63, -2 ** 63 - 1, 10 ** 30, 0]))
TEXT = st.text(st.characters(blacklist_categories=("Cs",)), max_size=12)
STRINGS = st.one_of(TEXT, st.sampled_from([
    "nan", "inf", "-inf", "0.2", "1e400", "no", "yes", "true", "", " ", "../../escaped", "/tmp/abs", "/dev/zero", "..",
    ".", "a/../../b", "dz", "sub", "mesh.stl", "zenit2_towing.toml", "[link=x]", "x[/red]", "$x^{$", "C:\\x",
    "a\x00b", "\x1b[2J", "x" * 70, "main_body", "solar_array_hinge", "revolute", "circular", "box", "mesh",
    "tumbling_rigid", "towing", "min_time"]))
SCALARS = st.one_of(FLOATS, INTS, STRINGS, st.booleans())
KEYS = st.one_of(st.sampled_from(["kind", "name", "file", "mass", "x", "towing", "mass_properties_from"]),
                 st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=6))
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(KEYS, inner, max_size=3)), max_leaves=8)


def _slots(node, out=None):
    """Every (container, key) pair of the parsed document, tables and arrays included."""
    out = [] if out is None else out
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for key, value in list(items):
        out.append((node, key))
        if isinstance(value, (dict, list)):
            _slots(value, out)
    return out


def _mutate(draw, raw):
    container, key = draw(st.sampled_from(_slots(raw)))
    value = container[key]
    op = draw(st.sampled_from(["replace", "scale", "scale", "scale", "delete", "add", "duplicate", "nest"]))
    if op == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
        # mostly benign factors, so that a good share of the documents stays valid
        container[key] = value * draw(st.sampled_from([1, 1, 2, 0.5, 1.01, -1, 0, 1e-300, 1e300, math.inf]))
    elif op == "delete" and isinstance(container, dict):
        del container[key]
    elif op == "add" and isinstance(value, dict):
        value[draw(KEYS)] = draw(VALUES)
    elif op == "duplicate" and isinstance(value, list) and value:
        value.append(copy.deepcopy(value[draw(st.integers(0, len(value) - 1))]))
    elif op == "nest":
        container[key] = [value] if draw(st.booleans()) else {"x": value}
    else:
        container[key] = draw(VALUES)


# ---------------------------------------------------------------------------- TOML text
def _key(key) -> str:
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", str(key)) else _string(str(key))


def _string(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    return '"' + re.sub(r"[\x00-\x1f\x7f]", lambda m: f"\\u{ord(m.group()):04x}", escaped) + '"'


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"


def toml_text(raw: dict) -> str:
    """TOML of a parsed document: top-level keys, every table inline (any nesting writes)."""
    return "".join(f"{_key(k)} = {_value(v)}\n" for k, v in raw.items())


@st.composite
def mutated_cases(draw):
    """(seed file, its kind, TOML text) of a shipped case with up to four mutations."""
    name = draw(st.sampled_from(sorted(SEEDS)))
    raw = copy.deepcopy(PARSED[name])
    for _ in range(draw(st.sampled_from([0, 1, 1, 1, 2, 3, 4]))):   # 0: the shipped case, written back
        if raw:
            _mutate(draw, raw)
    text = toml_text(raw)
    if draw(st.integers(0, 9)) == 0:            # a duplicate key: one line repeated
        lines = text.splitlines(keepends=True)
        text += lines[draw(st.integers(0, len(lines) - 1))] if lines else ""
    return name, SEEDS[name], text


# ---------------------------------------------------------------------------- the property
def _folder(tmp: Path) -> None:
    """The files a mutated case may name: the towing case, /dev/zero, a directory, a garbage mesh."""
    (tmp / "zenit2_towing.toml").write_text((CASES / "zenit2_towing.toml").read_text())
    (tmp / "dz").symlink_to("/dev/zero")
    (tmp / "sub").mkdir()
    (tmp / "mesh.stl").write_text("solid x\nnot a facet\nendsolid x\n")


def _finite(value) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, (list, tuple)):
        return all(_finite(v) for v in value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    return True


def _check(tmp: Path, kind: str, text: str, outcomes: Counter) -> None:
    path = tmp / "case.toml"
    path.write_text(text, encoding="utf-8")
    for label, load in ((kind, LOADERS[kind]), ("any", lambda p: load_any_case(p)[1])):
        try:
            case = load(path)
        except CaseError as exc:
            message = str(exc)
            assert message.startswith(f"{path}: ") and len(message.split(": ", 2)) == 3, message
            outcomes[f"{label}: CaseError"] += 1
        else:
            assert _finite(case.model_dump()), "a valid case holds finite numbers only"
            outcomes[f"{label}: valid"] += 1


def _fuzz(examples: int) -> Counter:
    outcomes = Counter()
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        _folder(tmp)

        @settings(max_examples=examples, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
        @given(mutated_cases())
        def property_(case):
            _, kind, text = case
            _check(tmp, kind, text, outcomes)

        property_()
    return outcomes


def test_every_case_loader_gives_a_case_or_a_case_error():
    # 150 examples, each through its kind's loader and load_any_case: 3 s on an idle core, 25 s with the
    # 2 cores shared by four test runs (measured here).
    outcomes = _fuzz(150)
    print(dict(outcomes))
    assert outcomes["any: valid"] > 0 and outcomes["any: CaseError"] > 0, outcomes


@pytest.mark.slow
def test_every_case_loader_gives_a_case_or_a_case_error_long():
    # 5000 examples: 146 s on the shared machine (304 valid, 4696 CaseError in load_any_case at the time)
    outcomes = _fuzz(5000)
    print(dict(outcomes))
    assert outcomes["any: valid"] > 0 and outcomes["any: CaseError"] > 0, outcomes
