"""Run folders shared by the riskassess tests (simulated once per session)."""
from pathlib import Path

import pytest

from riskassess.cli import main

CASES = Path(__file__).resolve().parents[2] / "cases"


def shortened_case(end_time: float) -> str:
    """cases/envisat_small.toml with a shorter simulated time (s)."""
    text = (CASES / "envisat_small.toml").read_text()
    assert "end_time = 7.5" in text
    return text.replace("end_time = 7.5", f"end_time = {end_time}", 1)


@pytest.fixture(scope="session")
def assessed(tmp_path_factory):
    """The reduced Envisat case (15 x 15 net, the reference weak locations), 2 s: a complete run folder."""
    tmp = tmp_path_factory.mktemp("assess")
    case = tmp / "small_assess.toml"
    case.write_text(shortened_case(2.0))
    out = tmp / "run"
    assert main(["assess", str(case), "--out", str(out), "--json"]) == 0
    return out
