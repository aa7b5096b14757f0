"""The observation registered a second time to its finished map (``perception.registration.map_second_pass``,
:func:`perception.scan_to_map.registered_again`), replayed offline on captured model-free runs
(bench/perception_capture.py): the observation's scans are made again (same case and seed; the first pass is
checked equal to the capture's poses and map), the second pass run, and the stage's fits and momentum step
redone with the new observation poses and information; the collision phase as captured (the map is unchanged,
so only the first collision frames' prediction from the last two observation poses would differ in a stage
run). Prints mass and principal moments with their stated 1-sigma, error / 1-sigma, as the stage states them.

    python bench/perception_second_pass.py CASE /tmp/percep17/capchain/none_obs20_seed{0,1,2,3,4}.pkl

CASE: the case the captures were made with (its seed is replaced by the capture's).
"""
from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import numpy as np

import perception_substitution as S
from perception_map_bias import angle_deg, observation_track
from perception.net_tracking import node_velocities
from perception.scan_to_map import alignments as map_alignments, thinned_scan, registered_again


def second_pass_alignments(case_path, capture):
    """The capture's alignments with the observation frames from the second pass, the median turn (deg) of
    the second pass and its CPU time a frame (s)."""
    seed = int(capture["answer"]["bench_seed"])
    scans, _, case, track = observation_track(case_path, seed, capture)
    reg = case.perception.registration
    tic = time.process_time()
    again = registered_again(track, [thinned_scan(s, reg.voxel) for s in scans], reg.max_correspondence)
    cpu = (time.process_time() - tic) / max(int(track.ok.sum()), 1)
    turns = [angle_deg_rotation(a[:3, :3] @ b[:3, :3].T) for a, b, ok in zip(again.world_to_body, track.world_to_body, track.ok)
             if ok]
    alignments = [copy.copy(a) for a in capture["alignments"]]
    times = np.asarray(capture["frames"]["time"])[:len(scans)]
    alignments[:len(scans)] = map_alignments(again, times)
    return alignments, float(np.median(turns)), cpu


def angle_deg_rotation(rotation) -> float:
    return float(np.degrees(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0))))


def stated(step, truth_mass, c_true) -> str:
    c, mass = step["c"], step["mass"]
    return (f"mass {100 * (mass.value / truth_mass - 1):+.3f} % (1-sigma {100 * mass.sigma / mass.value:.3f} %), "
            f"C {100 * (c.value / c_true - 1):+.3f} % (1-sigma {100 * c.sigma / c.value:.3f} %, error / 1-sigma "
            f"{abs(c.value / c_true - 1) / (c.sigma / c.value):.1f})")


def report(case_path, path) -> None:
    capture = S.load(path)
    c_true = S.true_c(capture)
    track_times, positions = np.asarray(capture["track"].times), np.asarray(capture["track"].positions)
    net = (positions, node_velocities(track_times, positions))
    rows = [("as captured (online pass)", capture["alignments"], "")]
    alignments, turn, cpu = second_pass_alignments(case_path, capture)
    rows.append(("second pass", alignments, f"; turn from the online pose median {turn:.3f} deg, {1e3 * cpu:.1f} ms CPU a frame"))
    print(f"\n== {path.split('/')[-1]}")
    for name, frames, note in rows:
        tracker = S.Tracker(frames)
        c, sigma, mass, before, after, origin, step, *_ = S.replay(capture, net=net, before_tracker=tracker)
        truth = S.true_terms(capture, before, after, origin)
        others_before, others = S.replay(capture, net=net, before_tracker=tracker)[7:9]
        estimated = S.estimated_terms(before, after, origin, others_before, others)
        covariances = S.stage_covariances(before, after, origin, step, others)
        shares = []
        for key in ("h0", "h1"):
            terms = dict(estimated, **{key: truth[key]})
            shares.append(100 * (c - S.c_from_terms(terms, others_before[1], step["mass"].value, covariances)[0]) / c_true)
        note = f"; C's share of h0 {shares[0]:+.3f} %, of h1 {shares[1]:+.3f} %" + note
        moments = np.linalg.eigvalsh(capture["truth"]["inertia_target"])[::-1]
        ratios = np.sort(before.fit.moments_)[::-1] * c
        errors = 100 * (ratios / moments - 1)
        print(f"  {name}: {stated(step, capture['truth']['mass'], c_true)}; principal moments "
              f"{', '.join(f'{e:+.3f}' for e in errors)} %; h0 {angle_deg(before.spin_per_c, truth['h0']):.3f} deg "
              f"from the truth{note}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case")
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args()
    for path in args.captures:
        report(Path(args.case), path)


if __name__ == "__main__":
    main()
