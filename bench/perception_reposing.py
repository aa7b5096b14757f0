"""The after-collision frames posed scan to scan (:func:`perception.scan_to_scan.scan_to_scan_poses`), replayed on
captured model-free runs (bench/perception_capture.py): CPU a re-posed frame (process time; optionally by part with
cProfile), the poses against a reference set of poses (e.g. the Open3D implementation's, saved by an earlier
replay), the partners' pose scatter, and the momentum step redone (``perception_substitution.replay``) with the
re-posed frames' attitude covariance propagated into C's 1-sigma, and without it. The observation's scans are made
again (same case and seed; checked equal to the capture's poses); the frames are started from the capture's poses
(a capture made with the switch on holds the poses already re-posed: the replay then measures the cost and the
covariance from a start within the pairwise ICP's settling of its end).

    python bench/perception_reposing.py CASE CAPTURE.pkl [...] [--reference DIR] [--profile]

CASE: the case the captures were made with (its seed is replaced by the capture's). ``--reference DIR``: files
``DIR/poses_seed<N>.npz`` (frames, poses world -> B) compared with.
"""
from __future__ import annotations

import argparse
import copy
import cProfile
import pstats
import time
from pathlib import Path

import numpy as np

import perception_substitution as S
from perception_map_bias import observation_scans
from perception.pose_graph import scan_clouds
from perception.scan_to_map import thinned_scan
from perception.scan_to_scan import scan_partners, scan_to_scan_poses


def after_frames(capture) -> tuple[dict, dict]:
    """The after fit's frames' debris returns (m, world) and their captured poses world -> B, by frame index."""
    times = np.asarray(capture["frames"]["time"])
    updates = {round(u["time"], 6): u for u in capture["collision_updates"]}
    indices = capture["fits"][-1]["indices"]
    scans = {int(k): np.asarray(updates[round(float(times[k]), 6)]["points_world"]) for k in indices}
    return scans, {k: capture["alignments"][k].world_to_body for k in scans}


def turn_deg(a, b) -> float:
    """Angle (deg) between the rotations of two poses (4, 4)."""
    cosine = (np.trace(a[:3, :3] @ b[:3, :3].T) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))


def c_figures(capture, alignments, attitude_covariance) -> str:
    tracker = S.Tracker(alignments)
    c, sigma, mass, *_ = S.replay(capture, before_tracker=tracker, after_tracker=tracker,
                                  attitude_covariance=attitude_covariance)
    error = c / S.true_c(capture) - 1
    return (f"C {100 * error:+.3f} % (1-sigma {100 * sigma / c:.3f} %, error / 1-sigma {abs(error) / (sigma / c):.1f}), "
            f"mass {100 * (mass / capture['truth']['mass'] - 1):+.3f} %")


def report(case_path: Path, path: str, reference: Path | None, profile: bool) -> None:
    capture = S.load(path)
    seed = int(capture["answer"]["bench_seed"])
    scans, _, case = observation_scans(case_path, seed, capture)
    reg = case.perception.registration
    observed = capture["alignments"][:len(scans)]
    tic = time.process_time()
    clouds = scan_clouds([thinned_scan(s, reg.voxel) if len(s) else np.zeros((0, 3)) for s in scans], reg.voxel)
    normals_cpu = time.process_time() - tic
    tic = time.process_time()
    partners = scan_partners(np.array([a.world_to_body for a in observed]), clouds, np.array([a.ok for a in observed]),
                             reg.max_correspondence)
    partners_cpu = time.process_time() - tic
    after_scans, starts = after_frames(capture)
    profiler = cProfile.Profile() if profile else None
    if profiler:
        profiler.enable()
    reposed = scan_to_scan_poses(after_scans, starts, partners, reg.voxel)
    if profiler:
        profiler.disable()
    frames = len(reposed.world_to_body)
    partner = reposed.partner_covariance()
    print(f"\n== {Path(path).name} (seed {seed}): {frames} frames re-posed, {1e3 * reposed.cpu_seconds / frames:.1f} ms "
          f"CPU a frame ({len(partners.indexes)} partner indexes built); once before: the observation's thinned scans "
          f"and normals {normals_cpu:.2f} s, partners in B {partners_cpu:.2f} s CPU; partners' scatter 1-sigma "
          f"{np.degrees(np.sqrt(np.trace(partner[:3, :3]) / 3)):.3f} deg, {1e3 * np.sqrt(np.trace(partner[3:, 3:]) / 3):.2f} mm "
          f"(rms over the axes); partners a frame {np.mean([len(p) for p in reposed.partners.values()]):.2f}", flush=True)
    if profiler:
        pstats.Stats(profiler).sort_stats("tottime").print_stats(12)
    if reference is not None and (reference / f"poses_seed{seed}.npz").exists():
        saved = np.load(reference / f"poses_seed{seed}.npz")
        turns = [turn_deg(reposed.world_to_body[int(k)], pose) for k, pose in zip(saved["frames"], saved["poses"])]
        print(f"  against the reference poses: turn median {np.median(turns):.4f}, max {np.max(turns):.4f} deg", flush=True)
    truth_turns = [turn_deg(reposed.world_to_body[k], np.linalg.inv(S.true_body_to_world(capture, k))) for k in starts]
    print(f"  attitude error against the truth: median {np.median(truth_turns):.3f}, rms "
          f"{np.sqrt(np.mean(np.square(truth_turns))):.3f} deg", flush=True)
    alignments = list(capture["alignments"])
    for k, pose in reposed.world_to_body.items():
        alignments[k] = copy.copy(alignments[k])
        alignments[k].world_to_body = pose
    print(f"  without the re-posed frames' covariance: {c_figures(capture, alignments, None)}", flush=True)
    print(f"  with it:                                  {c_figures(capture, alignments, reposed.attitude_covariance)}",
          flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--reference", type=Path, default=None, help="folder of poses_seed<N>.npz to compare with")
    parser.add_argument("--profile", action="store_true", help="print the re-posing's cProfile (12 rows by own time)")
    args = parser.parse_args()
    for path in args.captures:
        report(args.case, path, args.reference, args.profile)


if __name__ == "__main__":
    main()
