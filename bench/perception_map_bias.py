"""Is the model-free stage's common C bias the scan-made map's? Both free-flight fits redone on a captured
model-free run (bench/perception_capture.py) with every fit frame registered by the stage's own ICP
(``DebrisTracker._icp``) started from the TRUE pose, against (a) the stage's map and (b) the exact model (the
mesh sampled as the model-based stage samples it, put in the map's frame B). The observation's scans are not
in the capture: they are made again (same case, same seed, same random stream; checked equal to the capture's
poses). Printed per capture: C's error, the angle of the fits' spin momenta h0, h1 from the truth, and the
world-side part of the attitude errors across h (``perception_attitude_bias.split_errors``).

    python bench/perception_map_bias.py CASE /tmp/percep17/capchain/none_obs20_seed{0,1,2,3,4}.pkl

CASE: the case the captures were made with (its seed is replaced by the capture's).
"""
from __future__ import annotations

import argparse
import copy
import tomllib
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

import perception_substitution as S
from perception_attitude_bias import across_and_along, split_errors
from perception.net_tracking import node_velocities
from perception.registration import DebrisTracker, _cloud, known_shape_model
from riskassess.cases.impact import validate_case
from riskassess.stages.perceive import Frames, Scene, observe_tumble_model_free


def observation_scans(case_path: Path, seed: int, capture) -> list:
    """The observation's scans (m, world) of ``seed``, made again as the stage made them."""
    raw = tomllib.loads(case_path.read_text())
    raw["perception"]["seed"] = seed
    case = validate_case(raw, case_path)
    scene = Scene.from_case(case, case_path.parent, str(case_path))
    frames = Frames()
    _, tracker, _ = observe_tumble_model_free(scene, frames, np.random.default_rng(seed))
    same = max(np.abs(a.world_to_body - b.world_to_body).max() for a, b in zip(tracker.alignments, capture["alignments"]))
    if same > 1e-9:
        raise SystemExit(f"the observation made again differs from the capture's (pose {same:.2e}): another case?")
    return frames.scans, scene, case


def observation_track(case_path: Path, seed: int, capture):
    """The observation's scans, scene, case and online scan-to-map track of ``seed``, made again as the stage made
    them; refused if the map made again differs from the capture's."""
    from perception.scan_to_map import track_scans

    scans, scene, case = observation_scans(case_path, seed, capture)
    reg = case.perception.registration
    track = track_scans(scans, reg.voxel, reg.max_correspondence)
    if not np.array_equal(track.map_points, capture["collision_tracker"]["map_points_body"]):
        raise SystemExit("the map made again differs from the capture's")
    return scans, scene, case, track


def registered_from_truth(tracker, capture, scans_by_frame) -> list:
    """The capture's alignments with frames ``scans_by_frame`` (index -> scan, m, world) registered by
    ``tracker``'s ICP from the true pose."""
    alignments = [copy.copy(a) for a in capture["alignments"]]
    for k, scan in scans_by_frame.items():
        start = np.linalg.inv(S.true_body_to_world(capture, k))
        alignments[k].world_to_body = tracker._icp(_cloud(scan).voxel_down_sample(tracker.voxel), start)
    return alignments


def trackers(capture, model_points_body, model_normals_body) -> DebrisTracker:
    settings = dict(capture["collision_tracker"]["settings"], search_cpu_per_frame=np.inf, search_cpu_per_run=np.inf)
    return DebrisTracker(settings.pop("voxel"), settings.pop("max_correspondence"), settings.pop("model_frames"),
                         model_points_body, model_normals_body, **settings)


def across_h_deg(capture, alignments, indices, spin) -> float:
    """The world-side constant of the attitude errors of ``indices``, across ``spin`` (deg)."""
    true_rot = np.array([S.true_body_to_world(capture, k)[:3, :3] for k in indices])
    errors = Rotation.from_matrix(np.array([alignments[k].body_to_world[:3, :3] for k in indices])
                                  @ np.transpose(true_rot, (0, 2, 1))).as_rotvec()
    times = np.asarray(capture["frames"]["time"])[indices]
    return float(np.degrees(across_and_along(split_errors(errors, true_rot, times)["q_world"], spin)[0]))


def angle_deg(a, b) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))))


def report(case_path: Path, path: str) -> None:
    capture = S.load(path)
    c_true = S.true_c(capture)
    seed = int(capture["answer"]["bench_seed"])
    scans, scene, case = observation_scans(case_path, seed, capture)
    before_idx, after_idx = capture["fits"][0]["indices"], capture["fits"][-1]["indices"]
    updates = {round(u["time"], 6): u for u in capture["collision_updates"]}
    times = np.asarray(capture["frames"]["time"])
    fit_scans = {k: scans[k] for k in before_idx}
    fit_scans.update({k: np.asarray(updates[round(float(times[k]), 6)]["points_world"]) for k in after_idx})
    track_times, positions = np.asarray(capture["track"].times), np.asarray(capture["track"].positions)
    net = (positions, node_velocities(track_times, positions))
    target_to_body = capture["target_to_body"]
    exact_points, exact_normals = known_shape_model(scene.model_mesh_target, case.perception.registration.voxel,
                                                    case.perception.seed)
    models = {"map": (capture["collision_tracker"]["map_points_body"], capture["collision_tracker"]["map_normals_body"]),
              "exact model": (exact_points @ target_to_body[:3, :3].T + target_to_body[:3, 3],
                              exact_normals @ target_to_body[:3, :3].T)}
    rows = [("stage (map, its own poses)", capture["alignments"])]
    for name, (points, normals) in models.items():
        rows.append((f"{name}, ICP from the truth", registered_from_truth(trackers(capture, points, normals), capture,
                                                                         fit_scans)))
    print(f"\n== {path.split('/')[-1]} (seed {seed})")
    for name, alignments in rows:
        tracker = S.Tracker(alignments)
        c, sigma, mass, before, after, origin, *_ = S.replay(capture, net=net, before_tracker=tracker, after_tracker=tracker)
        c_before, *_ = S.replay(capture, net=net, before_tracker=tracker)
        c_after, *_ = S.replay(capture, net=net, after_tracker=tracker)
        truth = S.true_terms(capture, before, after, origin)
        print(f"  {name}: C {100 * (c / c_true - 1):+.3f} % (before fit only {100 * (c_before / c_true - 1):+.3f}, "
              f"after fit only {100 * (c_after / c_true - 1):+.3f}); h0 {angle_deg(before.spin_per_c, truth['h0']):.3f} deg, "
              f"h1 {angle_deg(after.spin_per_c, truth['h1']):.3f} deg from the truth; world-side error across h "
              f"before {across_h_deg(capture, alignments, before_idx, before.spin_per_c):.4f}, after "
              f"{across_h_deg(capture, alignments, after_idx, after.spin_per_c):.4f} deg", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args()
    for path in args.captures:
        report(args.case, path)


if __name__ == "__main__":
    main()
