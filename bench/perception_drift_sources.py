"""Where does the slow attitude error about the map frame B's third axis come from? On a captured model-free
perception run (bench/perception_capture.py), the registered attitude errors of the observation frames against
the truth (frame B) are set beside, frame by frame:

* **the map's growth**: the frames after which the map was rebuilt, reconstructed from the capture with the
  rule of :func:`perception.scan_to_map.track_scans` (a registered frame whose fitness is below MAP_COVERED, or
  MAP_INTERVAL frames after the last build), and the scan's uncovered share (1 - fitness, new surface); the
  error's step onto each new map against the steps between rebuilds, and the share of the slow (below half
  the tumble frequency) part of the error that the steps at rebuilds carry, against random frame sets of the
  same size;
* **the view geometry**: the line of sight (sensor -> debris CoM) in B and its angle to B's axes and to the
  true principal axes; the scan's point count (the surface seen: its projected area at the fixed 10 m hold);
* **the registration**: fitness, CPU time (a proxy for the ICP's iterations; the capture holds neither the
  iterations nor the inlier RMSE), the stated 1-sigma about B's third axis from the frame's information.

    python bench/perception_drift_sources.py runs/captures/none_obs20_seed2.pkl [...] [--fixed-map | --map-properties]

With ``--fixed-map`` (~20 s CPU a capture), the observation's scans are made again (the capture's case, seed and
observation time; the stage's online track is redone and checked against the captured poses) and each scan is
registered, as the stage does (motion prior, the two first frames at their true poses), to one **fixed** map
built from all the observation's scans at their true poses in the capture's B (with and without the motion
prior), and to a noise-free map of the debris mesh: a slow error that stays on the true-pose map is not the
online map's build-up; one that stays on the mesh map would be the registration's own on these views.

With ``--map-properties`` (~2-4 min CPU a capture; only this report), the observation made again with and without
the LiDAR's range noise, and the noisy scans registered (the stage's prior) to fixed maps at the true poses that
differ from the map of the noisy scans (voxel means on a grid anchored in B, residuals to the means) in one
property each: made of the noise-free scans; without the frame being registered; with the mesh's exact normals;
the noise-free map's points with the noisy map's normals; the means projected on their fitted planes (in numpy,
and as the stage's map does it, :class:`perception.scan_to_map.LazyNormals`); beside the stage's online track of
the noisy and of the noise-free scans (the current code).

The truth is read from the capture; nothing is refitted.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.spatial import cKDTree
from scipy.stats import f as f_distribution

from perception.motion import integrated_autocorrelation_time
from perception.normals import surface_normals
from perception import scan_to_map
from perception.scan_to_map import MAP_COVERED, MAP_INTERVAL

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from perception_substitution import _vec, load, true_body_to_world  # noqa: E402

CASE = Path(__file__).resolve().parent.parent / "cases" / "featured_debris_perception_model_free.toml"
#: Random frame sets drawn for the null distribution of the rebuild steps' share of the slow error.
NULL_DRAWS = 2000


def rebuild_frames(cap) -> np.ndarray:
    """Frames after whose registration the map was rebuilt (track_scans' rule replayed on the captured
    fitness and registration flags): the next registered frame is the first on the new map."""
    built, rebuilt = None, []
    for i, a in enumerate(cap["alignments"]):
        if not a.ok:
            continue
        if built is None:
            built = i
            continue
        if a.tight_fitness < MAP_COVERED or i - built >= MAP_INTERVAL:
            built = i
            rebuilt.append(i)
    return np.array(rebuilt, int)


def slow_part(series, frame_interval, cutoff_hz) -> np.ndarray:
    """The part (k,) of a per-frame series below ``cutoff_hz`` (FFT low-pass, mean removed)."""
    series = np.asarray(series, float) - np.mean(series)
    spectrum = np.fft.rfft(series)
    spectrum[np.fft.rfftfreq(len(series), frame_interval) >= cutoff_hz] = 0.0
    return np.fft.irfft(spectrum, len(series))


def sensor_world(cap) -> np.ndarray:
    """The LiDAR's origin (3,) (m, world) during the observation: the chaser holds at hold_distance along
    the run-in direction from the debris' first CoM (riskassess.stages.perceive.observe)."""
    from riskassess.cases.impact import load_case
    from riskassess.stages.perceive import Scene
    scene = Scene.from_case(load_case(CASE), CASE.parent, str(CASE))
    chaser_com = np.asarray(cap["frames"]["true_com_world"][0]) - scene.case.perception.hold_distance * scene.direction
    return scene.sensor_pose(chaser_com, np.eye(3))[0]


