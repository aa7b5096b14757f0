"""The shipped towing case with MRAC-2 and one of its notches switched on: shared by the notch tests."""
from pathlib import Path

from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase

CASE = Path(__file__).parents[3] / "cases" / "zenit2_towing.toml"


def mrac2_case_with(notch_key: str, **mrac) -> TowingCase:
    """The shipped case with MRAC-2 and ``mrac.<notch_key>`` on (other ``mrac`` keys changed as given)."""
    case = load_model(CASE, TowingCase)
    return case.model_copy(update=dict(thrust=case.thrust.model_copy(update=dict(kind="mrac2")),
                                       mrac=case.mrac.model_copy(update={notch_key: True} | mrac)))


def spinless_case_data(notch_key: str) -> dict:
    """The shipped case's data with ``mrac.<notch_key>`` on and no spin (and no switch, which needs the spin)."""
    data = load_model(CASE, TowingCase).model_dump()
    data["mrac"][notch_key] = True
    data["debris"]["spin_rate_deg_s"] = 0.0
    if data.get("full_net") is not None:
        data["full_net"]["switch_to_lower_order"] = False
    return data
