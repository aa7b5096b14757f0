"""The observation's poses and map optimized jointly (:func:`perception.pose_graph.jointly_optimized`), replayed
offline on captured model-free runs (bench/perception_capture.py). The observation's scans are made again (same
case and seed; the online pass checked equal to the capture's poses), the pose graph run on them and the map fused
again; the before fit takes the optimized observation poses; every after-fit frame is registered by the stage's own
ICP (``DebrisTracker._icp``) to the pose-graph map, started from the truth and from the stage's own pose. Reference
rows (percep21's, ``perception_map_bias.py``): every fit frame, before and after, registered from the truth to the
stage's map and to the exact model. The
last rows: every after-fit frame posed by scan-to-scan alignments to the 4 observation frames that share most of
its coarse cells (at the online or the graph's poses), started from the stage's pose, the partners' poses averaged
with their information (``perception.scan_to_scan.scan_to_scan_poses``). The stage's momentum step is redone for each (``perception_substitution.replay``). Printed per capture: C's error, its
stated 1-sigma, error / 1-sigma, mass, h0 and h1 from the truth, the pose graph's CPU and edges.

    python bench/perception_pose_graph.py CASE /tmp/percep17/capchain/none_obs20_seed{0,1,2,3,4}.pkl

CASE: the case the captures were made with (its seed is replaced by the capture's).
"""
from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import numpy as np

import perception_substitution as S
from perception_map_bias import angle_deg, observation_track, registered_from_truth, trackers
from perception.net_tracking import node_velocities
from perception.pose_graph import jointly_optimized, scan_clouds
from perception.scan_to_scan import scan_partners, scan_to_scan_poses
from perception.registration import _cloud, known_shape_model
from perception.scan_to_map import alignments as map_alignments, thinned_scan


def pose_graph_track(case_path, capture):
    """The online pass made again, the pose graph's track and result, the scene and the case."""
    seed = int(capture["answer"]["bench_seed"])
    scans, scene, case, track = observation_track(case_path, seed, capture)
    reg = case.perception.registration
    fused, result = jointly_optimized(track, [thinned_scan(s, reg.voxel) for s in scans], reg.voxel,
                                      reg.max_correspondence)
    return track, fused, result, scene, case, scans


def registered_from(tracker, capture, scans_by_frame, starts) -> list:
    """The capture's alignments with frames ``scans_by_frame`` registered by ``tracker``'s ICP from ``starts``
    (index -> world -> B)."""
    alignments = [copy.copy(a) for a in capture["alignments"]]
    for k, scan in scans_by_frame.items():
        alignments[k].world_to_body = tracker._icp(_cloud(scan).voxel_down_sample(tracker.voxel), starts[k])
    return alignments


def c_row(capture, net, alignments, c_true) -> str:
    tracker = S.Tracker(alignments)
    c, sigma, mass, before, after, origin, step, *_ = S.replay(capture, net=net, before_tracker=tracker,
                                                              after_tracker=tracker)
    truth = S.true_terms(capture, before, after, origin)
    error = c / c_true - 1
    return (f"C {100 * error:+.3f} % (1-sigma {100 * sigma / c:.3f} %, error / 1-sigma {abs(error) / (sigma / c):.1f}), "
            f"mass {100 * (mass / capture['truth']['mass'] - 1):+.3f} %; h0 {angle_deg(before.spin_per_c, truth['h0']):.3f}, "
            f"h1 {angle_deg(after.spin_per_c, truth['h1']):.3f} deg from the truth")


