"""Why the net's angular momentum after the collision is low: the differentiation stencil against the node fit.
On captured perception runs (bench/perception_capture.py), per free-flight frame of the stage's after fit:

* **the stencil**: the true node positions (at the frame times) differentiated by the Savitzky-Golay fit of
  order 2 (the stage's until percep20) and of order 4 (``perception.net_tracking.VELOCITY_FIT_ORDER``) against
  the true velocities: the net's angular momentum error (mean over the flight, N m s, world x, y, z) and C's
  error when the momentum step is redone with true positions and these velocities;
* **the fit**: C with the fitted nodes differentiated at each order, with the fitted positions and the true
  velocities, and with the true net (positions and velocities);
* **the association**: of the net returns (within 1 cm of a true thread: their true thread), the share whose
  nearest fitted thread within ``NetPrior.gate`` is their true thread; the seen nodes' position error (rms, m)
  and its part along the net's local normal; the seen nodes' angular-momentum error from their velocity errors
  split into the part in the net's local plane and the part along its normal.

    python bench/perception_net_velocity_bias.py /tmp/percep17/capchain/none_obs20_seed*.pkl

The truth is read from the collision run's record; the estimators never see it.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import perception_substitution as substitution  # noqa: E402
from perception_net_unseen import _vec, seen_nodes  # noqa: E402
from perception.net_tracking import NetPrior, nearest_segments, node_velocities  # noqa: E402

#: A return this close to a true thread (m) is taken as that thread's (the threads' radius is 2 mm, the
#: range noise 2 cm: most net returns lie within it, and the few that do not are left out of the share).
ON_THREAD = 0.01


def _angular(masses, positions, velocities, origin, select=None):
    """Angular momentum (3,) (N m s, world) of the selected nodes about ``origin``."""
    select = np.ones(len(masses), bool) if select is None else select
    return np.sum(masses[select, None] * np.cross(positions[select] - origin, velocities[select]), axis=0)


def local_normals(positions, threads) -> np.ndarray:
    """Unit normals (n, 3) of the net at each node: the least-spread direction of its neighbours' offsets."""
    offsets = [[] for _ in range(len(positions))]
    for a, b in np.asarray(threads):
        offsets[a].append(positions[b] - positions[a])
        offsets[b].append(positions[a] - positions[b])
    normals = np.zeros_like(positions)
    for k, rows in enumerate(offsets):
        q = np.asarray(rows)
        normals[k] = np.linalg.eigh(q.T @ q)[1][:, 0]
    return normals


def stencil_and_fit(cap) -> dict:
    """C's error (%) for the stencil and fit substitutions, and the stencil's angular-momentum error on the truth."""
    c_true = substitution.true_c(cap)
    track = cap["track"]
    times, fitted = np.asarray(track.times), np.asarray(track.positions)
    true_positions, true_velocities = substitution.true_net(cap)
    masses, origin = np.asarray(cap["assembly"]["net_masses"]), np.asarray(cap["origin"])
    frames = [int(np.argmin(np.abs(times - t))) for t in cap["fits"][-1]["motion"].times]
    out = {}
    for order in (2, 4):
        on_truth = node_velocities(times, true_positions, order=order)
        out[f"L_error_truth_order{order}"] = np.mean([
            _angular(masses, true_positions[j], on_truth[j], origin)
            - _angular(masses, true_positions[j], true_velocities[j], origin) for j in frames], axis=0)
        out[f"C_truth_order{order}"] = _c_error(cap, c_true, true_positions, on_truth)
        c, sigma = _c_error(cap, c_true, fitted, node_velocities(times, fitted, order=order), with_sigma=True)
        out[f"C_fit_order{order}"], out[f"sigma_fit_order{order}"] = c, sigma
    out["C_fit_positions_true_velocities"] = _c_error(cap, c_true, fitted, true_velocities)
    out["C_true_net"] = _c_error(cap, c_true, true_positions, true_velocities)
    return out


def _c_error(cap, c_true, positions, velocities, with_sigma=False):
    c, sigma, *_ = substitution.replay(cap, net=(positions, velocities))
    error = 100 * (c - c_true) / c_true
    return (error, 100 * sigma / c_true) if with_sigma else error


def association(cap) -> dict:
    """The fit's association of returns to threads, and where the seen nodes' errors lie (see module docstring)."""
    parts, track = cap["assembly"], cap["track"]
    masses, threads = np.asarray(parts["net_masses"]), np.asarray(parts["net_threads"])
    times, fitted = np.asarray(track.times), np.asarray(track.positions)
    velocities = node_velocities(times, fitted)
    true_positions, true_velocities = substitution.true_net(cap)
    origin = np.asarray(cap["origin"])
    updates = {round(u["time"], 6): u for u in cap["collision_updates"]}
    right, position_rms, normal_rms, in_plane, along_normal = [], [], [], [], []
    for t in cap["fits"][-1]["motion"].times:
        j = int(np.argmin(np.abs(times - t)))
        update = updates.get(round(float(times[j]), 6))
        returns = np.zeros((0, 3)) if update is None else np.asarray(update["all_returns_world"])
        true_index, _, true_distance = nearest_segments(returns, true_positions[j], threads)
        on_net = true_distance < ON_THREAD
        index, _, distance = nearest_segments(returns[on_net], fitted[j], threads)
        used = distance < NetPrior().gate
        right.append(np.mean(index[used] == true_index[on_net][used]) if used.any() else np.nan)
        seen = seen_nodes(returns, fitted[j], threads)
        if not seen.any():
            continue
        normals = local_normals(true_positions[j], threads)
        error = fitted[j] - true_positions[j]
        position_rms.append(np.sqrt(np.mean(np.sum(error[seen] ** 2, axis=1))))
        normal_rms.append(np.sqrt(np.mean(np.einsum("ij,ij->i", error[seen], normals[seen]) ** 2)))
        velocity_error = velocities[j] - true_velocities[j]
        normal_part = np.einsum("ij,ij->i", velocity_error, normals)[:, None] * normals
        in_plane.append(_angular(masses, true_positions[j], velocity_error - normal_part, origin, seen))
        along_normal.append(_angular(masses, true_positions[j], normal_part, origin, seen))
    return {"right_thread": np.nanmean(right), "right_thread_range": (np.nanmin(right), np.nanmax(right)),
            "seen_position_rms": np.mean(position_rms), "seen_normal_rms": np.mean(normal_rms),
            "L_seen_velocity_in_plane": np.mean(in_plane, axis=0), "L_seen_velocity_normal": np.mean(along_normal, axis=0)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("captures", nargs="+")
    args = parser.parse_args(argv)
    rows = []
    for path in args.captures:
        cap = substitution.load(path)
        rows.append((cap["answer"]["bench_seed"], stencil_and_fit(cap), association(cap)))
    print("The stencil, on the true node positions: the net's angular momentum error (N m s, world; mean over the "
          "after fit's frames) and C's error (%) with true positions and these velocities")
    print("| seed | L error, order 2 | L error, order 4 | C, order 2 | C, order 4 | C, true net |")
    print("|---|---|---|---|---|---|")
    for seed, s, _ in rows:
        print(f"| {seed} | {_vec(s['L_error_truth_order2'])} | {_vec(s['L_error_truth_order4'])} | "
              f"{s['C_truth_order2']:+.3f} | {s['C_truth_order4']:+.3f} | {s['C_true_net']:+.3f} |")
    print("\nThe fit: C's error (%) (stated 1-sigma) with the fitted nodes")
    print("| seed | order 2 | order 4 | fitted positions, true velocities | true net | fit's share with order 4 |")
    print("|---|---|---|---|---|---|")
    for seed, s, _ in rows:
        print(f"| {seed} | {s['C_fit_order2']:+.3f} ({s['sigma_fit_order2']:.3f}) | {s['C_fit_order4']:+.3f} "
              f"({s['sigma_fit_order4']:.3f}) | {s['C_fit_positions_true_velocities']:+.3f} | {s['C_true_net']:+.3f} | "
              f"{s['C_fit_order4'] - s['C_true_net']:+.3f} |")
    print("\nThe association (net returns within 1 cm of a true thread; seen nodes as fit_net_nodes counts them)")
    print("| seed | returns on their true thread (range over frames) | seen nodes' position error rms (m) | its normal "
          "part (m) | seen nodes' L error from velocities, in the net's plane | along its normal |")
    print("|---|---|---|---|---|---|")
    for seed, _, a in rows:
        lo, hi = a["right_thread_range"]
        print(f"| {seed} | {a['right_thread']:.2f} ({lo:.2f}-{hi:.2f}) | {a['seen_position_rms']:.3f} | "
              f"{a['seen_normal_rms']:.3f} | {_vec(a['L_seen_velocity_in_plane'])} | {_vec(a['L_seen_velocity_normal'])} |")


if __name__ == "__main__":
    main()