def line_of_sight_body(cap, indices, sensor) -> np.ndarray:
    """Unit line of sight sensor -> debris CoM (k, 3) in the true B frame."""
    rows = []
    for k in indices:
        pose = true_body_to_world(cap, k)
        los = np.asarray(cap["frames"]["true_com_world"][k]) - sensor
        rows.append(pose[:3, :3].T @ los / np.linalg.norm(los))
    return np.array(rows)


def principal_axes_body(cap) -> np.ndarray:
    """True principal axes (columns, ascending moments) in B."""
    _, axes_target = np.linalg.eigh(cap["truth"]["inertia_target"])
    return cap["target_to_body"][:3, :3] @ axes_target


def attitude_errors(cap, indices) -> np.ndarray:
    """rotvec(R_true^T R_registered) (k, 3) (rad, frame B)."""
    return np.array([Rotation.from_matrix(true_body_to_world(cap, k)[:3, :3].T
                                          @ cap["alignments"][k].body_to_world[:3, :3]).as_rotvec() for k in indices])


def map_batch_view(line_of_sight, rebuilt) -> np.ndarray:
    """For each frame (k, 3): the line of sight in B averaged over the scans added to the map at its last
    rebuild before the frame (the scans that dominate the rebuilt map: a rebuild thins the old map's points,
    one a voxel, together with every pending scan's, so in a voxel seen by the ~10 pending scans the old map
    point weighs about 1/11 of the new mean)."""
    rebuilt = np.unique(rebuilt)
    bounds = np.r_[0, rebuilt]
    batches = [line_of_sight[0]] + [line_of_sight[bounds[j - 1] + 1:bounds[j] + 1].mean(axis=0)
                                    for j in range(1, len(bounds))]
    last = np.searchsorted(rebuilt, np.arange(len(line_of_sight)), side="left")
    return np.array([batches[j] for j in last])


def correlation(a, b) -> float:
    return float(np.corrcoef(a, b)[0, 1])


def effective_samples(a, b) -> float:
    """Frames over the larger integrated autocorrelation time of two series: the samples a correlation rests on."""
    return len(a) / max(integrated_autocorrelation_time(np.c_[a]), integrated_autocorrelation_time(np.c_[b]), 1.0)


def rebuild_step_correlation(error, first_on_new_map, slow, rng) -> tuple[float, float, float]:
    """Correlation of the slow error (k,) with the slow part of its steps onto new maps alone, cumulated (the
    drift the rebuilds would make on their own), and that correlation's 50th and 95th percentiles over random
    frame sets of the same size (the steps' cumulated sum over any frames correlates with the error somewhat)."""
    steps = np.diff(error, prepend=error[0])
    target = slow(error)

    def r(frames):
        mask = np.zeros(len(error), bool)
        mask[frames] = True
        return correlation(target, slow(np.cumsum(np.where(mask, steps, 0.0))))

    null = [r(rng.choice(np.arange(1, len(error)), len(first_on_new_map), replace=False)) for _ in range(NULL_DRAWS)]
    return r(first_on_new_map), float(np.percentile(null, 50)), float(np.percentile(null, 95))


def strongest_slow_frequencies(series, frame_interval, cutoff_hz) -> list[tuple[float, float]]:
    """The two strongest frequencies below ``cutoff_hz`` (Hz) of a series (k,) and their shares of its variance."""
    power = np.abs(np.fft.rfft(series - series.mean())) ** 2
    frequencies = np.fft.rfftfreq(len(series), frame_interval)
    slow = np.flatnonzero((frequencies > 0) & (frequencies < cutoff_hz))
    top = slow[np.argsort(power[slow])[::-1][:2]]
    return [(float(frequencies[i]), float(power[i] / power[1:].sum())) for i in top]


