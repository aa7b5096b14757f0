"""`riskassess assess`: the reduced reference case with weak locations, end to end."""
import json

import numpy as np
import pytest

from riskassess.products.results import read_manifest


def test_verdict_written_and_consistent_with_the_loads(assessed):
    assert "structures.json" in read_manifest(assessed)["files"]
    verdict = json.loads((assessed / "structures.json").read_text())
    by_name = {loc["name"]: loc for loc in verdict["locations"]}
    series = np.load(assessed / "timeseries.npz")
    time, moment = series["time"], series["joint_moment_joint"][:, 0]
    solar = by_name["solar_array_hinge_panel"]["criteria"]["moment"]
    # the judged demand is the h1/h3 resultant of the recorded hinge moment after 0.25 s
    judged = time >= 0.25
    assert solar["peak"] == pytest.approx(np.hypot(moment[judged, 0], moment[judged, 2]).max(), rel=1e-12)
    # a released location carries nothing afterwards, and its piece is reported
    released = by_name["solar_array_hinge_panel"]["released_at_s"]
    if released is not None:
        assert released >= 0.25 and solar["peak"] >= 200.0
        assert np.abs(moment[time > released + 2e-3]).max() == 0.0
        piece = verdict["released_pieces"][0]
        assert piece["bodies"] == ["solar_array"] and piece["mass_kg"] == 350.0
        assert piece["size_m"] == pytest.approx([14.3, 5.0, 0.05], rel=1e-9)
    else:
        assert solar["peak"] < 200.0
    # likelihood: uniform over 200-1000 N m
    assert solar["likelihood"] == pytest.approx(np.clip((solar["peak"] - 200.0) / 800.0, 0, 1), abs=1e-12)
    asar = by_name["asar_mount"]["criteria"]
    assert set(asar) == {"normal_stress", "shear_stress"} and not by_name["asar_mount"]["fails"]


def test_stress_series_written(assessed):
    stresses = np.load(assessed / "structures.npz")
    assert "asar_mount/von_mises_stress" in stresses.files
    assert len(stresses["time"]) == len(stresses["asar_mount/normal_stress"])


def test_single_run_json_carries_p_secondary_debris_without_a_number(assessed):
    """`assess --json` without --monte-carlo: the key scripts read is there, with no number that could read as a
    probability (one run is one draw), the run's answer, and its condition sentence (issue 23, "Done when")."""
    printed = json.loads((assessed.parent / "assess_stdout.json").read_text())
    verdict = json.loads((assessed / "structures.json").read_text())
    p = printed["p_secondary_debris"]
    # the Monte Carlo keys of riskassess.products.envelope.debris_probability, all without a value
    assert p["estimate"] is None and p["interval"] is None and p["confidence"] is None
    assert (p["runs"], p["debris_runs"], p["no_debris_runs"], p["unknown_runs"]) == (0, 0, 0, 0)
    assert p["needs"] == "--monte-carlo N"
    assert p["deterministic"] == verdict["debris_state"] == printed["structures"]["debris_state"]
    assert printed["condition"] == p["condition"]
    # the sentence states the answer and every location that decides it, word for word from structures.json
    deciding = {"debris": "fails", "indeterminate": "indeterminate"}.get(verdict["debris_state"])
    answer = {"debris": "secondary debris.", "no_debris": "no secondary debris.",
              "indeterminate": "indeterminate"}[verdict["debris_state"]]
    assert p["condition"].startswith("One deterministic run: " + answer)
    for loc in verdict["locations"]:
        if deciding is None or loc["state"] == deciding:
            assert loc["condition"] in p["condition"]
    assert p["condition"].endswith("it needs assess --monte-carlo N.")
