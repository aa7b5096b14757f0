"""The attitude a lost track's re-acquisition can be told from: how far the propagation from the
last registered pre-contact poses lies from the truth, and from the pose the tracker accepted.

For each capture of ``bench_perception.py --capture`` (model-free stage, collision phase = phase 1):
the first frame registered after the first lost stretch of the collision phase (the re-acquisition),
the attitude propagated to it at the constant rates of the last two registered frames before the loss
(:func:`perception.registration.propagate_pose`), and three angles: propagation to truth (the
propagation's error, which the continuity limit must exceed), accepted pose to truth (a flip is
~180 deg), propagation to the accepted pose; with the rates before the loss (registered) and the true
rates just before the loss and at the re-acquisition (from the truth's attitudes, 0.1 s apart).

    python bench/perception_reacquire_continuity.py /tmp/percep15_captures/none_obs20_seed*.pkl
"""
import argparse
import pickle

import numpy as np
from scipy.spatial.transform import Rotation

from perception.registration import propagate_pose


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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args(argv)
    for path in args.captures:
        figures = reacquisition_figures(path)
        if figures is None:
            print(path, "no lost and re-acquired track in the collision phase")
            continue
        print(path, "lost %.1f s, re-acquired %.1f s (gap %.1f s); rate registered before %.3f rad/s, true before "
              "%.3f, true at re-acquisition %.3f; propagation -> truth %.1f deg, accepted -> truth %.1f deg, "
              "propagation -> accepted %.1f deg" % tuple(figures.values()))


if __name__ == "__main__":
    main()