def fixed_map_errors(cap) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """The observation's attitude errors (k, 3) (rad, frame B) of the stage's online track, made again from the
    capture's case, seed and observation time, and of the same scans registered to a fixed map of the scans at
    their true poses, with the stage's motion prior and without, and to a noise-free map of the mesh (with the prior);
    and the largest difference (-) of the online poses from the captured ones (0: the same run)."""
    from perception import scan_to_map
    from perception.registration import known_shape_model

    scene, scans, online = _observation_scans(cap)
    k = len(scans)
    difference = max(float(np.abs(online[i] - cap["alignments"][i].world_to_body).max()) for i in range(k))
    reg = scene.case.perception.registration
    thin = [scan_to_map.thinned_scan(scan, reg.voxel) for scan in scans]
    true_world_to_body = [np.linalg.inv(true_body_to_world(cap, i)) for i in range(k)]
    points, normals, index, _ = scan_to_map._built_map(
        np.vstack([scan_to_map._transform(thin[i], true_world_to_body[i]) for i in range(k)]), reg.voxel,
        reg.max_correspondence)
    def registered(prior_sigma, built=(points, normals, index)):
        poses = true_world_to_body[:2]
        for i in range(2, k):
            pose, _, _ = scan_to_map._register(thin[i], built[0], built[1],
                                               scan_to_map.predict_world_to_body(poses[i - 1], poses[i - 2]),
                                               reg.max_correspondence, prior_sigma, built[2])
            poses.append(pose)
        return poses

    # the noise-free map: the debris mesh sampled densely (known_shape_model), in B, thinned as the stage's map
    mesh_points_target, _ = known_shape_model(scene.mesh_target, reg.voxel, 0)
    mesh_map = scan_to_map._built_map(scan_to_map._transform(mesh_points_target, cap["target_to_body"]), reg.voxel,
                                      reg.max_correspondence)[:3]

    def errors(world_to_body):
        return np.array([Rotation.from_matrix(true_body_to_world(cap, i)[:3, :3].T
                                              @ np.linalg.inv(world_to_body[i])[:3, :3]).as_rotvec() for i in range(k)])

    return (errors(online), errors(registered(scan_to_map.PRIOR_SIGMA)), errors(registered(None)),
            errors(registered(scan_to_map.PRIOR_SIGMA, mesh_map)), difference)


def report_fixed_map(path) -> None:
    cap = load(path)
    online, fixed, fixed_no_prior, mesh, difference = fixed_map_errors(cap)
    dt = float(np.median(np.diff(np.asarray(cap["frames"]["time"])[:len(online)])))
    cutoff = 2.29 / (4.0 * np.pi)
    print(f"== {path}, the scans made again: the online track's largest pose difference from the capture {difference:.1e}")
    slow_b3 = {}
    for name, errors in [("online map (the stage)", online), ("fixed map, true poses", fixed),
                         ("fixed map, no motion prior", fixed_no_prior), ("noise-free mesh map", mesh)]:
        errors = np.degrees(errors - errors.mean(axis=0))
        slow = np.array([slow_part(errors[:, i], dt, cutoff) for i in range(3)]).T
        slow_b3[name] = slow[:, 2]
        print(f"    {name}: errors rms {_vec(errors.std(axis=0))} deg, slow part rms {_vec(slow.std(axis=0))} deg; "
              f"slow B3 every 1 s {np.array2string(slow[::10, 2], precision=2, max_line_width=200)}")
    a, b, c, _ = slow_b3.values()
    print(f"    slow B3 error, online vs fixed map: r {correlation(a, b):+.2f}; fixed map with vs without the prior: r "
          f"{correlation(b, c):+.2f}")


