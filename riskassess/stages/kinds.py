"""Which stage a case file is written for, its schema and its loader: one table for
``riskassess validate``, ``riskassess schema --kind`` and the tests of the shipped cases.

Each stage has its own case schema (see the modules below); the kind is told from the file's
top-level tables, then the file is validated by that stage's schema, so the errors name the
stage's keys.
"""
from __future__ import annotations

from pathlib import Path

from riskassess.cases.impact import CaseError, read_toml

#: Case kind -> the commands that run a case of that kind. Each kind's schema and loader are
#: imported only when a file of that kind is read (:func:`schema_and_loader`): ``riskassess run``
#: then never loads the towing and diagnosis packages (and their compiled kernels).
KINDS = {
    "impact": "run, assess, perceive, sweep",
    "towing": "tow, identify",
    "diagnosis": "diagnose",
    "approach": "approach",
}


def schema_and_loader(kind: str) -> tuple[type, object]:
    """The pydantic model of a case file of ``kind`` and the loader of such a file.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.

    Returns
    -------
    model : type
        The case file's pydantic model.
    loader : callable
        ``loader(path)`` -> the validated case; :class:`~riskassess.cases.impact.CaseError` naming the
        file and keys when it is not valid.
    """
    _known(kind)
    from riskassess.cases.impact import load_model
    if kind == "impact":
        from riskassess.cases.impact import Case, load_case
        return Case, load_case
    if kind == "towing":
        from riskassess.cases.towing import TowingCase
        return TowingCase, lambda path: load_model(path, TowingCase)
    if kind == "diagnosis":
        from riskassess.cases.diagnosis import DiagnosisCaseFile
        from riskassess.diagnosis.cases import load_diagnosis_case
        return DiagnosisCaseFile, load_diagnosis_case
    from riskassess.cases.approach import ApproachCase
    return ApproachCase, lambda path: load_model(path, ApproachCase)


def case_kind(raw: dict) -> str:
    """'impact', 'approach', 'towing' or 'diagnosis' for the parsed TOML of a case file: its
    top-level ``kind``. Files written before the kind was explicit are told by their tables
    (a diagnosis file then names its scenario in ``kind``).

    Parameters
    ----------
    raw : dict
        Parsed TOML of a case file.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        For a ``kind`` that is not a text or not a known kind (the message lists the kinds).
    """
    kind = raw.get("kind")
    if kind is not None and not isinstance(kind, str):
        raise ValueError(f"kind: a text is expected (one of {', '.join(KINDS)}); got {type(kind).__name__}")
    if kind in KINDS and not (kind == "towing" and _legacy_diagnosis(raw)):
        return kind
    if kind is not None:
        from riskassess.cases.diagnosis import SCENARIOS  # a diagnosis file names its scenario
        if kind in SCENARIOS:
            return "diagnosis"
        raise ValueError(f"kind: '{kind}' is not a case kind; the kinds are: {', '.join(KINDS)} "
                         f"(a diagnosis file: kind = \"diagnosis\" and scenario = one of {', '.join(SCENARIOS)})")
    return _kind_from_tables(raw)


def _legacy_diagnosis(raw: dict) -> bool:
    """A diagnosis file of the towing scenario written before case kinds (``kind = "towing"``,
    naming its towing case in ``towing``) rather than a towing case (its tethers are tables)."""
    return isinstance(raw.get("towing"), str) and "main_tether" not in raw and "sub_tethers" not in raw


def _kind_from_tables(raw: dict) -> str:
    if "model" in raw and "objective" in raw:  # maneuverable-unit approach
        return "approach"
    if "main_tether" in raw or "sub_tethers" in raw:
        return "towing"
    return "impact"                            # net impact, assess and perceive


def _known(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"unknown case kind '{kind}'; the kinds are: {', '.join(KINDS)}")


def load_any_case(path: str | Path) -> tuple[str, object]:
    """(kind, validated case) of any case file; :class:`~riskassess.cases.impact.CaseError` naming the
    file and the keys when it is not valid for its kind.

    Parameters
    ----------
    path : str or Path
        A case file of any kind.

    Returns
    -------
    kind : str
    case : pydantic.BaseModel
        The validated case of that kind.
    """
    try:
        kind = case_kind(read_toml(path))
    except CaseError:
        raise
    except ValueError as exc:
        raise CaseError(f"{path}: {exc}") from None
    return kind, schema_and_loader(kind)[1](path)


def case_schema(kind: str = "impact") -> dict:
    """The JSON schema (draft 2020-12, pydantic's) of a case file of ``kind``: keys, units in the
    descriptions, ranges, required keys; a diagnosis file is one of its scenario kinds (``kind``
    discriminator). ``ValueError`` listing the kinds for an unknown one.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.

    Returns
    -------
    dict
    """
    model, _ = schema_and_loader(kind)
    commands = KINDS[kind]
    schema = model.model_json_schema()
    schema.setdefault("title", model.__name__)
    schema["description"] = (f"riskassess {kind} case file (TOML), for: {commands}. "
                             + schema.get("description", "")).strip()
    return schema