def report(case_path: Path, path: str) -> None:
    capture = S.load(path)
    c_true = S.true_c(capture)
    track, fused, result, scene, case, scans = pose_graph_track(case_path, capture)
    scans_total = len(track.ok)
    times = np.asarray(capture["frames"]["time"])
    observed = [copy.copy(a) for a in capture["alignments"]]
    observed[:scans_total] = map_alignments(fused, times[:scans_total])
    after_idx = capture["fits"][-1]["indices"]
    updates = {round(u["time"], 6): u for u in capture["collision_updates"]}
    after_scans = {k: np.asarray(updates[round(float(times[k]), 6)]["points_world"]) for k in after_idx}
    before_idx = capture["fits"][0]["indices"]
    fit_scans = {**{k: scans[k] for k in before_idx}, **after_scans}
    truth_starts = {k: np.linalg.inv(S.true_body_to_world(capture, k)) for k in fit_scans}
    stage_starts = {k: capture["alignments"][k].world_to_body for k in after_idx}
    track_times, positions = np.asarray(capture["track"].times), np.asarray(capture["track"].positions)
    net = (positions, node_velocities(track_times, positions))
    target_to_body = capture["target_to_body"]
    exact_points, exact_normals = known_shape_model(scene.model_mesh_target, case.perception.registration.voxel,
                                                    case.perception.seed)
    exact = trackers(capture, exact_points @ target_to_body[:3, :3].T + target_to_body[:3, 3],
                     exact_normals @ target_to_body[:3, :3].T)
    stage_map = trackers(capture, capture["collision_tracker"]["map_points_body"],
                         capture["collision_tracker"]["map_normals_body"])
    graph_map = trackers(capture, fused.map_points, fused.map_normals)
    turns = [angle_deg_rotation(a[:3, :3] @ b[:3, :3].T) for a, b, ok in zip(fused.world_to_body, track.world_to_body,
                                                                            track.ok) if ok]
    print(f"\n== {path.split('/')[-1]} (seed {capture['answer']['bench_seed']}): pose graph {len(result.edges)} edges "
          f"({result.loop_closures} loop closures) over {int(track.ok.sum())} frames, {result.cpu_seconds:.1f} s CPU "
          f"({1e3 * result.cpu_seconds / max(int(track.ok.sum()), 1):.1f} ms a frame); turn from the online pose median "
          f"{np.median(turns):.3f} deg; map {len(track.map_points)} -> {len(fused.map_points)} points", flush=True)
    tic = time.process_time()
    rows = [("stage as captured", capture["alignments"]),
            ("stage map, fit frames from the truth", registered_from_truth(stage_map, capture, fit_scans)),
            ("exact model, fit frames from the truth", registered_from(exact, capture, fit_scans, truth_starts))]
    observed_from_truth = registered_from(graph_map, {**capture, "alignments": observed}, after_scans, truth_starts)
    observed_from_stage = registered_from(graph_map, {**capture, "alignments": observed}, after_scans, stage_starts)
    rows += [("pose graph: its observation poses, after frames to its map from the truth", observed_from_truth),
             ("pose graph: its observation poses, after frames to its map from the stage's poses", observed_from_stage)]
    reg = case.perception.registration
    clouds = scan_clouds([thinned_scan(scan, reg.voxel) for scan in scans], reg.voxel)
    for label, frames_poses, base in (("online", track.world_to_body, capture["alignments"]),
                                      ("pose graph", fused.world_to_body, observed)):
        partners = scan_partners(frames_poses, clouds, track.ok, reg.max_correspondence)
        poses = scan_to_scan_poses(after_scans, stage_starts, partners, reg.voxel).world_to_body
        alignments = [copy.copy(a) for a in base]
        for k, pose in poses.items():
            alignments[k].world_to_body = pose
        rows.append((f"{label} observation poses, after frames scan to scan to the 4 observation frames of most "
                     f"overlap, from the stage's poses", alignments))
    for name, alignments in rows:
        print(f"  {name}: {c_row(capture, net, alignments, c_true)}", flush=True)
    print(f"  (after-frame ICPs {time.process_time() - tic:.1f} s CPU)", flush=True)


def angle_deg_rotation(rotation) -> float:
    return float(np.degrees(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args()
    for path in args.captures:
        report(args.case, path)


if __name__ == "__main__":
    main()