def _observation_scans(cap, range_noise=None):
    """The capture's observation made again (its case, seed and observation time): the scene, the scans (m,
    world) and the stage's online track's poses world -> B; ``range_noise`` (m) replaces the LiDAR's."""
    from riskassess.cases.impact import load_case
    from riskassess.stages.perceive import Frames, Scene, observe_tumble_model_free

    answer = cap["answer"]
    case = load_case(CASE)
    perception = case.perception.model_copy(update={"seed": int(answer["bench_seed"]), "model": "none",
                                                    "observation_time": float(answer["bench_observation_s"])})
    case = case.model_copy(update={"perception": perception})
    scene = Scene.from_case(case, CASE.parent, str(CASE))
    if range_noise is not None:
        scene = dataclasses.replace(scene, spec=dataclasses.replace(scene.spec, range_noise=range_noise))
    frames = Frames()
    _, tracker, _ = observe_tumble_model_free(scene, frames, np.random.default_rng(perception.seed))
    k = len(frames.scans)
    return scene, frames.scans, [a.world_to_body for a in tracker.alignments[:k]]


def _registered_to(thin, true_world_to_body, built, max_correspondence, prior_sigma=None):
    """Each thinned scan (world) registered as the stage does (motion prior from the two previous poses, the first
    two frames at their true poses) to a fixed map ``built`` = (points, normals, index) or, when ``built`` is a
    callable, to the map ``built(i)`` of frame i."""
    prior_sigma = scan_to_map.PRIOR_SIGMA if prior_sigma is None else prior_sigma
    poses = list(true_world_to_body[:2])
    for i in range(2, len(thin)):
        points, normals, index = built(i) if callable(built) else built
        pose, _, _ = scan_to_map._register(thin[i], points, normals,
                                           scan_to_map.predict_world_to_body(poses[i - 1], poses[i - 2]),
                                           max_correspondence, prior_sigma, index)
        poses.append(pose)
    return poses


def _voxel_sums(points_body, voxel):
    """Voxel keys (v, 3) int, point sums (v, 3) (m) and counts (v,) of points (n, 3) (m, frame B) on a grid anchored
    at the origin of B (the leave-one-out map subtracts one scan's sums)."""
    keys, inverse, counts = np.unique(np.floor(points_body / voxel).astype(np.int64), axis=0, return_inverse=True,
                                      return_counts=True)
    sums = np.zeros((len(keys), 3))
    np.add.at(sums, inverse.ravel(), points_body)
    return keys, sums, counts


def _map_from_means(points, voxel, max_correspondence, normals=None, on_planes=False):
    """(points, normals, index) of map points (n, 3) (m, frame B). ``on_planes``: as the stage's map, normals
    estimated lazily (4 voxels, 30 neighbours) and the residuals taken to the points projected on their fitted
    planes; otherwise to the points themselves, with the given ``normals`` (n, 3) or the same estimated ones."""
    points = np.ascontiguousarray(points)
    index = scan_to_map.map_index(points, max_correspondence)
    if on_planes:
        return points, scan_to_map.LazyNormals(np.empty((len(points), 3)), np.zeros(len(points), np.bool_),
                                               4 * voxel, 30), index
    normals = surface_normals(points, 4 * voxel, 30) if normals is None else normals
    return points, scan_to_map.LazyNormals.given(normals, index), index


def mesh_normals_at(scene, target_to_body, points_body) -> np.ndarray:
    """The debris mesh's face normals (n, 3) (frame B) at the nearest surface point of each map point (n, 3) (m, B)."""
    body_to_target = np.linalg.inv(target_to_body)
    _, _, triangles = scene.mesh_target.nearest.on_surface(scan_to_map._transform(points_body, body_to_target))
    return np.asarray(scene.mesh_target.face_normals)[triangles] @ target_to_body[:3, :3].T


