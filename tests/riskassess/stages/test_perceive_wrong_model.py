"""A wrong model (issue 26, item 2): the scanned debris differs from the model the tracker is given
([perception.truth_damage]); the stage finds it from its own residuals and tracks without the model.

The debris is the shipped damaged case's (cases/featured_debris_perception_damaged.toml): bus, 2 m
array and antenna mast as drawn. Short observations (1.5-3 s at 10 Hz) keep the tests fast; the
model is checked after 10 frames, as the stage does after EARLY_CHECK_FRAMES.
"""
import json
import tomllib
from pathlib import Path

import numpy as np
import open3d as o3d
import pytest

from perception.free_flight import fit_free_motion
from perception.model_mismatch import MAX_UNEXPLAINED, MAX_UNSEEN
from perception.registration import DebrisTracker, known_shape_model
from riskassess.cases.impact import validate_case
from riskassess.cli import main
from riskassess.stages import perceive

CASE = Path(__file__).parents[3] / "cases" / "featured_debris_perception_damaged.toml"


def _raw(variant: str, observation: float) -> dict:
    """The shipped case's content: 'intact' (no damage), 'bent' (array 15 deg only), 'antenna'
    (mast lost only), 'com' (CoM 5 cm off only) or 'damaged' (all three, as shipped)."""
    raw = tomllib.loads(CASE.read_text())
    raw["perception"]["observation_time"] = observation
    damage = raw["perception"]["truth_damage"]
    if variant == "intact":
        del raw["perception"]["truth_damage"]
    elif variant != "damaged":
        keep = {"bent": "bends", "antenna": "missing_shapes", "com": "center_of_mass_shift"}[variant]
        for key, empty in (("bends", []), ("missing_shapes", []), ("center_of_mass_shift", [0.0, 0.0, 0.0])):
            if key != keep:
                damage[key] = empty
    return raw


def _observed(variant: str, observation: float):
    """The observation tracked with the model, its model check after 10 frames, and the scene."""
    case = validate_case(_raw(variant, observation), CASE)
    scene = perceive.Scene.from_case(case, CASE.parent)
    reg = case.perception.registration
    tracker = DebrisTracker(reg.voxel, reg.max_correspondence, reg.model_frames,
                            *known_shape_model(scene.model_mesh_target, reg.voxel, case.perception.seed),
                            seed=case.perception.seed)
    frames = perceive.Frames()
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        _, check = perceive.observe_tumble(scene, tracker, frames, [np.eye(3)], np.random.default_rng(0),
                                           early_check=10)
    return scene, tracker, frames, check


def test_the_intact_debris_matches_its_model():
    # With the right model every return lies within its 2 cm range noise of the surface: measured
    # 0.0 % of returns beyond the 10 cm gate and 0.0 % of the model's predicted returns unseen (3 s,
    # 31 frames, 29-31 registered; 20 s runs: docs/perception.md). Limits of the check: 3 %.
    scene, tracker, frames, check = _observed("intact", 3.0)
    assert not check.mismatch, check.reasons
    assert check.registered >= 0.9 * check.frames
    assert check.unexplained_median < 0.2 * MAX_UNEXPLAINED and check.unseen_median < 0.2 * MAX_UNSEEN
    before = fit_free_motion(tracker, perceive._good(tracker, np.array(frames.phase) == 0), frames.time)
    offset = perceive._model_center_of_mass_offset(scene, before)
    assert "model_mass_mismatch" not in offset
    assert np.linalg.norm(offset["model_center_of_mass_offset_m"]) < 0.005   # measured 0.5 mm


@pytest.mark.parametrize("variant", ["bent", "antenna"])
def test_a_damaged_debris_does_not_match_its_model(variant):
    # A 15 deg bend moves the array's tip 0.52 m off the drawn plane: the tracker's own check refuses
    # every frame (measured 0 of 30 registered, 5 s). The lost 0.7 m mast: registered 9 of 30, and
    # 3.6 % of the surface the model shows is not in the scans.
    _, _, _, check = _observed(variant, 1.5)
    assert check.mismatch
    assert check.frames == 10            # decided after the early check's 10 frames
    assert any("registers only" in reason or "not in the scans" in reason or "off its surface" in reason
               for reason in check.reasons)


def test_a_shifted_center_of_mass_is_stated_not_tracked_around():
    # The shapes match, so the mesh tracker is kept; the CoM is measured from the motion (the body
    # point on a straight line) and lands 50 mm (~100 sigma at 5 s) from the drawings' CoM.
    scene, tracker, frames, check = _observed("com", 3.0)
    assert not check.mismatch
    before = fit_free_motion(tracker, perceive._good(tracker, np.array(frames.phase) == 0), frames.time)
    offset = perceive._model_center_of_mass_offset(scene, before)
    assert "model_mass_mismatch" in offset
    # the truth: the case's 5 cm shift along z (target frame); 3 s of tumble fix the CoM to ~1 mm
    assert np.allclose(offset["model_center_of_mass_offset_m"], [0.0, 0.0, 0.05], atol=0.005)


# the whole stage on the shipped damaged case (~20 s): slow suite; the detection itself is tested above
@pytest.mark.slow
def test_perceive_says_the_model_is_wrong_and_tracks_without_it(tmp_path, capsys, monkeypatch):
    # The shipped damaged case, 1.5 s of observation: the model is found wrong after 10 frames, the
    # scans are tracked again without it; 1.5 s of model-free track does not fix the inertia ratios,
    # so the answer is "not observable" before the collision (exit 3), with the mismatch stated.
    monkeypatch.setattr(perceive, "EARLY_CHECK_FRAMES", 10)
    text = CASE.read_text().replace("observation_time = 20.0", "observation_time = 1.5", 1)
    assert "observation_time = 1.5" in text
    case = tmp_path / "case.toml"
    case.write_text(text)
    assert main(["perceive", str(case), "--out", str(tmp_path / "run"), "--json"]) == 3
    answer = json.loads(capsys.readouterr().out)
    assert answer["perception_model"] == "known" and answer["model_check"]["mismatch"]
    assert "does not match the scanned debris" in answer["model_mismatch"]
    assert answer["tracked_with"] == "scan-to-map" and answer["body_frame"] == "first_scan"
    assert answer["tracking"]["observation"]["frames"] == 16
    assert answer["not_observable"].startswith("before the collision")
