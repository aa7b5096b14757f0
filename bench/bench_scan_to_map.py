"""Model-free against mesh-based tracking of a synthetic tumble, over several LiDAR noise seeds.

The body tumbles torque-free with Tang et al. (2023)'s normalized moments and initial rates (Table 1),
its origin on a straight line at 10 m, scanned at 10 Hz by the C-Fans-256-like LiDAR of the paper's
Table 3 (2 cm noise). For each seed the same scans are tracked

* without the mesh: :func:`perception.scan_to_map.track_scans` (perception.model = "none");
* with it: :class:`perception.registration.DebrisTracker` on the mesh (perception.model = "known"),

and the figures printed per seed: registration CPU time per frame (process time, the first two
frames apart), frames registered, attitude error
(mean, worst; for the model-free track also after removing the map's constant turn), CoM error in
the world at t = 0, and the inertia-ratio errors of the torque-free fit.

    python bench/bench_scan_to_map.py [--seeds 0 1 2 3 4] [--duration 20] [--body featured|ellipsoid]
                                      [--models none known] [--settled 1e-4 1e-3] [--tukey 0.5 1]
                                      [--prefixes 5 10 20 30 60] [--constants "" "FINE_POINTS=2000"]

``--prefixes``: the data-length study (Tang et al. 2023, Table 4) from one tracked run per seed: the
fits redone on the first T s of the frames, for each T. The track of frame k uses only frames up to k
(the map is built from the frames registered before it), so a prefix is exactly what a T-s observation
would have given.

``--constants``: an A/B of any of the module's constants (perception/scan_to_map.py, e.g. ``COARSE_ITERATIONS=10``,
``FINE_POINTS=2000,MAP_INTERVAL=20``; ``""`` is the module as it is): each seed's scans are tracked once per entry,
back to back in one process, every constant back at the module's value before each entry.
"""
from __future__ import annotations

import argparse
import os
import time
from types import SimpleNamespace

import numpy as np
import open3d as o3d
import trimesh
from scipy.spatial.transform import Rotation

from multibody.geometry import shape_mesh
from perception.euler_poinsot import propagate_torque_free, rotations_from_wxyz
from perception.free_flight import fit_free_motion
from perception.lidar import LidarSpec, cast
from perception.motion import NotObservable
from perception.registration import DebrisTracker, known_shape_model
from perception import scan_to_map
from perception.scan_to_map import alignments, track_scans

DEG = np.pi / 180
LIDAR = LidarSpec(150 * DEG, 30 * DEG, 0.09 * DEG, 0.12 * DEG, 0.02, 10.0)   # Tang et al. 2023, Table 3
MOMENTS = np.array([445.98, 422.80, 313.04])                                # Table 1 (kg m^2)
OMEGA0 = np.array([2.0, 0.5, 1.0])                                          # Table 1 (rad/s)
COM0, VELOCITY = np.array([10.0, 0.0, 0.0]), np.array([0.01, 0.0, -0.01])   # m, m/s
VOXEL, CORRESPONDENCE = 0.03, 0.1


def _body(name):
    if name == "ellipsoid":
        return shape_mesh("ellipsoid", semi_axes=[0.65, 0.7, 0.9])
    return trimesh.util.concatenate([shape_mesh("box", size=[1.2, 1.0, 1.6]),
                                     shape_mesh("box", size=[0.05, 2.0, 0.8], center=(0.0, 1.5, 0.2))])


def _figures(times, body_to_world_true, world_to_body, ok, information, seconds):
    """Attitude errors (deg) of the registered frames, with the constant turn removed, and the fits."""
    turns = Rotation.from_matrix([np.linalg.inv(pose)[:3, :3] @ truth.T
                                  for pose, truth in zip(world_to_body[ok], body_to_world_true[ok])])
    error = np.degrees(turns.magnitude())
    relative = np.degrees((turns.mean().inv() * turns).magnitude())
    tracker = SimpleNamespace(alignments=[SimpleNamespace(body_to_world=np.linalg.inv(p), information=i)
                                          for p, i in zip(world_to_body, information)])
    try:
        motion = fit_free_motion(tracker, np.flatnonzero(ok), times)
        com = 1e3 * np.linalg.norm(motion.line.position_world([0.0])[0] - COM0)
        ratios = (motion.fit.moments_[:2] / (MOMENTS[:2] / MOMENTS[2]) - 1) * 100
    except NotObservable as exc:
        com, ratios = float("nan"), f"not observable: {exc}"
    ms = 1e3 * np.asarray(seconds)[2:]
    return (f"{ms.mean():6.1f} ms/frame CPU mean, {np.median(ms):5.1f} median; {ok.sum()}/{len(ok)} frames; attitude "
            f"{error.mean():.2f} / {error.max():.2f} deg (constant turn removed {relative.mean():.2f} / {relative.max():.2f}); "
            f"CoM {com:.1f} mm; ratios {np.round(ratios, 3) if not isinstance(ratios, str) else ratios} %")


