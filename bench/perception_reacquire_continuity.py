"""The attitude a lost track's re-acquisition can be told from: how far the propagation from the
last registered pre-contact poses lies from the truth, and from the pose the tracker accepted.

For each capture of ``bench_perception.py --capture`` (model-free stage, collision phase = phase 1):
the first frame registered after the first lost stretch of the collision phase (the re-acquisition),
the attitude propagated to it at the constant rates of the last two registered frames before the loss
(:func:`perception.pose_motion.propagate_pose`), and three angles: propagation to truth (the
propagation's error, which the continuity limit must exceed), accepted pose to truth (a flip is
~180 deg), propagation to the accepted pose; with the rates before the loss (registered) and the true
rates just before the loss and at the re-acquisition (from the truth's attitudes, 0.1 s apart).

    python bench/perception_reacquire_continuity.py /tmp/percep15_captures/none_obs20_seed*.pkl

``--rate-frames N [N ...]`` adds, for each N, the propagation from constant rates fitted to the last N
registered frames before the loss (:func:`perception.pose_motion.propagate_fitted_pose`; N = 2 is the
two-frame propagation): its angle to the truth at the re-acquisition and at every whole second of the gap,
and the fitted rate against the true one.
"""
import argparse
import pickle

import numpy as np
from scipy.spatial.transform import Rotation

from perception.pose_motion import propagate_fitted_pose, propagate_pose


def _angle_deg(a, b) -> float:
    return float(np.degrees(Rotation.from_matrix(a @ b.T).magnitude()))


def _true_rate(truth, i) -> float:
    """|omega| (rad/s) from the true body -> world attitudes of frames i-1 and i (0.1 s apart)."""
    return float(Rotation.from_matrix(truth[i] @ truth[i - 1].T).magnitude() / 0.1)


def reacquisition_figures(path) -> dict | None:
    """The figures of the module docstring for one capture; None when the collision phase never lost
    and re-acquired the track."""
    capture = pickle.load(open(path, "rb"))
    frames, alignments = capture["frames"], capture["alignments"]
    target_to_body = capture["target_to_body"][:3, :3]
    times, phase = np.array(frames["time"]), np.array(frames["phase"])
    ok = np.array([a.ok for a in alignments])
    truth = [np.asarray(r) @ target_to_body.T for r in frames["true_target_to_world"]]   # body -> world
    collision = np.flatnonzero(phase == 1)
    lost = [i for i in collision if not ok[i] and ok[i - 1]]
    if not lost:
        return None
    back = [i for i in collision if i > lost[0] and ok[i]]
    if not back:
        return None
    k, last = back[0], lost[0] - 1
    propagated = np.linalg.inv(propagate_pose(alignments[last].world_to_body, alignments[last - 1].world_to_body,
                                              (times[k] - times[last]) / (times[last] - times[last - 1])))[:3, :3]
    accepted = alignments[k].body_to_world[:3, :3]
    registered_rate = Rotation.from_matrix(alignments[last].body_to_world[:3, :3]
                                           @ alignments[last - 1].body_to_world[:3, :3].T).magnitude() / (times[last] - times[last - 1])
    return {"lost_s": times[lost[0]], "reacquired_s": times[k], "gap_s": times[k] - times[last],
            "rate_registered": registered_rate, "rate_true_before": _true_rate(truth, last),
            "rate_true_after": _true_rate(truth, k),
            "propagation_to_truth_deg": _angle_deg(propagated, truth[k]),
            "accepted_to_truth_deg": _angle_deg(accepted, truth[k]),
            "propagation_to_accepted_deg": _angle_deg(propagated, accepted)}


def fitted_propagation_errors(path, frame_counts) -> list[dict]:
    """Per N of ``frame_counts``: the fitted rate (rad/s) from the last N registered frames before the
    collision phase's first loss, and the propagation's angle to the truth (deg) at the re-acquisition
    and 1, 2, 3, 4, 5 s after the last registered frame."""
    capture = pickle.load(open(path, "rb"))
    frames, alignments = capture["frames"], capture["alignments"]
    target_to_body = capture["target_to_body"][:3, :3]
    times, phase = np.array(frames["time"]), np.array(frames["phase"])
    ok = np.array([a.ok for a in alignments])
    truth = [np.asarray(r) @ target_to_body.T for r in frames["true_target_to_world"]]
    collision = np.flatnonzero(phase == 1)
    lost = [i for i in collision if not ok[i] and ok[i - 1]]
    back = [i for i in collision if lost and i > lost[0] and ok[i]]
    if not back:
        return []
    last = lost[0] - 1
    rows = []
    for count in frame_counts:
        used = list(range(last - count + 1, last + 1))
        if not ok[used].all():
            continue
        poses = [alignments[i].world_to_body for i in used]
        at = {}
        for index in [back[0]] + [int(np.argmin(np.abs(times - times[last] - gap))) for gap in (1, 2, 3, 4, 5)]:
            propagated = np.linalg.inv(propagate_fitted_pose(times[used], poses, times[index]))[:3, :3]
            at[round(float(times[index] - times[last]), 1)] = _angle_deg(propagated, truth[index])
        # the fitted rate: between two propagated poses (the fit's line need not pass through the last pose)
        one, two = (np.linalg.inv(propagate_fitted_pose(times[used], poses, times[last] + step))[:3, :3] for step in (0.1, 0.2))
        rate = Rotation.from_matrix(two @ one.T).magnitude() / 0.1
        rows.append({"frames": count, "rate": rate, "reacquired_gap_s": round(float(times[back[0]] - times[last]), 1),
                     "to_truth_deg": at})
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--rate-frames", type=int, nargs="+", default=[])
    args = parser.parse_args(argv)
    for path in args.captures:
        figures = reacquisition_figures(path)
        if figures is None:
            print(path, "no lost and re-acquired track in the collision phase")
            continue
        print(path, "lost %.1f s, re-acquired %.1f s (gap %.1f s); rate registered before %.3f rad/s, true before "
              "%.3f, true at re-acquisition %.3f; propagation -> truth %.1f deg, accepted -> truth %.1f deg, "
              "propagation -> accepted %.1f deg" % tuple(figures.values()))
        for row in fitted_propagation_errors(path, args.rate_frames):
            print("    rate fitted to %d frames: %.3f rad/s; propagation -> truth (deg) at gap (s): %s (re-acquired at %.1f)"
                  % (row["frames"], row["rate"], ", ".join(f"{gap:g}: {angle:.1f}" for gap, angle in row["to_truth_deg"].items()),
                     row["reacquired_gap_s"]))


if __name__ == "__main__":
    main()