def projected_on_fitted_planes(points, radius, max_nn=30) -> tuple[np.ndarray, np.ndarray]:
    """Each point (n, 3) (m) moved along its normal onto the plane fitted (PCA) to its ``max_nn`` nearest within
    ``radius`` (m): the plane through their mean; and those normals (n, 3)."""
    gap, near = cKDTree(points).query(points, max_nn, distance_upper_bound=radius)
    found = np.isfinite(gap)
    near = np.where(found, near, np.arange(len(points))[:, None])
    weight = found / found.sum(axis=1, keepdims=True)
    mean = np.einsum("nk,nki->ni", weight, points[near])
    centred = points[near] - mean[:, None, :]
    covariance = np.einsum("nk,nki,nkj->nij", weight, centred, centred)
    normals = np.linalg.eigh(covariance)[1][:, :, 0]
    return points - np.einsum("ni,ni->n", points - mean, normals)[:, None] * normals, normals


def map_property_errors(cap) -> dict:
    """Attitude errors (k, 3) (rad, frame B) of the observation's noisy scans registered (the stage's prior) to fixed
    maps at the true poses that differ in one property each from the map of the noisy scans (voxel means on a grid
    anchored in B, lazily estimated normals): the map of the noise-free scans; the noisy map without the frame
    being registered; the noisy map's points with the mesh's exact normals; the noise-free map's points with the
    normals estimated from the noisy map; and the online tracks of the noisy and noise-free scans."""
    scene, scans, online = _observation_scans(cap)
    _, clean_scans, clean_online = _observation_scans(cap, range_noise=0.0)
    reg = scene.case.perception.registration
    voxel, distance = reg.voxel, reg.max_correspondence
    k = len(scans)
    truth = [np.linalg.inv(true_body_to_world(cap, i)) for i in range(k)]
    thin = [scan_to_map.thinned_scan(s, voxel) for s in scans]
    clean_thin = [scan_to_map.thinned_scan(s, voxel) for s in clean_scans]
    body = [scan_to_map._transform(thin[i], truth[i]) for i in range(k)]
    keys, sums, counts = _voxel_sums(np.vstack(body), voxel)
    noisy_points = sums / counts[:, None]
    noisy = _map_from_means(noisy_points, voxel, distance)
    clean_keys, clean_sums, clean_counts = _voxel_sums(
        np.vstack([scan_to_map._transform(clean_thin[i], truth[i]) for i in range(k)]), voxel)
    clean_points = clean_sums / clean_counts[:, None]
    row = {tuple(key): j for j, key in enumerate(keys)}

    def left_out(i):
        own_keys, own_sums, own_counts = _voxel_sums(body[i], voxel)
        rows = np.array([row[tuple(key)] for key in own_keys])
        s, c = sums.copy(), counts.astype(float).copy()
        s[rows] -= own_sums
        c[rows] -= own_counts
        keep = c > 0
        return _map_from_means(s[keep] / c[keep, None], voxel, distance)

    noisy_normals = surface_normals(noisy_points, 4 * voxel, 30)
    nearest_noisy = cKDTree(noisy_points).query(clean_points)[1]
    errors = lambda poses: np.array([Rotation.from_matrix(true_body_to_world(cap, i)[:3, :3].T   # noqa: E731
                                                          @ np.linalg.inv(poses[i])[:3, :3]).as_rotvec()
                                     for i in range(k)])
    return {
        "online map (the stage), noisy scans": errors(online),
        "online map, noise-free scans (their own track)": errors(clean_online),
        "fixed map of the noisy scans": errors(_registered_to(thin, truth, noisy, distance)),
        "fixed map of the noise-free scans": errors(_registered_to(thin, truth, _map_from_means(clean_points, voxel, distance), distance)),
        "fixed noisy map, the registered frame left out": errors(_registered_to(thin, truth, left_out, distance)),
        "fixed noisy map's points, the mesh's exact normals": errors(_registered_to(
            thin, truth, _map_from_means(noisy_points, voxel, distance, mesh_normals_at(scene, cap["target_to_body"], noisy_points)), distance)),
        "fixed noise-free map's points, the noisy map's normals": errors(_registered_to(
            thin, truth, _map_from_means(clean_points, voxel, distance, noisy_normals[nearest_noisy]), distance)),
        "fixed noisy map's points projected on their fitted planes (numpy)": errors(_registered_to(
            thin, truth, _map_from_means(projected_on_fitted_planes(noisy_points, 4 * voxel)[0], voxel, distance),
            distance)),
        "fixed noisy map's points projected on their fitted planes (the stage's LazyNormals)": errors(_registered_to(
            thin, truth, _map_from_means(noisy_points, voxel, distance, on_planes=True), distance)),
        "noise-free scans on the fixed map of the noise-free scans": errors(_registered_to(
            clean_thin, truth, _map_from_means(clean_points, voxel, distance), distance)),
    }


