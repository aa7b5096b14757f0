"""Where the net's angular momentum error comes from: the nodes the LiDAR saw, or those it did not. On captured
perception runs (bench/perception_capture.py), per free-flight frame after the collision: the net's angular
momentum about the stage's origin from the estimated nodes (positions fitted, velocities differentiated, as the
stage) against the truth, split into the nodes with a return on an adjoining thread in that frame ("seen",
nearest_segments within NetPrior.gate of the frame's returns, as fit_net_nodes counts them) and the others; and
the unseen nodes' own momentum about the net's centre of mass motion (their momentum less what they would carry
moving with the net's mean velocity), the size a covariance term for them could take without the truth.

    python bench/perception_net_unseen.py /tmp/percep17/capchain/none_obs20_seed*.pkl

All in N m s, world components, means over the free-flight frames of the stage's after fit.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import perception_substitution as substitution  # noqa: E402
from perception.momentum import point_masses_momentum  # noqa: E402
from perception.net_tracking import NetPrior, nearest_segments, node_velocities  # noqa: E402


def seen_nodes(returns_world, positions_world, threads, gate=NetPrior().gate) -> np.ndarray:
    """Nodes (n,) bool with a return within ``gate`` (m) of an adjoining thread (positions m, world)."""
    seen = np.zeros(len(positions_world), bool)
    if len(returns_world):
        index, _, distance = nearest_segments(returns_world, positions_world, threads)
        seen[np.asarray(threads)[index[distance < gate]].ravel()] = True
    return seen


def split(path) -> dict:
    cap = substitution.load(path)
    parts, track = cap["assembly"], cap["track"]
    masses, threads = np.asarray(parts["net_masses"]), np.asarray(parts["net_threads"])
    origin = np.asarray(cap["origin"])
    fit_after = cap["fits"][-1]["motion"]
    times = np.asarray(track.times)
    positions = np.asarray(track.positions)
    velocities = node_velocities(times, positions)
    true_positions, true_velocities = substitution.true_net(cap)
    updates = {round(u["time"], 6): u for u in cap["collision_updates"]}
    rows = []
    for t in fit_after.times:
        j = int(np.argmin(np.abs(times - t)))
        update = updates.get(round(float(times[j]), 6))
        returns = np.zeros((0, 3)) if update is None else np.asarray(update["all_returns_world"])
        seen = seen_nodes(returns, positions[j], threads)
        error = {}
        for name, select in (("seen", seen), ("unseen", ~seen)):
            _, estimated = point_masses_momentum(masses[select], positions[j][select], velocities[j][select], origin)
            _, true = point_masses_momentum(masses[select], true_positions[j][select], true_velocities[j][select], origin)
            error[name] = estimated - true
        mean_velocity = masses @ velocities[j] / masses.sum()
        _, relative = point_masses_momentum(masses[~seen], positions[j][~seen],
                                            velocities[j][~seen] - mean_velocity, origin)
        rows.append((error["seen"], error["unseen"], relative, (~seen).mean()))
    seen_error, unseen_error, relative, share = (np.array(column) for column in zip(*rows))
    return {"seed": cap["answer"]["bench_seed"], "seen_error": seen_error.mean(axis=0),
            "unseen_error": unseen_error.mean(axis=0), "unseen_relative": relative.mean(axis=0),
            "unseen_share": share.mean(), "frames": len(rows)}


def _vec(v) -> str:
    return "(" + ", ".join(f"{x:+.2f}" for x in v) + ")"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args(argv)
    print("| capture | seed | frames | unseen nodes (share) | error of the seen nodes' L | error of the unseen nodes' L "
          "| unseen nodes' L about the net's mean motion (estimate) |")
    print("|---|---|---|---|---|---|---|")
    for path in args.captures:
        r = split(path)
        print(f"| {path} | {r['seed']} | {r['frames']} | {r['unseen_share']:.2f} | {_vec(r['seen_error'])} | "
              f"{_vec(r['unseen_error'])} | {_vec(r['unseen_relative'])} |", flush=True)


if __name__ == "__main__":
    main()
