"""The CLI's tables at 80 and 120 columns: every cell's full text printed, never cut."""
import io
import json
import re

import pytest
from rich.console import Console

from riskassess.cli import print_perception, print_summary, print_verdict
from riskassess.products.tables import VERDICT_COLUMNS, perception_rows, summary_rows, verdict_rows


def _render(width: int, show, *args) -> str:
    buffer = io.StringIO()
    show(*args, console=Console(width=width, file=buffer, emoji=False, force_terminal=False))
    return buffer.getvalue()


def _flat(text: str) -> str:
    """All whitespace (line breaks of wrapped lines, indents) as one space."""
    return re.sub(r"\s+", " ", text)


def _assert_complete(output: str, cells, width: int) -> None:
    assert "…" not in output and "..." not in output
    assert max(len(line) for line in output.splitlines()) <= width
    flat = _flat(output)
    for cell in cells:
        if str(cell).strip():
            assert _flat(str(cell)) in flat, f"cell {cell!r} not printed whole at {width} columns"


@pytest.fixture(scope="module")
def short_run(envisat_small_first_0p3s):
    _, run = envisat_small_first_0p3s
    return json.loads((run / "summary.json").read_text()), json.loads((run / "structures.json").read_text()), run


#: A perception answer as perceive_case returns it (values of the tang2023 case, rounded).
PERCEPTION = {
    "case": "tang2023_debris_perception", "mass_kg": 1432.7, "mass_std_kg": 12.5, "mass_error_signed_percent": -0.512,
    "principal_moments_kg_m2": [1200.0, 2300.5, 2900.25], "principal_moments_std_kg_m2": [10.0, 20.0, 30.0],
    "principal_moments_error_percent": [1.2, -0.8, 0.3], "inertia_ratios": [0.41, 0.79],
    "inertia_ratios_std": [0.01, 0.02], "inertia_ratio_error_percent": [0.9, -1.1],
    "center_of_mass_target_m": [0.012, -0.034, 1.25], "center_of_mass_std_m": [0.001, 0.002, 0.003],
    "center_of_mass_error_m": 0.0042, "normalized_kinetic_energy_D_rad2_s2": 0.00123,
    "normalized_kinetic_energy_error_percent": 0.4, "normalized_angular_momentum_F_rad2_s2": 0.00151,
    "normalized_angular_momentum_error_percent": -0.2, "angular_momentum_direction_error_deg": 0.812,
    "registration_ms_per_frame": 41.7, "first_frame_search_s": 2.31, "observation_time_s": 30.0,
    "not_observable": [],
}


@pytest.mark.parametrize("width", [80, 120])
def test_summary_table_complete(short_run, width):
    summary, _, run = short_run
    output = _render(width, print_summary, summary, run)
    _assert_complete(output, [c for row in summary_rows(summary) for c in row], width)


@pytest.mark.parametrize("width", [80, 120])
def test_verdict_table_complete(short_run, width):
    _, verdict, _ = short_run
    output = _render(width, print_verdict, verdict)
    rows = verdict_rows(verdict)
    cells = [r[c] for r in rows for c in VERDICT_COLUMNS if c != "fails?"] + ["FAIL", "secondary debris: YES"]
    _assert_complete(output, cells, width)
    assert any(p in _flat(output) for p in ("released piece: solar_array", "solar_array, 350 kg"))


@pytest.mark.parametrize("width", [80, 120])
def test_perception_table_complete(width, tmp_path):
    output = _render(width, print_perception, PERCEPTION, tmp_path)
    _assert_complete(output, [c for row in perception_rows(PERCEPTION) for c in row], width)


def test_wide_terminal_keeps_the_table(short_run):
    summary, _, run = short_run
    output = _render(200, print_summary, summary, run)
    assert "┃ quantity" in output   # the summary fits 200 columns: a table, not stacked rows
