"""Why a lost track's true pose was or was not re-acquired: every candidate pose of the collision phase's
searches and chains, against the truth.

Reads a capture of ``bench_perception.py --capture`` made with the candidate log on (bench/perception_capture.py
keeps ``candidate_log`` and the collision frames' registration inputs). Per searched frame and search
(``stage``): the candidates' angle to the true attitude, their check figures (tight fitness, free-space
violation, unseen share), the checks they fail, and their turn from the attitude propagated at the last
registered rates; the chains that survive each frame (lengths, view turns). With ``--replay`` the collision
phase's registration is run again from the capture's inputs (the tracker as the collision phase started),
optionally with another continuity limit (``--continuity-deg``; 0: off), and its log printed instead. The
replay feeds the recorded scans: the stage's cropping and pointing followed the recorded run's poses, so a
replay with other settings is an approximation of a stage run, not one.

    python bench/perception_reacquire_candidates.py /tmp/percep17/capcont3/none_obs20_seed3.pkl
    python bench/perception_reacquire_candidates.py CAPTURE --replay --continuity-deg 0 --until 6
"""
from __future__ import annotations

import argparse
import pickle

import numpy as np
from scipy.spatial.transform import Rotation

from perception.registration import DebrisTracker


def _angle_deg(a, b) -> float:
    return float(np.degrees(Rotation.from_matrix(a @ b.T).magnitude()))


def true_body_to_world(capture, time_s) -> np.ndarray:
    """The true body -> world rotation (frame B of the track) at the frame nearest ``time_s`` (s)."""
    frames = capture["frames"]
    index = int(np.argmin(np.abs(np.array(frames["time"]) - time_s)))
    return np.asarray(frames["true_target_to_world"][index]) @ capture["target_to_body"][:3, :3].T


def replayed_log(capture, continuity_turn="recorded", until=np.inf, chain_missed_frames=0, grow_map=False):
    """The collision phase's registration run again from ``capture``'s inputs up to ``until`` (s), with
    the candidate log on; ``continuity_turn`` (rad or None) replaces the recorded tracker's, and a chain may
    miss ``chain_missed_frames`` frames and, with ``grow_map``, confirmed frames grow the map. The search
    budgets are lifted (the recorded run's CPU cuts depend on the load). Returns the log, the tracker's alignments and its map growth (``DebrisTracker.map_growth``)."""
    start = capture["collision_tracker"]
    settings = dict(start["settings"], search_cpu_per_frame=np.inf, search_cpu_per_run=np.inf,
                    chain_missed_frames=chain_missed_frames, grow_map=grow_map)
    if continuity_turn != "recorded":
        settings["continuity_turn"] = continuity_turn
    tracker = DebrisTracker(settings.pop("voxel"), settings.pop("max_correspondence"), settings.pop("model_frames"),
                            start["map_points_body"], start["map_normals_body"], **settings)
    tracker.alignments = list(start["alignments"])
    tracker.candidate_log = []
    for update in capture["collision_updates"]:
        if update["time"] > until:
            break
        tracker.field_of_view, tracker.ray_spacing = update["field_of_view"], update["ray_spacing"]
        tracker.update(update["time"], update["points_world"], update["sensor_world"],
                       all_returns_world=update.get("all_returns_world"), sensor_to_world=update.get("sensor_to_world"))
    return tracker.candidate_log, tracker.alignments, tracker.map_growth


def describe(capture, log, until=np.inf) -> list[str]:
    """One line per logged candidate or chain record up to ``until`` (s), with its angle to the truth."""
    lines = []
    for record in log:
        if record["time"] > until:
            break
        if record["stage"] == "chains":
            lines.append("%5.1f s  chains surviving: lengths %s, view turns %s deg" % (
                record["time"], record["lengths"], [round(float(np.degrees(v)), 1) for v in record["view_turns"]]))
            continue
        body_to_world = np.linalg.inv(record["world_to_body"])[:3, :3]
        lines.append("%5.1f s  %-32s to truth %6.1f deg, from propagation %6.1f deg; fitness %.3f, free space %.3f, "
                     "unseen %.3f; %s" % (
                         record["time"], record["stage"], _angle_deg(body_to_world, true_body_to_world(capture, record["time"])),
                         np.degrees(record["turn_from_propagation"]), record["tight_fitness"],
                         record["free_space_violation"], record["unseen"],
                         "passes" if record["ok"] else "fails " + ", ".join(record["failed"])))
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("capture")
    parser.add_argument("--replay", action="store_true", help="run the collision phase's registration again")
    parser.add_argument("--continuity-deg", type=float, default=None,
                        help="with --replay: continuity limit (deg; 0: off); default the recorded run's")
    parser.add_argument("--chain-missed-frames", type=int, default=0, help="with --replay: frames a chain may miss")
    parser.add_argument("--grow-map", action="store_true",
                        help="with --replay: confirmed frames after a re-acquisition grow the map")
    parser.add_argument("--until", type=float, default=np.inf, help="last time shown or replayed (s)")
    args = parser.parse_args(argv)
    capture = pickle.load(open(args.capture, "rb"))
    if args.replay:
        turn = "recorded" if args.continuity_deg is None else (np.radians(args.continuity_deg) or None)
        log, alignments, map_growth = replayed_log(capture, turn, args.until, args.chain_missed_frames, args.grow_map)
        registered = [a for a in alignments[len(capture["collision_tracker"]["alignments"]):] if a.ok]
        print("registered collision frames (s), angle to the truth (deg):", " ".join(
            "%.1f (%.1f)" % (a.time, _angle_deg(a.body_to_world[:3, :3], true_body_to_world(capture, a.time)))
            for a in registered))
        for growth in map_growth:
            print("map grown at %.1f s: %d points added, %d in the map" % (
                growth["time"], growth["points_added"], growth["map_points"]))
    else:
        log = capture["candidate_log"]
    print("\n".join(describe(capture, log, args.until)))


if __name__ == "__main__":
    main()