#: Constants of perception/scan_to_map.py that ``--constants`` may set (reset to these before each entry).
_TUNABLE = ("SETTLED", "TUKEY_CUTOFF", "COARSE_ITERATIONS", "FINE_ITERATIONS", "COARSE_POINTS", "FINE_POINTS",
            "MAP_COVERED", "MAP_INTERVAL", "MIN_FITNESS")


def _constants(entry):
    """``"NAME=VALUE,NAME=VALUE"`` -> {NAME: value} (int or float as the module's own), checked against
    :data:`_TUNABLE`; ``""`` -> {}."""
    chosen = {}
    for item in filter(None, (part.strip() for part in entry.split(","))):
        name, _, value = item.partition("=")
        if name not in _TUNABLE or not value:
            raise SystemExit(f"--constants {entry!r}: {item!r} is not NAME=VALUE with NAME one of {', '.join(_TUNABLE)}")
        chosen[name] = type(getattr(scan_to_map, name))(float(value))
    return chosen


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--duration", type=float, default=20.0, help="tumble tracked (s)")
    parser.add_argument("--body", choices=("featured", "ellipsoid"), default="featured")
    parser.add_argument("--models", nargs="+", choices=("none", "known"), default=["none", "known"])
    parser.add_argument("--settled", type=float, nargs="+", default=None,
                        help="scan-to-map ICP stop tolerances to compare (m: a step's rotation times "
                             "scan_to_map.BODY_SIZE plus its translation); each seed is tracked once per value, "
                             "back to back (A/B in one process); default the module's SETTLED")
    parser.add_argument("--tukey", type=float, nargs="+", default=None,
                        help="scan-to-map Tukey cut-offs to compare (share of the correspondence distance, "
                             "scan_to_map.TUKEY_CUTOFF); each seed is tracked once per value, back to back")
    parser.add_argument("--prefixes", type=float, nargs="+", default=None,
                        help="data lengths (s): the fits also redone on the first T s of each track (Table 4)")
    parser.add_argument("--constants", nargs="+", default=None,
                        help='scan-to-map constants to compare, one entry per track: "NAME=VALUE,NAME=VALUE" '
                             '(perception/scan_to_map.py; "" the module as it is); back to back per seed')
    args = parser.parse_args()
    entries = [_constants(entry) for entry in args.constants or [""]]
    times = np.arange(int(round(args.duration * LIDAR.rate)) + 1) / LIDAR.rate
    quaternions, _ = propagate_torque_free(np.array([1.0, 0, 0, 0]), OMEGA0, MOMENTS / MOMENTS[2], times, 0.005)
    body_to_world = rotations_from_wxyz(quaternions).as_matrix()
    mesh = _body(args.body)
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)   # RANSAC re-acquisition warnings
    defaults = {name: getattr(scan_to_map, name) for name in _TUNABLE}
    print(f"load {os.getloadavg()[0]:.2f}; {args.body} body, {args.duration:g} s at {LIDAR.rate:g} Hz")
    for seed in args.seeds:
        rng = np.random.default_rng(seed)
        scans = [cast(LIDAR, [(mesh.vertices @ r.T + COM0 + VELOCITY * t, mesh.faces)], t, rng).points_sensor
                 for t, r in zip(times, body_to_world)]
        variants = [(settled, tukey, entry) for settled in (args.settled or [defaults["SETTLED"]])
                    for tukey in (args.tukey or [defaults["TUKEY_CUTOFF"]]) for entry in entries]
        for settled, tukey, entry in variants if "none" in args.models else []:
            for name, value in {**defaults, "SETTLED": settled, "TUKEY_CUTOFF": tukey, **entry}.items():
                setattr(scan_to_map, name, value)
            free = track_scans(scans, VOXEL, CORRESPONDENCE)
            records = alignments(free, times)
            # B of the model-free track is the first scan's frame; the truth in it: R_k R_0^T (R_0 = I here)
            named = "".join(f", {name} {value:g}" for name, value in entry.items())
            print(f"seed {seed} none, settled {1e3 * settled:g} mm, Tukey {tukey:g} x distance{named}: "
                  + _figures(times, body_to_world, free.world_to_body, free.ok,
                             np.array([a.information for a in records]), free.cpu_seconds), flush=True)
            for length in args.prefixes or []:
                k = round(length * LIDAR.rate) + 1
                print(f"  first {length:g} s: " + _figures(times[:k], body_to_world[:k], free.world_to_body[:k],
                                                           free.ok[:k], np.array([a.information for a in records[:k]]),
                                                           free.cpu_seconds[:k]), flush=True)
        if "known" not in args.models:
            continue
        known = DebrisTracker(VOXEL, CORRESPONDENCE, 30, *known_shape_model(mesh, VOXEL, seed), seed=seed)
        for t, points in zip(times, scans):
            known.update(t, points, np.zeros(3))
        ok = np.array([a.ok for a in known.alignments])
        poses = np.array([a.world_to_body for a in known.alignments])
        print(f"seed {seed} known: " + _figures(times, body_to_world, poses, ok,
                                               np.array([a.information for a in known.alignments]),
                                               [a.cpu_seconds for a in known.alignments]))
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"{time.perf_counter() - t0:.0f} s wall")