def report_map_properties(path) -> None:
    cap = load(path)
    dt = float(np.median(np.diff(np.asarray(cap["frames"]["time"])[:201])))
    cutoff = 2.29 / (4.0 * np.pi)
    print(f"== {path}: which property of the scan-made map (fixed maps at the true poses, the stage's prior)")
    for name, errors in map_property_errors(cap).items():
        errors = np.degrees(errors[2:] - errors[2:].mean(axis=0))
        slow = np.array([slow_part(errors[:, i], dt, cutoff) for i in range(3)]).T
        print(f"    {name}: errors rms {_vec(errors.std(axis=0))} deg, slow part rms {_vec(slow.std(axis=0))} deg; "
              f"slow B3 every 2 s {np.array2string(slow[::20, 2], precision=2, max_line_width=200)}")
    sys.stdout.flush()


def report_across_captures(paths) -> None:
    """The slow B3 errors of several captures of the same case (the same tumble, another noise seed) against
    each other: a drift common to all is set by what the seeds share (the tumble, the view, the rebuild
    schedule), one that differs by the noise realisation."""
    caps = [load(p) for p in paths]
    obs = [np.asarray(c["fits"][0]["indices"], int) for c in caps]
    same = all(len(o) == len(obs[0]) and np.allclose(np.asarray(c["frames"]["true_target_to_world"])[o],
                                                     np.asarray(caps[0]["frames"]["true_target_to_world"])[obs[0]])
               for c, o in zip(caps, obs))
    print(f"== across the captures: the same true attitudes on the observation frames: {same}")
    if not same:
        return
    dt = float(np.median(np.diff(np.asarray(caps[0]["frames"]["time"])[obs[0]])))
    cutoff = 2.29 / (4.0 * np.pi)
    slow = [slow_part(np.degrees(attitude_errors(c, o)[:, 2]), dt, cutoff) for c, o in zip(caps, obs)]
    for i in range(len(caps)):
        for j in range(i + 1, len(caps)):
            print(f"    slow B3 error, {paths[i]} vs {paths[j]}: r {correlation(slow[i], slow[j]):+.2f}; rms "
                  f"{slow[i].std():.3f} / {slow[j].std():.3f} deg")


