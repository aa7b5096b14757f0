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


def test_warmup_import_part_loads_every_kernel_with_a_stated_signature():
    # The CLI loads the towing and diagnosis packages only for their own commands, so the warm-up's
    # "import" part must load them itself, or their kernels (compiled at import: ~1 min cold) would
    # compile at a user's first tow or diagnosis. A fresh interpreter, so the suite's own imports
    # cannot hide a missing one. The list: the modules the CLI used to load whose kernels state their
    # signatures (so compile at import) or are built from the thrust-law and effect plug-ins.
    import subprocess
    import sys

    modules = ["multibody.towing_kernel", "multibody.control.thrust_laws", "riskassess.diagnosis.plants.towing_dynamics",
               "riskassess.diagnosis.plants.dynamics", "riskassess.diagnosis.effects"]
    code = ("import sys; from riskassess.warmup import compile_at_import; compile_at_import(); "
            f"print([m for m in {modules!r} if m not in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=PROJECT, check=True)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr
