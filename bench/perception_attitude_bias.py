"""Is the registered attitudes' bias across the spin momentum a reference artefact or a registration bias?

On a captured perception run (bench/perception_capture.py), each free-flight fit's registered attitude
errors against the truth (rotation vectors, world frame, ``e_k = log(R_reg,k R_true,k^T)``) are split,
by linear least squares over the fit's frames, into

* a **body-side** constant ``e_body`` (the map's frame B off the truth's by a fixed rotation: in the world it
  turns with the body, ``R_true,k e_body``). A body-side constant cannot change the spin momentum in the world,
  ``h = R I omega / C``: the fit absorbs it into its principal axes (checked below by replaying the step with
  it taken out: C must not move);
* a **world-side** constant ``q_world`` (every attitude turned by one rotation in the world: what turns h),
  and, with ``--trend``, a world-side drift ``q_dot_world`` (growing with time, i.e. with the turned angle);
* the rest (per-frame noise).

Then C is replayed (order-4 net velocities, the stage's momentum step) with each part taken out of the
registered attitudes, and the fits' spin momenta h0, h1 are compared with the truth directly: the angle of
``h_fit`` from ``h_true`` across h and the relative error along it (frame-independent: no reference
involved).

    python bench/perception_attitude_bias.py /tmp/percep17/capchain/none_obs20_seed{0,1,2,3,4}.pkl
"""
from __future__ import annotations

import argparse
import copy

import numpy as np
from scipy.spatial.transform import Rotation

import perception_substitution as S
from perception.net_tracking import node_velocities


def attitude_errors_world(cap, indices) -> tuple[np.ndarray, np.ndarray]:
    """Registered minus true attitude of frames ``indices``: rotation vectors (k, 3) (rad, world) and the
    true B -> world rotations (k, 3, 3)."""
    true_rot = np.array([S.true_body_to_world(cap, k)[:3, :3] for k in indices])
    reg_rot = np.array([cap["alignments"][k].body_to_world[:3, :3] for k in indices])
    errors = Rotation.from_matrix(reg_rot @ np.transpose(true_rot, (0, 2, 1))).as_rotvec()
    return errors, true_rot


def split_errors(errors_world, true_rot, times, trend=False) -> dict:
    """Least-squares split ``e_k = q + (t_k - t_mean) q_dot + R_k e_body + r_k`` (rad, rad/s; q and q_dot in
    the world frame, e_body in B)."""
    k = len(errors_world)
    columns = [np.tile(np.eye(3), (k, 1)), true_rot.reshape(3 * k, 3)]
    if trend:
        columns.append(np.kron((times - times.mean())[:, None], np.eye(3)))
    design = np.hstack(columns)
    solution, *_ = np.linalg.lstsq(design, errors_world.reshape(-1), rcond=None)
    residual = errors_world.reshape(-1) - design @ solution
    return {"q_world": solution[:3], "e_body": solution[3:6],
            "q_dot_world": solution[6:9] if trend else np.zeros(3),
            "rms_residual": float(np.sqrt(np.mean(residual.reshape(k, 3) ** 2) * 3))}


def corrected_tracker(cap, indices, world_rotvec=None, body_rotvec=None) -> S.Tracker:
    """The alignments with frames ``indices`` turned by -world_rotvec on the world side and -body_rotvec on the
    body side (rad), both about the true CoM (so the CoM track is unchanged)."""
    alignments = [copy.copy(a) for a in cap["alignments"]]
    com_body = S.true_com_body(cap)
    world = Rotation.from_rotvec(-np.zeros(3) if world_rotvec is None else -np.asarray(world_rotvec)).as_matrix()
    body = Rotation.from_rotvec(np.zeros(3) if body_rotvec is None else -np.asarray(body_rotvec)).as_matrix()
    for k in indices:
        pose = alignments[k].body_to_world
        rot = world @ pose[:3, :3] @ body
        com_world = pose[:3, :3] @ com_body + pose[:3, 3]
        new = np.eye(4)
        new[:3, :3] = rot
        new[:3, 3] = com_world - rot @ com_body
        alignments[k].world_to_body = np.linalg.inv(new)
    return S.Tracker(alignments)


def across_and_along(vector, direction) -> tuple[float, float]:
    """|vector across direction| and vector . direction / |direction|."""
    unit = direction / np.linalg.norm(direction)
    along = float(vector @ unit)
    return float(np.linalg.norm(vector - along * unit)), along


def h_against_truth(h_fit, h_true) -> str:
    """Angle of the fitted spin momentum from the true one (deg) and its relative magnitude error (%)."""
    cos = h_fit @ h_true / np.linalg.norm(h_fit) / np.linalg.norm(h_true)
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return f"{angle:.3f} deg off, |h| {100 * (np.linalg.norm(h_fit) / np.linalg.norm(h_true) - 1):+.3f} %"


def report(path, trend=False) -> None:
    cap = S.load(path)
    c_true = S.true_c(cap)
    times_all = np.asarray(cap["frames"]["time"])
    track_times, positions = np.asarray(cap["track"].times), np.asarray(cap["track"].positions)
    net = (positions, node_velocities(track_times, positions))
    c0, _, _, before, after, origin, *_ = S.replay(cap, net=net)
    truth = S.true_terms(cap, before, after, origin)
    print(f"\n== {path.split('/')[-1]}: C as the stage (order-4 net) {100 * (c0 / c_true - 1):+.3f} %")
    parts = {}
    for name, key, fit, h_true in (("before", "before_tracker", before, truth["h0"]),
                                   ("after", "after_tracker", after, truth["h1"])):
        indices = cap["fits"][0 if name == "before" else -1]["indices"]
        errors, true_rot = attitude_errors_world(cap, indices)
        split = split_errors(errors, true_rot, times_all[indices], trend)
        parts[name] = (key, indices, split)
        h = fit.spin_per_c
        q_across, q_along = across_and_along(split["q_world"], h)
        mean_across, _ = across_and_along(errors.mean(axis=0), h)
        turn_h = np.cross(split["q_world"], h)   # what a world turn q does to h (first order)
        print(f"  {name}: {len(indices)} frames {times_all[indices][0]:.1f}-{times_all[indices][-1]:.1f} s; "
              f"h fit vs truth {h_against_truth(h, h_true)}; "
              f"(h_fit - h_true) across h {1e3 * across_and_along(h - h_true, h)[0]:.3f} mrad/s, q x h {1e3 * np.linalg.norm(turn_h):.3f} mrad/s, "
              f"cos(h_fit - h_true, q x h) {((h - h_true) @ turn_h) / (np.linalg.norm(h - h_true) * np.linalg.norm(turn_h) + 1e-30):+.2f}")
        print(f"    mean world error {np.round(np.degrees(errors.mean(axis=0)), 4)} deg (across h {np.degrees(mean_across):.4f}); "
              f"split: e_body {np.round(np.degrees(split['e_body']), 4)} deg, q_world {np.round(np.degrees(split['q_world']), 4)} deg "
              f"(across h {np.degrees(q_across):.4f}, along {np.degrees(q_along):+.4f}), "
              f"q_dot {np.round(np.degrees(split['q_dot_world']) * 1e3, 2)} mdeg/s, rest {np.degrees(split['rms_residual']):.3f} deg rms")
    rows = []
    for label, kwargs in (
            ("the before fit's e_body out of both fits (a change of B: must leave C)",
             {parts[n][0]: corrected_tracker(cap, parts[n][1], body_rotvec=parts["before"][2]["e_body"]) for n in parts}),
            ("world-side q out of the before fit",
             {parts["before"][0]: corrected_tracker(cap, parts["before"][1], world_rotvec=parts["before"][2]["q_world"])}),
            ("world-side q out of the after fit",
             {parts["after"][0]: corrected_tracker(cap, parts["after"][1], world_rotvec=parts["after"][2]["q_world"])}),
            ("world-side q out of both",
             {parts[n][0]: corrected_tracker(cap, parts[n][1], world_rotvec=parts[n][2]["q_world"]) for n in parts}),
            ("both sides out of both",
             {parts[n][0]: corrected_tracker(cap, parts[n][1], world_rotvec=parts[n][2]["q_world"],
                                             body_rotvec=parts[n][2]["e_body"]) for n in parts})):
        c, *_ = S.replay(cap, net=net, **kwargs)
        rows.append(f"{label}: {100 * (c / c_true - 1):+.3f} %")
    print("    C error with: " + "; ".join(rows), flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--trend", action="store_true", help="fit a world-side drift q_dot too")
    args = parser.parse_args()
    for path in args.captures:
        report(path, args.trend)


if __name__ == "__main__":
    main()
