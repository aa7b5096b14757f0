"""The install-time warm-up (riskassess/warmup.py) runs a valid, short copy of a shipped case."""
from pathlib import Path

from riskassess.cases.impact import load_case
from riskassess.warmup import WARMUP_CASE, WARMUP_END_TIME_S, warmup_case_text

PROJECT = Path(__file__).resolve().parents[2]


def test_warmup_case_is_the_shipped_case_shortened_and_valid(tmp_path):
    # The warm-up must reach the contact kernels: its case has to pass validation (which refuses an
    # end_time shorter than the net's flight to the target) and differ from the shipped file only in
    # end_time, so the kernels compile with the types every impact case uses.
    path = tmp_path / WARMUP_CASE.name
    path.write_text(warmup_case_text(PROJECT))
    shortened = load_case(path)
    shipped = load_case(PROJECT / WARMUP_CASE)
    assert shortened.simulation.end_time == WARMUP_END_TIME_S
    assert shortened.model_dump(exclude={"simulation"}) == shipped.model_dump(exclude={"simulation"})
    assert (shortened.simulation.model_dump(exclude={"end_time"})
            == shipped.simulation.model_dump(exclude={"end_time"}))
