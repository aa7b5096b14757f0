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