def report(path, rng) -> None:
    cap = load(path)
    obs = np.asarray(cap["fits"][0]["indices"], int)
    times = np.asarray(cap["frames"]["time"])[obs]
    dt = float(np.median(np.diff(times)))
    rate = np.linalg.norm(cap["fits"][0]["motion"].fit.rate_body_at(times[0])) if hasattr(
        cap["fits"][0]["motion"], "fit") else 2.29
    cutoff = rate / (4.0 * np.pi)
    slow = lambda s: slow_part(s, dt, cutoff)  # noqa: E731
    errors = attitude_errors(cap, obs)
    e3 = np.degrees(errors[:, 2] - errors[:, 2].mean())
    e3_slow = slow(e3)
    print(f"== {path}: {len(obs)} observation frames, dt {dt:.2f} s, cutoff {cutoff:.3f} Hz; error about B3 rms "
          f"{e3.std():.3f} deg, its slow part rms {e3_slow.std():.3f} deg")

    # (a) the map's growth
    rebuilt = rebuild_frames(cap)
    rebuilt = rebuilt[rebuilt < obs[-1]]
    position = {k: j for j, k in enumerate(obs)}
    first_on_new = np.array([position[k] + 1 for k in rebuilt if k in position and position[k] + 1 < len(obs)])
    steps = np.diff(e3)
    on_new = np.zeros(len(steps), bool)
    on_new[first_on_new - 1] = True
    fitness = np.array([cap["alignments"][k].tight_fitness for k in obs])
    cpu = np.array([cap["alignments"][k].cpu_seconds for k in obs])
    forced = np.sum(fitness[[position[k] for k in rebuilt if k in position]] < MAP_COVERED)
    print(f"(a) map rebuilds in the observation: {len(rebuilt)} ({forced} on new surface, fitness < {MAP_COVERED}; "
          f"the rest on the {MAP_INTERVAL}-frame interval); frames between rebuilds median "
          f"{np.median(np.diff(rebuilt)):.0f}")
    print(f"    CPU of the first frame on a new map median {1e3 * np.median(cpu[first_on_new]):.1f} ms, of the others "
          f"{1e3 * np.median(np.delete(cpu, first_on_new)[1:]):.1f} ms (lazy normals: the reconstruction's check)")
    print(f"    step of the B3 error onto a new map: rms {np.sqrt(np.mean(steps[on_new] ** 2)):.3f} deg, mean "
          f"{steps[on_new].mean():+.4f} deg ({on_new.sum()} steps); between rebuilds: rms "
          f"{np.sqrt(np.mean(steps[~on_new] ** 2)):.3f} deg, mean {steps[~on_new].mean():+.4f} deg ({(~on_new).sum()})")
    ratio = np.mean(steps[on_new] ** 2) / np.mean(steps[~on_new] ** 2)
    print(f"    their variance ratio {ratio:.2f}, one-sided F test p {f_distribution.sf(ratio, on_new.sum(), (~on_new).sum()):.3f}")
    r, null50, null95 = rebuild_step_correlation(e3, first_on_new, slow, rng)
    print(f"    slow B3 error vs the slow part of the steps onto new maps, cumulated: r {r:+.2f} (random frame sets "
          f"of the same size: median {null50:+.2f}, 95th percentile {null95:+.2f})")
    uncovered = slow(1.0 - fitness)
    growth = np.cumsum(1.0 - fitness)
    print(f"    slow B3 error vs the scans' uncovered share (slow parts): r {correlation(e3_slow, uncovered):+.2f}; vs "
          f"the cumulated uncovered share (the map's growth, slow part): r {correlation(e3_slow, slow(growth)):+.2f}; "
          f"new surface in the first 5 s / the rest: {np.sum((1 - fitness)[times < times[0] + 5]):.2f} / "
          f"{np.sum((1 - fitness)[times >= times[0] + 5]):.2f} scan-equivalents")
    half = len(e3) // 2
    print(f"    slow B3 error every 1 s (deg): {np.array2string(e3_slow[::10], precision=2, max_line_width=200)}")
    print(f"    B3 error's slow part rms in the first / second half of the observation: {e3_slow[:half].std():.3f} / "
          f"{e3_slow[half:].std():.3f} deg; B3 error mean first / second half {e3[:half].mean():+.3f} / "
          f"{e3[half:].mean():+.3f} deg")

    # (b) the view geometry
    sensor = sensor_world(cap)
    los = line_of_sight_body(cap, obs, sensor)
    axes = principal_axes_body(cap)
    angle_b3 = np.degrees(np.arccos(np.abs(los[:, 2])))
    angle_p = np.degrees(np.arccos(np.abs(los @ axes)))
    points = np.asarray(cap["frames"]["n_points"])[obs].astype(float)
    print(f"(b) line of sight's angle to B3: {angle_b3.min():.0f}-{angle_b3.max():.0f} deg (mean {angle_b3.mean():.0f}); "
          f"to principal axes 1/2/3 mean {_vec(angle_p.mean(axis=0))} deg; scan points {points.min():.0f}-"
          f"{points.max():.0f}")
    for name, series in [("line of sight's B3 component |u3|", np.abs(los[:, 2])),
                         ("line of sight's angle to principal axis 1", angle_p[:, 0]),
                         ("scan points", points)]:
        s = slow(series)
        print(f"    slow B3 error vs slow {name}: r {correlation(e3_slow, s):+.2f} (effective samples "
              f"{effective_samples(e3_slow, s):.1f}); its slow part's share of its variance "
              f"{np.sum(s ** 2) / np.sum((series - series.mean()) ** 2):.2f}")

    for i in range(3):
        s = slow(los[:, i])
        lags = range(-20, 21)
        lagged = [correlation(e3_slow[max(0, lag):len(s) + min(0, lag)], s[max(0, -lag):len(s) - max(0, lag)])
                  for lag in lags]
        best = int(np.argmax(np.abs(lagged)))
        peaks = ", ".join(f"{f:.3f} Hz ({share:.2f})" for f, share in strongest_slow_frequencies(los[:, i], dt, cutoff))
        print(f"    slow B3 error vs slow line of sight's B{i + 1} component (signed): r {correlation(e3_slow, s):+.2f}, "
              f"largest |r| {lagged[best]:+.2f} with the error {list(lags)[best]} frames later; the component's "
              f"strongest slow frequencies {peaks}")
    peaks = ", ".join(f"{f:.3f} Hz ({share:.2f})" for f, share in strongest_slow_frequencies(e3, dt, cutoff))
    print(f"    the B3 error's strongest slow frequencies: {peaks}")
    rebuilt_obs = np.array([position[k] for k in rebuilt if k in position])
    for i in range(3):
        real = correlation(e3_slow, slow(map_batch_view(los, rebuilt_obs)[:, i]))
        shifted = [correlation(e3_slow, slow(map_batch_view(los, np.clip(rebuilt_obs + shift, 1, len(obs) - 2))[:, i]))
                   for shift in range(-5, 6) if shift]
        print(f"    slow B3 error vs slow line of sight's B{i + 1} component averaged over the last map rebuild's scans: "
              f"r {real:+.2f} (the rebuild schedule shifted by -5..+5 frames: r {min(shifted):+.2f} to {max(shifted):+.2f})")

    # (c) the registration
    sigma3 = np.degrees([np.sqrt(np.linalg.inv(cap["alignments"][k].information)[2, 2]) for k in obs])
    print(f"(c) fitness {fitness.min():.3f}-{fitness.max():.3f}; stated 1-sigma about B3 {sigma3.min():.3f}-"
          f"{sigma3.max():.3f} deg (median {np.median(sigma3):.3f})")
    for name, series in [("fitness", fitness), ("CPU per frame", cpu), ("stated 1-sigma about B3", sigma3)]:
        s = slow(series)
        print(f"    slow B3 error vs slow {name}: r {correlation(e3_slow, s):+.2f}; |B3 error| vs {name}: r "
              f"{correlation(np.abs(e3), series):+.2f}")
    world = np.array([true_body_to_world(cap, k)[:3, :3] @ e for k, e in zip(obs, errors)])
    world = np.degrees(world - world.mean(axis=0))
    print(f"    the errors in the world (sensor-fixed axes): rms {_vec(world.std(axis=0))} deg, slow part rms "
          f"{_vec(np.array([slow(world[:, i]).std() for i in range(3)]))} deg; in B: rms "
          f"{_vec(np.degrees(errors.std(axis=0)))} deg, slow {_vec(np.array([slow(np.degrees(errors[:, i])).std() for i in range(3)]))}")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--seed", type=int, default=0, help="random frame sets of the null distribution")
    parser.add_argument("--fixed-map", action="store_true",
                        help="make the scans again and register them to a fixed map of their true poses")
    parser.add_argument("--map-properties", action="store_true",
                        help="register the noisy scans to fixed true-pose maps differing in one property each")
    args = parser.parse_args()
    if args.map_properties:
        for path in args.captures:
            report_map_properties(path)
        return
    np.set_printoptions(precision=4, suppress=True)
    rng = np.random.default_rng(args.seed)
    for path in args.captures:
        report(path, rng)
    if len(args.captures) > 1:
        report_across_captures(args.captures)
    if args.fixed_map:
        for path in args.captures:
            report_fixed_map(path)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
