"""The plant of a diagnosis case, picked by the case's ``kind``: the rigid or hinged tumbling
debris (:mod:`riskassess.diagnosis.plants.plant`) or the towed debris
(:mod:`riskassess.diagnosis.plants.towing_plant`). It sits above both plants, so neither imports the other.
"""
from __future__ import annotations

from riskassess.diagnosis.plants.plant import Plant
from riskassess.diagnosis.plants.towing_plant import TowingPlant


def plant_of(case):
    """The plant of a diagnosis case: :class:`~riskassess.diagnosis.plants.plant.Plant`, or
    :class:`~riskassess.diagnosis.plants.towing_plant.TowingPlant` for the towing scenario.

    Parameters
    ----------
    case : DiagnosisCase
        Validated diagnosis case.

    Returns
    -------
    plant : Plant or TowingPlant
    """
    if case.kind == "towing":
        return TowingPlant.from_case(case)
    return Plant.from_case(case)
