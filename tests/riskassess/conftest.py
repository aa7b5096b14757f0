"""Run folders shared by the riskassess tests (simulated once per session)."""
import contextlib
import io
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
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["assess", str(case), "--out", str(out), "--json"]) == 0
    # what `assess --json` printed, kept beside the folder (not in it: the folder is the tool's)
    (tmp / "assess_stdout.json").write_text(printed.getvalue())
    return out


@pytest.fixture(scope="session")
def envisat_small_first_0p3s(tmp_path_factory):
    """The reduced Envisat case shortened to 0.3 s (first contact at ~0.15 s, the solar-array hinge
    fails at ~0.27 s): (case file, run folder written by ``riskassess assess``)."""
    tmp = tmp_path_factory.mktemp("short")
    case = tmp / "small_0p3.toml"
    case.write_text(shortened_case(0.3))
    out = tmp / "cli_run"
    assert main(["assess", str(case), "--out", str(out), "--json"]) == 0
    return case, out
