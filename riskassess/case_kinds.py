"""Which stage a case file is written for, and its loader: one table for ``riskassess validate``
and the tests of the shipped cases.

Each stage has its own case schema (see the modules below); the kind is told from the file's
top-level tables, then the file is validated by that stage's schema, so the errors name the
stage's keys.
"""
from __future__ import annotations

from pathlib import Path

from riskassess.case import load_case, load_model, read_toml


def case_kind(raw: dict) -> str:
    """'impact', 'approach', 'towing' or 'diagnosis' for the parsed TOML of a case file."""
    if "kind" in raw:                          # diagnosis scenarios: top-level kind
        return "diagnosis"
    if "model" in raw and "objective" in raw:  # maneuverable-unit approach
        return "approach"
    if "main_tether" in raw or "sub_tethers" in raw:
        return "towing"
    return "impact"                            # net impact, assess and perceive


def load_any_case(path: str | Path) -> tuple[str, object]:
    """(kind, validated case) of any case file; :class:`~riskassess.case.CaseError` naming the
    file and the keys when it is not valid for its kind."""
    kind = case_kind(read_toml(path))
    if kind == "approach":
        from riskassess.approach_case import ApproachCase
        return kind, load_model(path, ApproachCase)
    if kind == "towing":
        from riskassess.towing_case import TowingCase
        return kind, load_model(path, TowingCase)
    if kind == "diagnosis":
        from riskassess.diagnosis_case import load_diagnosis_case
        return kind, load_diagnosis_case(path)
    return kind, load_case(path)
