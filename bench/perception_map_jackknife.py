"""The scan-made map's bias measured within a run: maps fused from parts of the observation (its two halves in
time, its odd and its even frames), every fit frame (before and after the collision) registered by the stage's
own ICP (``DebrisTracker._icp``) to each map from the stage's pose, and the stage's momentum step redone with
each; the spread of C over the maps is the part of C's error that the choice of map makes, which no resampling
of one run's residuals sees (docs/perception.md, percep19, percep21). Replayed on captured model-free runs
(bench/perception_capture.py); the observation's scans made again (same case and seed, checked).

    python bench/perception_map_jackknife.py CASE /tmp/percep17/capchain/none_obs20_seed{0,1,2,3,4}.pkl [--pose-graph]

--pose-graph: the maps fused from the pose graph's poses (perception.pose_graph) instead of the online pass's.
Printed per capture and map: C's error, its stated 1-sigma, h0 and h1 from the truth; then the spread of C.
"""
from __future__ import annotations

import argparse
import copy
from pathlib import Path

import numpy as np

import perception_substitution as S
from perception_map_bias import angle_deg, observation_scans, trackers
from perception.net_tracking import node_velocities
from perception.pose_graph import optimized_poses
from perception.registration import _cloud
from perception.scan_to_map import _transform, surface_map, thinned_scan, track_scans


def part_maps(poses, thin, ok, voxel) -> dict:
    """Maps (points, normals; frame B, m) fused from parts of the registered frames."""
    frames = np.flatnonzero(ok)
    half = len(frames) // 2
    parts = {"all": frames, "first half": frames[:half], "second half": frames[half:],
             "even frames": frames[0::2], "odd frames": frames[1::2]}
    maps = {}
    for name, chosen in parts.items():
        cloud = surface_map(np.vstack([_transform(thin[i], poses[i]) for i in chosen]), voxel)
        maps[name] = (np.asarray(cloud.points), np.asarray(cloud.normals))
    return maps


def registered_to(tracker, capture, scans_by_frame) -> list:
    """The capture's alignments with frames ``scans_by_frame`` registered by ``tracker`` from the stage's pose."""
    alignments = [copy.copy(a) for a in capture["alignments"]]
    for k, scan in scans_by_frame.items():
        alignments[k].world_to_body = tracker._icp(_cloud(scan).voxel_down_sample(tracker.voxel),
                                                   capture["alignments"][k].world_to_body)
    return alignments


def report(case_path: Path, path: str, pose_graph: bool) -> None:
    capture = S.load(path)
    c_true = S.true_c(capture)
    seed = int(capture["answer"]["bench_seed"])
    scans, scene, case = observation_scans(case_path, seed, capture)
    reg = case.perception.registration
    thin = [thinned_scan(s, reg.voxel) for s in scans]
    track = track_scans(scans, reg.voxel, reg.max_correspondence)
    poses = (optimized_poses(track.world_to_body, thin, track.ok, reg.voxel, reg.max_correspondence).world_to_body
             if pose_graph else track.world_to_body)
    times = np.asarray(capture["frames"]["time"])
    updates = {round(u["time"], 6): u for u in capture["collision_updates"]}
    fit_scans = {k: scans[k] for k in capture["fits"][0]["indices"]}
    fit_scans.update({k: np.asarray(updates[round(float(times[k]), 6)]["points_world"])
                      for k in capture["fits"][-1]["indices"]})
    track_times, positions = np.asarray(capture["track"].times), np.asarray(capture["track"].positions)
    net = (positions, node_velocities(track_times, positions))
    print(f"\n== {path.split('/')[-1]} (seed {seed}; maps from the {'pose graph' if pose_graph else 'online'} poses)",
          flush=True)
    cs = {}
    for name, (points, normals) in part_maps(poses, thin, track.ok, reg.voxel).items():
        alignments = registered_to(trackers(capture, points, normals), capture, fit_scans)
        tracker = S.Tracker(alignments)
        c, sigma, mass, before, after, origin, *_ = S.replay(capture, net=net, before_tracker=tracker,
                                                            after_tracker=tracker)
        truth = S.true_terms(capture, before, after, origin)
        cs[name] = c / c_true - 1
        print(f"  map of {name} ({len(points)} points): C {100 * cs[name]:+.3f} % (1-sigma {100 * sigma / c:.3f} %), "
              f"h0 {angle_deg(before.spin_per_c, truth['h0']):.3f}, h1 {angle_deg(after.spin_per_c, truth['h1']):.3f} deg "
              f"from the truth", flush=True)
    halves = abs(cs["first half"] - cs["second half"]) / 2
    alternate = abs(cs["even frames"] - cs["odd frames"]) / 2
    print(f"  spread of C: halves |C1 - C2| / 2 = {100 * halves:.3f} %, odd / even {100 * alternate:.3f} %; "
          f"error of the whole map's C {100 * cs['all']:+.3f} %", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--pose-graph", action="store_true")
    args = parser.parse_args()
    for path in args.captures:
        report(args.case, path, args.pose_graph)


if __name__ == "__main__":
    main()
