"""Diagnosis case files checked against the effect catalog: the schema
(:mod:`riskassess.cases.diagnosis`) validates the file, this layer hands it the catalog
(:data:`riskassess.diagnosis.effects.CATALOG`) so ``[[effects]]`` entries are checked too."""
from __future__ import annotations

from multibody.maths.plugins import Family
from riskassess.cases import diagnosis as schema
from riskassess.diagnosis.effects import CATALOG
from riskassess.diagnosis.impact_effects import IMPACT_CATALOG

#: Every effect a case's ``[[effects]]`` may name: the attitude and towing catalog and the impact one.
ALL_EFFECTS = Family("effect", {**CATALOG, **IMPACT_CATALOG})


def load_diagnosis_case(path) -> schema.DiagnosisCase:
    """Read and validate a diagnosis case file, its ``[[effects]]`` against the catalog;
    :class:`~riskassess.cases.impact.CaseError` names the file and the key.

    Parameters
    ----------
    path : str or Path
        The case file (TOML).

    Returns
    -------
    case : DiagnosisCase
    """
    return schema.load_diagnosis_case(path, ALL_EFFECTS)


def diagnosis_case_from_dict(raw: dict, case_dir=".") -> schema.DiagnosisCase:
    """:func:`riskassess.cases.diagnosis.diagnosis_case_from_dict` with the effect catalog.

    Parameters
    ----------
    raw : dict
        Parsed case content.
    case_dir : str or Path, optional
        Folder the case's file references (``towing``) are relative to.

    Returns
    -------
    case : DiagnosisCase
    """
    return schema.diagnosis_case_from_dict(raw, case_dir, ALL_EFFECTS)
