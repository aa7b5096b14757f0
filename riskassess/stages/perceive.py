"""`riskassess perceive`: debris mass and inertia from LiDAR and the net collision
(Tang et al. 2023, Actuators 12, 344).

Timeline (time 0 = the chaser starts its run in):

1. **Observation**, ``-observation_time .. 0``: the chaser holds ``hold_distance`` back along the
   launch direction; the debris tumbles freely (Exudyn); the LiDAR scans it at its frame rate;
   each scan is registered (:class:`perception.registration.DebrisTracker`). From the poses:
   the CoM (:func:`perception.motion.center_of_mass_line`), the normalized inertia and principal
   axes (:class:`perception.euler_poinsot.TorqueFreeFit`), the normalized kinetic energy and
   angular momentum and its direction.
2. **Collision**, ``0 .. simulation.end_time``: the coupled Exudyn impact of the chaser's netted
   pocket on the debris, started from the observed tumble's end state. The LiDAR rides on the
   chaser and sees debris and net threads; the debris is still registered, the net's nodes are
   fitted to the thread returns (:mod:`perception.net_tracking`).
3. **Momentum step** (:mod:`perception.momentum`): once the debris flies free of the net, its
   new CoM velocity and spin come from fits with the now known CoM and normalized inertia; the
   chaser's own navigation (taken exact) and the net's tracked nodes close the linear and
   angular momentum balances, which give the mass and the smallest principal moment C.

With ``perception.model = "none"`` the observation is tracked without the debris mesh
(:mod:`perception.scan_to_map`: scan-to-map registration, the first scan's frame as body frame),
the map then serves as the collision phase's model; the fits are the same.

The estimators see only the scans, the chaser's navigation and the design of the chaser and
net; the simulated truth is used for the error figures alone (and the mesh, with model "none",
only to make the scans).
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import open3d as o3d
import trimesh
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from multibody.free_motion import free_motion
from multibody.impact import ImpactSimulation
from perception.free_flight import RESTART_RESIDUAL_DEG, FreeMotion, fit_free_motion, normalized_energy_and_momentum
from perception.lidar import LidarSpec, cast, sensor_to_platform
from perception.momentum import point_masses_momentum, rigid_body_momentum
from perception.momentum_balance import momentum_step
from perception.model_mismatch import CHECK_EVERY, ModelCheck, SurfaceDistance, gate, model_check, unexplained_share, unseen_share
from perception.motion import NotObservable
from perception.net_tracking import NetPrior, carried_by_chaser, fit_net_nodes, nearest_segments, node_velocities, thread_mesh
from perception.pointing import Pointing, debris_blob
from perception.pose_graph import scan_clouds
from perception.scan_to_scan import ReposedFrames, ScanPartners, scan_partners, scan_to_scan_poses
from perception.registration import MAP_LATERAL_BINS, MIN_POINTS, DebrisTracker, known_shape_model
from perception.scan_to_map import alignments as map_alignments, registered_again, thinned_scan, track_scans
from perception.shape import half_turn_symmetry_transforms, rotation_error
from riskassess.products import results
from riskassess.models.impact import model_inputs
from riskassess.cases.impact import Case, CaseError, load_case
from riskassess.stages.run import begin_run_folder, run_recorded, write_simulation
from riskassess.cases.target_geometry import body_meshes_target_frame
from riskassess.cases.truth_damage import damaged_case

#: Scan points farther than this from the predicted debris surface are not registered to it (m):
#: a frame's motion is predicted to ~1 cm; net threads sit decimetres to metres in front.
DEBRIS_GATE = 0.3
#: A model-free track (``perception.model = 'none'``) is used only when the torque-free fit explains
#: its attitudes to this RMS (deg). Tracks of a featured body fit to ~0.4 deg (each frame good to
#: ~1 deg, mostly a constant turn of the map); on the paper's smooth ellipsoid the map slides about
#: the near-symmetry axis and the fit leaves 12 deg (10 s) (tests/perception/test_scan_to_map.py,
#: docs/perception.md).
#: The same bound the torque-free fit restarts beyond (perception/free_flight.py): one rule, "a fit this far
#: from its frames stopped in a wrong optimum", so the restart and the refusal cannot drift apart.
MAX_MODEL_FREE_RESIDUAL_DEG = RESTART_RESIDUAL_DEG
#: ... and when the fit determines the inertia ratios to this relative 1-sigma (-). A track that slid
#: smoothly (the paper's ellipsoid over 5 s: 2.6 deg from the fit, 19 deg from the truth) passes the
#: residual test but leaves the ratios undetermined (1-sigma 120 %, the fit at its bound of 2);
#: a featured body's 10 s track gives 0.4-0.5 %.
MAX_MODEL_FREE_RATIO_SIGMA = 0.05
#: Returns closer than this to a predicted net thread are taken as net, not debris (m).
NET_GATE = 0.1
#: The debris flies free once no tracked net thread comes closer to its surface than this (m).
SEPARATION = 0.1
#: With its track lost, the debris is looked for in a ball of its reach about its CoM plus this (m):
#: the map's and the CoM line's errors (cm) and the range noise.
BLOB_MARGIN = 0.2


def _pose(rotation, translation) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = translation
    return pose


@dataclass
class Scene:
    """What the perception run is made of, from the case: sensor, debris model, chaser and net.

    With ``[perception.truth_damage]`` the scanned and simulated debris (``real_case``,
    ``mesh_target``, ``debris``, ``truth``) differs from the model the tracker is given
    (``model_mesh_target``, the case's [target]); without it they are the same.
    """

    case: Case
    base: Path
    spec: LidarSpec
    sensor_to_chaser: np.ndarray        # (3, 3) sensor -> chaser body
    sensor_in_chaser: np.ndarray        # (3,) sensor origin, chaser body frame (m)
    mesh_target: object                 # trimesh, target frame: the real debris, which the LiDAR scans
    debris: object                      # RigidBodySpec of the real debris at the start of the observation
    truth: dict                         # mass, com_target, inertia_target (used for errors only)
    model_mesh_target: object = None    # trimesh, target frame: the debris model given to the tracker
    real_case: Case = None              # the case of the real debris (truth_damage applied)

    @classmethod
    def from_case(cls, case: Case, base: Path, source: str = "case") -> "Scene":
        """The scene of a perception case; a :class:`CaseError` when a section the stage needs is
        missing or the target is not one rigid body.

        Parameters
        ----------
        case : Case
            A loaded impact case with ``[perception]`` and ``[chaser]`` sections.
        base : Path
            Folder the case's relative file paths (meshes) are resolved against.
        source : str
            Name of the case in error messages (its file path).

        Returns
        -------
        Scene
        """
        if case.perception is None:
            raise CaseError(f"{source}: perception: missing; `riskassess perceive` needs a [perception] section "
                            "(see cases/tang2023_debris_perception.toml)")
        if case.chaser is None:
            raise CaseError(f"{source}: chaser: missing; the momentum step needs the chaser carrying the net "
                            "([chaser] section)")
        if len(case.target.bodies) != 1 or case.target.joints:
            raise CaseError(f"{source}: target.bodies: perception estimates one rigid debris body; the case has "
                            f"{len(case.target.bodies)} bodies and {len(case.target.joints)} joints")
        lidar = case.perception.lidar
        spec = LidarSpec(lidar.fov_azimuth, lidar.fov_elevation, lidar.resolution_azimuth,
                         lidar.resolution_elevation, lidar.range_noise, lidar.rate, lidar.max_range)
        real = damaged_case(case, base)
        model_mesh = trimesh.util.concatenate(body_meshes_target_frame(case, base)[0])
        mesh = trimesh.util.concatenate(body_meshes_target_frame(real, base)[0]) if real is not case else model_mesh
        body = real.target.bodies[0]
        inputs = model_inputs(real, base)
        debris = inputs.assembly.bodies[0]
        com_target = debris.body_to_lvlh.T @ (debris.com_lvlh - np.asarray(case.target.position_lvlh, float))
        truth = {"mass": body.mass, "com_target": com_target, "inertia_target": debris.inertia_body}
        return cls(case, base, spec, sensor_to_platform(lidar.boresight_lvlh, lidar.up_lvlh),
                   np.asarray(lidar.position_chaser, float), mesh, debris, truth, model_mesh, real)

    @property
    def direction(self) -> np.ndarray:
        d = np.asarray(self.case.launch.direction, float)
        return d / np.linalg.norm(d)

    def sensor_pose(self, chaser_com, chaser_to_world, aim_world=None) -> tuple[np.ndarray, np.ndarray]:
        """Sensor origin (3,) and sensor->world rotation (3, 3) for a chaser pose; with
        ``pointing = 'target'`` and an aim point (m, world), the boresight turns to it (the
        mount's up axis kept as close to the chaser's as the new boresight allows).

        Parameters
        ----------
        chaser_com : (3,) float
            Chaser CoM, world (LVLH) frame (m).
        chaser_to_world : (3, 3) float
            Chaser body -> world rotation.
        aim_world : (3,) float, optional
            Point to aim the boresight at, world frame (m); None keeps the body-fixed mount.

        Returns
        -------
        sensor_world : (3,) float
            Sensor origin, world frame (m).
        sensor_to_world : (3, 3) float
            Sensor -> world rotation.
        """
        origin = chaser_com + chaser_to_world @ self.sensor_in_chaser
        body_fixed = chaser_to_world @ self.sensor_to_chaser
        if aim_world is None or self.case.perception.lidar.pointing == "body":
            return origin, body_fixed
        return origin, sensor_to_platform(np.asarray(aim_world) - origin, body_fixed[:, 2])

    def debris_vertices_world(self, target_to_world, target_origin_world) -> np.ndarray:
        """The debris mesh's vertices placed in the world frame.

        Parameters
        ----------
        target_to_world : (3, 3) float
            Target (mesh) frame -> world (LVLH) rotation.
        target_origin_world : (3,) float
            Target frame origin, world frame (m).

        Returns
        -------
        (v, 3) float
            Vertices, world frame (m).
        """
        return np.asarray(self.mesh_target.vertices) @ target_to_world.T + target_origin_world


@dataclass
class Frames:
    """Per LiDAR frame: time (s), phase (0 observation, 1 collision), the registration and the
    truth it is scored against."""

    time: list = field(default_factory=list)
    phase: list = field(default_factory=list)
    n_points: list = field(default_factory=list)
    rotation_error: list = field(default_factory=list)
    true_target_to_world: list = field(default_factory=list)
    true_com_world: list = field(default_factory=list)
    cast_seconds: list = field(default_factory=list)
    # observation frames only: the scans (n, 3) (m, world) and sensor poses, for the model check
    # and a model-free fall back
    scans: list = field(default_factory=list)
    sensor_poses: list = field(default_factory=list)
    # collision frames' debris returns (n, 3) (m, world) by frame index, kept only when the free flight's frames
    # are posed scan to scan (perception.registration.after_frames_scan_to_scan)
    debris_returns: dict = field(default_factory=dict)


def _scan_world(scene, meshes_world, sensor_world, sensor_to_world, t, rng):
    """Ray-cast world-frame meshes from a sensor pose; points (n, 3) world frame and labels."""
    meshes_sensor = [((v - sensor_world) @ sensor_to_world, f) for v, f in meshes_world]
    scan = cast(scene.spec, meshes_sensor, t, rng)
    return scan.points_sensor @ sensor_to_world.T + sensor_world, scan.label


def _aim_point(tracker: DebrisTracker):
    """Where the debris is expected in this frame (m, world): its model centroid at the
    tracker's predicted pose; None before any good frame."""
    pose = tracker.predicted_world_to_body()
    if pose is None:
        return None
    body_to_world = np.linalg.inv(pose)
    return body_to_world[:3, :3] @ tracker.model_points_body.mean(axis=0) + body_to_world[:3, 3]


def _thinned(points_world, voxel) -> np.ndarray:
    """One point per ``voxel`` (m) cell (Open3D voxel filter): keeps thin threads, bounds the work."""
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points_world))
    return np.asarray(cloud.voxel_down_sample(voxel).points)


def _crop_to_predicted(tracker: DebrisTracker, points_world) -> np.ndarray:
    """Scan points near the debris surface predicted from the last two good frames (others
    belong to the net); all points when there is no prediction. Done here on the full scan,
    before the tracker thins it: the tracker's own ``gate`` (after thinning) registered fewer
    free-flight frames in the shortened test case (7 against 16)."""
    predicted, has_motion = tracker.prediction()
    if not has_motion:
        return points_world
    body = points_world @ predicted[:3, :3].T + predicted[:3, 3]
    return points_world[np.isfinite(tracker.distance_to_model(body, DEBRIS_GATE))]


# ------------------------------------------------------------------------------ phase 1
def observe_tumble(scene: Scene, tracker: DebrisTracker, frames: Frames, symmetries, rng, progress=None,
                   early_check: int | None = None):
    """Free tumble before the run in, scanned from the hold point. Returns the debris state at
    time 0 (CoM, body->world, velocity, omega body) for the collision run, and the model check.

    With ``early_check`` the model is checked (:func:`check_model`) after that many frames; when it
    does not match the scans, the remaining frames are only scanned (stored in ``frames`` for a
    model-free track), not registered to it: a wrong model costs seconds per frame in searches
    (3 s/frame measured on the damaged featured debris). Otherwise the check is taken over all frames.

    Parameters
    ----------
    scene : Scene
        Sensor, debris model and truth of the case.
    tracker : perception.registration.DebrisTracker
        Known-shape tracker; every scan is registered into it.
    frames : Frames
        Per-frame record, appended to (time in s, truth in the world frame).
    symmetries : list of (3, 3) float
        Rotations of the mesh's indistinguishable attitudes (target frame), for the error figures.
    rng : numpy.random.Generator
        Range noise of the LiDAR.
    progress : callable, optional
        ``progress(phase, done, total)`` after each frame (``phase`` a str, counts in frames).

    Returns
    -------
    com_world : (3,) float
        Debris CoM at time 0, world (LVLH) frame (m).
    body_to_world : (3, 3) float
        Debris body -> world rotation at time 0.
    velocity_world : (3,) float
        CoM velocity, world frame (m/s).
    omega_body : (3,) float
        Angular velocity, body frame (rad/s).
    check : perception.model_mismatch.ModelCheck
        The model against the scans.
    """
    p = scene.case.perception
    debris = scene.debris
    count = int(round(p.observation_time * scene.spec.rate))
    sample_times = np.arange(count + 1) / scene.spec.rate
    states = free_motion([debris], [], sample_times)
    chaser_com = debris.com_lvlh - p.hold_distance * scene.direction
    com_target = scene.truth["com_target"]
    check = None
    for k, t in enumerate(sample_times - p.observation_time):
        aim = _aim_point(tracker) if check is None else None
        sensor_world, sensor_to_world = scene.sensor_pose(chaser_com, np.eye(3), aim)
        rot, com = states["body_to_lvlh"][k, 0], states["body_com_lvlh"][k, 0]
        origin = com - rot @ com_target
        tic = time.perf_counter()
        points, _ = _scan_world(scene, [(scene.debris_vertices_world(rot, origin), scene.mesh_target.faces)],
                                sensor_world, sensor_to_world, t, rng)
        frames.cast_seconds.append(time.perf_counter() - tic)
        frames.scans.append(points)
        frames.sensor_poses.append((sensor_world, sensor_to_world))
        if check is None:
            _register(tracker, frames, t, 0, points, sensor_world, rot, com, symmetries)
            if early_check is not None and k + 1 == early_check:
                check = check_model(scene, tracker, frames)
                check = check if check.mismatch else None
        else:   # the model was found wrong: scanned for the model-free track only
            _record(frames, t, 0, points, rot, com)
        if progress:
            progress("observation", k + 1, count + 1)
    state = (states["body_com_lvlh"][-1, 0], states["body_to_lvlh"][-1, 0], states["body_velocity_lvlh"][-1, 0],
             states["body_omega_body"][-1, 0])
    return state, check or check_model(scene, tracker, frames)


def observe_tumble_model_free(scene: Scene, frames: Frames, rng, progress=None):
    """Free tumble before the run in, scanned from the hold point (boresight fixed: no pose to aim
    at before the track exists), every scan registered to a map built from the scans
    (:func:`perception.scan_to_map.track_scans`). Returns the debris state at time 0 as
    :func:`observe_tumble`, the tracker for the collision phase (the map as its frozen model) and the
    target -> B transform (4, 4) of the truth, for the error figures only.

    Parameters
    ----------
    scene : Scene
        Sensor, debris model and truth of the case (the mesh only makes the scans).
    frames : Frames
        Per-frame record, appended to (time in s, truth in the world frame).
    rng : numpy.random.Generator
        Range noise of the LiDAR.
    progress : callable, optional
        ``progress(phase, done, total)`` after each frame (``phase`` a str, counts in frames).

    Returns
    -------
    state : tuple of (3,), (3, 3), (3,), (3,) float
        Debris CoM (m, world), body -> world rotation, CoM velocity (m/s, world) and angular
        velocity (rad/s, body frame) at time 0, as :func:`observe_tumble`.
    tracker : perception.registration.DebrisTracker
        Tracker with the map (frame B, m) as its model and the track's alignments.
    target_to_body : (4, 4) float
        Truth's target -> B transform (m for the translation); identity when no frame registered.
    """
    p = scene.case.perception
    debris = scene.debris
    count = int(round(p.observation_time * scene.spec.rate))
    sample_times = np.arange(count + 1) / scene.spec.rate
    states = free_motion([debris], [], sample_times)
    chaser_com = debris.com_lvlh - p.hold_distance * scene.direction
    com_target = scene.truth["com_target"]
    sensor_world, sensor_to_world = scene.sensor_pose(chaser_com, np.eye(3))
    for k, t in enumerate(sample_times - p.observation_time):
        rot, com = states["body_to_lvlh"][k, 0], states["body_com_lvlh"][k, 0]
        tic = time.perf_counter()
        points, _ = _scan_world(scene, [(scene.debris_vertices_world(rot, com - rot @ com_target), scene.mesh_target.faces)],
                                sensor_world, sensor_to_world, t, rng)
        frames.cast_seconds.append(time.perf_counter() - tic)
        frames.scans.append(points)
        frames.sensor_poses.append((sensor_world, sensor_to_world))
        frames.time.append(t)
        frames.phase.append(0)
        frames.n_points.append(len(points))
        frames.true_target_to_world.append(rot)
        frames.true_com_world.append(com)
        if progress:
            progress("observation", k + 1, count + 1)
    state = (states["body_com_lvlh"][-1, 0], states["body_to_lvlh"][-1, 0], states["body_velocity_lvlh"][-1, 0],
             states["body_omega_body"][-1, 0])
    return (state, *track_model_free(scene, frames))


def track_model_free(scene: Scene, frames: Frames):
    """The observation's scans (``frames.scans``) tracked without a model
    (:func:`perception.scan_to_map.track_scans`); ``frames.rotation_error`` (re)scored against the
    truth mapped into the first scan's frame B.

    Parameters
    ----------
    scene : Scene
        The case's scene (registration settings; truth for the errors).
    frames : Frames
        Observation frames with their scans (m, world) and truth.

    Returns
    -------
    tracker : perception.registration.DebrisTracker
        Tracker with the map (frame B, m) as its model and the track's alignments.
    target_to_body : (4, 4) float
        Truth's target -> B transform (m for the translation); identity when no frame registered.
    """
    p = scene.case.perception
    com_target = scene.truth["com_target"]
    origins = [com - rot @ com_target for rot, com in zip(frames.true_target_to_world, frames.true_com_world)]
    reg = p.registration
    track = track_scans(frames.scans, reg.voxel, reg.max_correspondence)
    if reg.map_second_pass:
        thin = [thinned_scan(scan, reg.voxel) if len(scan) else np.zeros((0, 3)) for scan in frames.scans]
        track = registered_again(track, thin, reg.max_correspondence)
    # No registered frame (e.g. empty scans): no map; the fits below answer "not observable".
    tracker = DebrisTracker(reg.voxel, reg.max_correspondence, reg.model_frames,
                            *((track.map_points, track.map_normals) if track.ok.any() else ()), seed=p.seed,
                            free_space_lateral_bins=MAP_LATERAL_BINS, **_search_budget(reg))
    tracker.alignments = map_alignments(track, frames.time)
    target_to_body = np.eye(4)
    if track.ok.any():
        first = int(np.flatnonzero(track.ok)[0])
        target_to_body = track.world_to_body[first] @ _pose(frames.true_target_to_world[first], origins[first])
    frames.rotation_error = [rotation_error(alignment.body_to_world[:3, :3], true_rot @ target_to_body[:3, :3].T,
                                            [np.eye(3)]) if alignment.ok else np.nan
                             for alignment, true_rot in zip(tracker.alignments, frames.true_target_to_world)]
    return tracker, target_to_body


def _search_budget(registration) -> dict:
    """The tracker's CPU limits of the search for a lost track (``perception.registration``'s
    ``search_cpu_per_frame`` and ``search_cpu_per_run``, s) and its continuity limit of a
    re-acquisition (``reacquire_continuity_turn``, rad) and the frames a candidate chain may miss
    (``reacquire_chain_missed_frames``) and whether confirmed frames grow the map after a re-acquisition
    (``reacquire_grow_map``), as keyword arguments of
    :class:`perception.registration.DebrisTracker`."""
    return {"search_cpu_per_frame": registration.search_cpu_per_frame,
            "search_cpu_per_run": registration.search_cpu_per_run,
            "continuity_turn": registration.reacquire_continuity_turn,
            "chain_missed_frames": registration.reacquire_chain_missed_frames,
            "grow_map": registration.reacquire_grow_map}


def _search_budget_figures(tracker: DebrisTracker, frames: Frames) -> dict:
    """The search budget, what was spent of it (CPU s) and the frames it left not registered (their
    times, s; phase 0 observation, 1 collision)."""
    cut = [i for i, alignment in enumerate(tracker.alignments) if alignment.over_budget]
    return {"cpu_per_frame_s": tracker.search_cpu_per_frame, "cpu_per_run_s": tracker.search_cpu_per_run,
            "cpu_spent_s": tracker.search_cpu_spent,
            "frames_searched": int(sum(alignment.searched for alignment in tracker.alignments)),
            "frames_not_registered": len(cut),
            "frames_not_registered_times_s": [round(float(frames.time[i]), 3) for i in cut],
            "frames_not_registered_phases": [int(frames.phase[i]) for i in cut]}


def _name_budget_cuts(answer: dict) -> None:
    """Add to an answer "not observable" after the collision how many collision frames the search
    budget left not registered (read from ``answer['search_budget']``): more search time might have
    found the debris again."""
    cut = answer["search_budget"]["frames_not_registered_phases"].count(1)
    if cut and answer["not_observable"]:
        answer["not_observable"] += (f" ({cut} collision frames not registered: the search budget of "
                                     f"perception.registration was spent)")


def check_model(scene: Scene, tracker: DebrisTracker, frames: Frames) -> ModelCheck:
    """Residuals of the observation's registered scans against the model the tracker was given
    (:mod:`perception.model_mismatch`): every CHECK_EVERY-th registered frame, the share of its
    returns off the posed model and the share of the posed model's predicted returns (the model
    ray-cast from the frame's sensor pose, no noise) not in the scan.

    Parameters
    ----------
    scene : Scene
        The case's scene (the model mesh, target frame; the LiDAR).
    tracker : perception.registration.DebrisTracker
        The known-model tracker after the observation.
    frames : Frames
        Observation frames with their scans and sensor poses.

    Returns
    -------
    perception.model_mismatch.ModelCheck
    """
    gate_m = gate(scene.spec.range_noise)
    model = scene.model_mesh_target
    vertices, faces = np.asarray(model.vertices), np.asarray(model.faces)
    distance = SurfaceDistance(vertices, faces)
    noiseless = dataclasses.replace(scene.spec, range_noise=0.0)
    # frames without returns to register (debris out of range, an empty scan) say nothing of the model
    observed = [k for k, phase in enumerate(frames.phase)
                if phase == 0 and k < len(tracker.alignments) and frames.n_points[k] >= MIN_POINTS]
    registered = [k for k in observed if tracker.alignments[k].ok]
    unexplained, unseen = [], []
    for k in registered[::CHECK_EVERY]:
        scan = frames.scans[k]
        pose = tracker.alignments[k]
        unexplained.append(unexplained_share(scan @ pose.world_to_body[:3, :3].T + pose.world_to_body[:3, 3],
                                             distance, gate_m))
        body_to_world = pose.body_to_world
        predicted = cast(noiseless, [((vertices @ body_to_world[:3, :3].T + body_to_world[:3, 3]
                                       - frames.sensor_poses[k][0]) @ frames.sensor_poses[k][1], faces)],
                         frames.time[k], np.random.default_rng(0)).points_sensor
        predicted_world = predicted @ frames.sensor_poses[k][1].T + frames.sensor_poses[k][0]
        unseen.append(unseen_share(predicted_world, scan, gate_m))
    return model_check(len(observed), len(registered), unexplained, unseen, gate_m)


def _record(frames, t, phase, points, true_rot, true_com):
    """A frame's time (s), phase, return count and truth (target -> world rotation, CoM in m, world)."""
    frames.time.append(t)
    frames.phase.append(phase)
    frames.n_points.append(len(points))
    frames.true_target_to_world.append(true_rot)
    frames.true_com_world.append(true_com)


def _register(tracker, frames, t, phase, points, sensor_world, true_rot, true_com, symmetries, target_to_body=np.eye(3),
              all_returns=None, sensor_to_world=None):
    """Register a scan (a tiny one is recorded as failed by the tracker) and score it against the
    true attitude (target -> world ``true_rot``; ``target_to_body`` (3, 3) the truth's rotation into
    the tracker's frame B: identity when B is the target frame). ``all_returns`` (m, 3) (m, world):
    every return of the frame when ``points`` is the debris' share of them, for the free-space check;
    ``sensor_to_world`` (3, 3): the sensor's attitude, for the unseen-model check."""
    alignment = tracker.update(t, points, sensor_world, all_returns_world=all_returns, sensor_to_world=sensor_to_world)
    _record(frames, t, phase, points, true_rot, true_com)
    frames.rotation_error.append(rotation_error(alignment.body_to_world[:3, :3], true_rot @ target_to_body.T, symmetries)
                                 if alignment.ok else np.nan)
    for index in tracker.revised:   # frames of a re-acquisition the following frames' motion confirmed
        revised = tracker.alignments[index]
        frames.rotation_error[index] = (rotation_error(revised.body_to_world[:3, :3],
                                                       frames.true_target_to_world[index] @ target_to_body.T, symmetries)
                                        if revised.ok else np.nan)


# ------------------------------------------------------------------------------ estimation
def _good(tracker, select) -> np.ndarray:
    ok = np.array([a.ok for a in tracker.alignments])
    return np.flatnonzero(ok & select)


# ------------------------------------------------------------------------------ phase 2
def collision_case(case: Case, com_target, com, body_to_world, velocity, omega_body, rate) -> Case:
    """The case's collision run started from the observed tumble's end state (the debris CoM at
    ``com_target`` in the target frame), the net snapshots at the LiDAR's frame rate.

    Parameters
    ----------
    case : Case
        The perception case.
    com_target : (3,) float
        Debris CoM, target frame (m).
    com : (3,) float
        Debris CoM at time 0, world (LVLH) frame (m).
    body_to_world : (3, 3) float
        Debris target -> world rotation at time 0.
    velocity : (3,) float
        CoM velocity, world frame (m/s).
    omega_body : (3,) float
        Angular velocity, target (body) frame (rad/s).
    rate : float
        LiDAR frame rate (Hz): net snapshot rate, lower bound of the output rate.

    Returns
    -------
    Case
        A copy of ``case`` with the target's start state and output rates replaced.
    """
    origin = com - body_to_world @ com_target
    omega_world = body_to_world @ omega_body
    target = case.target.model_copy(update={
        "position_lvlh": origin.tolist(), "attitude_rotation_vector": Rotation.from_matrix(body_to_world).as_rotvec().tolist(),
        "velocity_lvlh": (velocity - np.cross(omega_world, com - origin)).tolist(), "angular_velocity": list(omega_body)})
    simulation = case.simulation.model_copy(update={"net_output_rate": rate,
                                                    "output_rate": max(case.simulation.output_rate, rate)})
    return case.model_copy(update={"target": target, "simulation": simulation})


@dataclass
class NetTrack:
    times: list = field(default_factory=list)
    positions: list = field(default_factory=list)
    n_points: list = field(default_factory=list)
    separation: list = field(default_factory=list)
    true_positions: list = field(default_factory=list)


def observe_collision(scene, tracker, frames, symmetries, rng, recorder, assembly, progress=None,
                      target_to_body=np.eye(4), com_body=None) -> NetTrack:
    """Scan debris and net from the chaser through the collision run; register the debris, fit
    the net's nodes, measure the gap between them. ``target_to_body`` (4, 4): the truth's
    transform into the tracker's frame B, for the error figures. The pan-tilt mount aims at the
    debris CoM ``com_body`` predicted from the track, carried by its velocity through a lost track
    and widened into a search when nothing is seen (:class:`perception.pointing.Pointing`).

    Parameters
    ----------
    scene : Scene
        Sensor, debris model and truth of the case.
    tracker : perception.registration.DebrisTracker
        Tracker of the observation phase; the collision scans are registered into it.
    frames : Frames
        Per-frame record, appended to (time in s, truth in the world frame).
    symmetries : list of (3, 3) float
        Rotations of the indistinguishable attitudes, for the error figures.
    rng : numpy.random.Generator
        Range noise of the LiDAR.
    recorder : multibody.recorder.Recorder
        The collision run's record: body series (``body_to_lvlh``, ``body_com_lvlh``; m, LVLH = world)
        and net snapshots (``time`` in s, ``positions_lvlh`` (k, n, 3) in m).
    assembly : multibody.assembly.ImpactAssembly
        The collision run's bodies, chaser, net and mount (design values the estimator may use).
    progress : callable, optional
        ``progress(phase, done, total)`` after each frame (``phase`` a str, counts in frames).
    target_to_body : (4, 4) float
        Truth's target -> B transform (m for the translation).
    com_body : (3,) float, optional
        Debris CoM in frame B (m), from the observation's CoM line; default the model's centroid.

    Returns
    -------
    NetTrack
        Per collision frame: time (s), fitted net nodes (n, 3) (m, world), returns used, gap
        debris-net (m; NaN without a debris pose) and the true nodes (m, world).
    """
    series, net_snapshots = recorder.series, recorder.net
    net = assembly.net
    chaser, mount = assembly.chaser, assembly.mount
    com_target = scene.truth["com_target"]
    radius = 0.5 * scene.case.net.thread.diameter
    track = NetTrack()
    series_time = series["time"]
    model_sample = tracker.model_points_body[:: max(1, len(tracker.model_points_body) // 800)]
    previous_chaser = None
    estimate = net.positions.copy()
    times = net_snapshots["time"]
    pointing = _pointing(tracker, frames, com_body)
    keep_returns = scene.case.perception.registration.after_frames_scan_to_scan
    # The mount turns through the run: a lost track is searched over all attitudes, and a box-like
    # debris' half turns pass the surface checks; the directions where the rays met nothing tell them
    # apart (perception.visibility.unseen_model_share).
    tracker.field_of_view = np.array([scene.spec.fov_azimuth, scene.spec.fov_elevation])
    tracker.ray_spacing = max(scene.spec.resolution_azimuth, scene.spec.resolution_elevation)
    # the debris' reach about its CoM (m), plus a margin for the map's and the scan's errors
    radius_body = float(np.max(np.linalg.norm(tracker.model_points_body - pointing.com_body, axis=1))) + BLOB_MARGIN
    for k, t in enumerate(times):
        if t <= 0.0:
            continue   # the observation's last frame is this instant
        i = int(np.argmin(np.abs(series_time - t)))
        chaser_pose = _pose(series["body_to_lvlh"][i, chaser], series["body_com_lvlh"][i, chaser])
        rot, com = series["body_to_lvlh"][i, 0], series["body_com_lvlh"][i, 0]
        true_net = net_snapshots["positions_lvlh"][k]
        sensor_world, body_fixed = scene.sensor_pose(chaser_pose[:3, 3], chaser_pose[:3, :3])
        sensor_world, sensor_to_world = scene.sensor_pose(chaser_pose[:3, 3], chaser_pose[:3, :3],
                                                          pointing.aim(t, sensor_world, body_fixed[:, 2]))
        tic = time.perf_counter()
        points, _ = _scan_world(scene, [(scene.debris_vertices_world(rot, com - rot @ com_target), scene.mesh_target.faces),
                                        thread_mesh(true_net, net.threads, radius)],
                                sensor_world, sensor_to_world, t, rng)
        frames.cast_seconds.append(time.perf_counter() - tic)
        points = _thinned(points, 0.5 * tracker.voxel)
        # The net is predicted by carrying the last estimate with the chaser; returns on the
        # predicted threads are not offered to the debris registration.
        start_pose = previous_chaser if previous_chaser is not None else _pose(np.eye(3), assembly.bodies[chaser].com_lvlh)
        predicted = carried_by_chaser(estimate, start_pose, chaser_pose)
        on_net = nearest_segments(points, predicted, net.threads)[2] < NET_GATE if len(points) else np.zeros(0, bool)
        debris_points, blob = _debris_returns(tracker, pointing, t, points[~on_net], radius_body)
        if keep_returns:
            frames.debris_returns[len(frames.time)] = debris_points
        _register(tracker, frames, t, 1, debris_points, sensor_world, rot, com,
                  symmetries, target_to_body[:3, :3], all_returns=points, sensor_to_world=sensor_to_world)
        alignment = tracker.alignments[-1]
        pointing.record(t, alignment.body_to_world if alignment.ok else None, len(debris_points) >= MIN_POINTS, blob)
        # The net's nodes are fitted to the returns the debris does not explain, the rim held at
        # the rod tips; with the debris lost, to those outside the ball its returns were found in
        # (all returns went into the net fit before, which pulled the net onto the debris and
        # the next frames' net gate then took the debris' returns for net).
        debris_world = model_sample @ alignment.body_to_world[:3, :3].T + alignment.body_to_world[:3, 3]
        near_debris = cKDTree(debris_world).query(points, distance_upper_bound=2 * tracker.voxel)[0]
        if alignment.ok:
            candidates = points[~np.isfinite(near_debris)]
        else:
            candidates = points if blob is None else points[np.linalg.norm(points - blob, axis=1) > radius_body]
        tips = mount.points_body @ chaser_pose[:3, :3].T + chaser_pose[:3, 3]
        fit = fit_net_nodes(candidates, predicted, net.threads, NetPrior(point=max(scene.spec.range_noise, radius)),
                            anchors=(mount.nodes, tips))
        estimate = fit.positions_world
        previous_chaser = chaser_pose
        track.times.append(t)
        track.positions.append(estimate)
        track.n_points.append(fit.n_points)
        track.true_positions.append(true_net)
        track.separation.append(float(nearest_segments(debris_world, estimate, net.threads)[2].min())
                                if alignment.ok else np.nan)   # unknown without a debris pose
        for index in tracker.revised:   # frames a re-acquisition confirmed after the fact: their debris pose
            revised = tracker.alignments[index].body_to_world
            before = index - (len(tracker.alignments) - len(track.separation))
            if before < 0:   # an observation frame (a chain begun before the run in): no net gap
                continue
            track.separation[before] = float(nearest_segments(model_sample @ revised[:3, :3].T + revised[:3, 3],
                                                              track.positions[before], net.threads)[2].min())
        if progress:
            progress("collision", k, len(times) - 1)
    return track


def _debris_returns(tracker: DebrisTracker, pointing: Pointing, time_s, points_world, radius):
    """The returns offered to the debris registration (m, world) and, when its track is lost, the
    centre of the ball they were taken from (m, world; else None). With a motion prediction: the
    returns near the predicted surface (:func:`_crop_to_predicted`). Without: the densest ball of
    the debris' ``radius`` (m) about its predicted CoM and where it was last seen
    (:func:`perception.pointing.debris_blob`), so that the search and the next frame's aim take the
    debris, not net threads the net prediction missed (featured debris, 1.0-2.0 s after the start of
    the run in: 91-97 % of the returns in the ball are the debris')."""
    if tracker.prediction()[1] or not len(points_world):
        return _crop_to_predicted(tracker, points_world), None
    centre, inside = debris_blob(points_world, (pointing.predicted_com(time_s), pointing.seen_world), radius)
    return points_world[inside], centre


def _pointing(tracker: DebrisTracker, frames: Frames, com_body=None) -> Pointing:
    """The collision phase's mount aim, started with the observation's good frames (their CoM
    track gives the velocity the debris has when the run in starts)."""
    com_body = tracker.model_points_body.mean(axis=0) if com_body is None else np.asarray(com_body, float)
    pointing = Pointing(com_body)
    for t, alignment in zip(frames.time, tracker.alignments):
        if alignment.ok:
            pointing.record(t, alignment.body_to_world, True)
    return pointing


def free_flight_start(track: NetTrack) -> int:
    """Index (into the collision frames) from which the debris stays clear of the net.

    A run of frames whose debris registration failed has no measured gap. It counts as touching
    when a measured frame next to it touches (during the contact the failures are the net
    covering the debris), as clear otherwise: a failure between two clear frames, with the net
    metres away, is a registration failure and says nothing about contact (one such frame 7 s
    after the contact once cut the free flight from 10.5 s to 4.5 s).

    Parameters
    ----------
    track : NetTrack
        Collision frames with the debris-net gap ``separation`` (m; NaN where unmeasured).

    Returns
    -------
    int
        Index of the first free-flight frame; :class:`NotObservable` when the debris never
        touched the net or still touches it at the end.
    """
    separation = np.asarray(track.separation, float)
    measured = np.flatnonzero(np.isfinite(separation))
    if len(measured) == 0 or separation[measured[-1]] <= SEPARATION:
        raise NotObservable("the debris is still touching the net (or its registration fails) at the end of the "
                            "collision run; lengthen simulation.end_time")
    if not np.any(separation[measured] <= SEPARATION):
        raise NotObservable("the net never came near the debris: the collision transferred no momentum")
    touching = _touching_through_failures(separation)
    # The contact may end between frames and the gap is measured on an estimated net: the first
    # clear frame is a margin, free flight is taken from the second.
    return int(np.flatnonzero(touching)[-1] + 2)


def _touching_through_failures(separation) -> np.ndarray:
    """Per frame: touching (gap <= SEPARATION); a run of failed frames (NaN gap) takes
    'touching' when a measured neighbour of the run touches."""
    touching = separation <= SEPARATION          # NaN compares False
    failed = ~np.isfinite(separation)
    edges = np.flatnonzero(np.diff(np.r_[0, failed.astype(np.int8), 0]))
    for start, stop in zip(edges[::2], edges[1::2]):
        near = (start > 0 and touching[start - 1]) or (stop < len(touching) and touching[stop])
        touching[start:stop] = near
    return touching


# ------------------------------------------------------------------------------ momentum step
def others_momentum_after(assembly, recorder, track, frame_times, origin):
    """Chaser (navigation) + net (tracked nodes) linear and angular momentum about ``origin`` at
    each free-flight frame: (k, 3), (k, 3).

    Parameters
    ----------
    assembly : multibody.assembly.ImpactAssembly
        Chaser (mass kg, inertia kg m^2 body frame) and net node masses (kg).
    recorder : multibody.recorder.Recorder
        The collision run's body series (the chaser's navigation; m, m/s, rad/s, LVLH = world).
    track : NetTrack
        Tracked net nodes per collision frame (m, world).
    frame_times : (k,) float
        Free-flight frame times (s).
    origin : (3,) float
        Point the angular momentum is taken about, world frame (m).

    Returns
    -------
    linear : (k, 3) float
        Linear momentum, world frame (N s).
    angular : (k, 3) float
        Angular momentum about ``origin``, world frame (N m s).
    """
    series = recorder.series
    chaser = assembly.bodies[assembly.chaser]
    track_times = np.asarray(track.times)
    velocities = node_velocities(track_times, np.asarray(track.positions))
    linear, angular = [], []
    for t in frame_times:
        i = int(np.argmin(np.abs(series["time"] - t)))
        j = int(np.argmin(np.abs(track_times - t)))
        c = assembly.chaser
        p_c, l_c = rigid_body_momentum(chaser.mass, chaser.inertia_body, series["body_com_lvlh"][i, c],
                                       series["body_velocity_lvlh"][i, c], series["body_to_lvlh"][i, c],
                                       series["body_omega_body"][i, c], origin)
        p_n, l_n = point_masses_momentum(assembly.net.masses, track.positions[j], velocities[j], origin)
        linear.append(p_c + p_n)
        angular.append(l_c + l_n)
    return np.array(linear), np.array(angular)


def others_momentum_before(assembly, origin):
    """Chaser + net momentum at the start of the run in, from their design launch state.

    Parameters
    ----------
    assembly : multibody.assembly.ImpactAssembly
        Chaser and net at launch (m, m/s, rad/s; LVLH = world frame).
    origin : (3,) float
        Point the angular momentum is taken about, world frame (m).

    Returns
    -------
    linear : (3,) float
        Linear momentum, world frame (N s).
    angular : (3,) float
        Angular momentum about ``origin``, world frame (N m s).
    """
    chaser = assembly.bodies[assembly.chaser]
    p_c, l_c = rigid_body_momentum(chaser.mass, chaser.inertia_body, chaser.com_lvlh, chaser.velocity_lvlh,
                                   chaser.body_to_lvlh, chaser.omega_body, origin)
    p_n, l_n = point_masses_momentum(assembly.net.masses, assembly.net.positions, assembly.net_velocity, origin)
    return p_c + p_n, l_c + l_n


# ------------------------------------------------------------------------------ the stage
def _percent(estimate, truth):
    return (np.asarray(estimate, float) / np.asarray(truth, float) - 1.0) * 100.0


def estimates(scene: Scene, before: FreeMotion, after: FreeMotion | None, step: dict | None,
              state_at_zero, target_to_body=np.eye(4), frame: str | None = None) -> dict:
    """The perception answer: estimates with 1-sigma uncertainties and, since the case knows the
    truth, their errors. ``target_to_body`` (4, 4): the truth's transform into the tracker's frame B
    (identity with the known mesh; with ``perception.model = 'none'`` B is the first scan's frame and
    the frame-dependent estimates are named ``..._first_scan_...``).

    Parameters
    ----------
    scene : Scene
        The case's scene (its truth for the errors).
    before : FreeMotion
        Free-flight fit of the observation (CoM in frame B, normalized inertia, spin per C).
    after : FreeMotion or None
        Free-flight fit after the collision (unused here; the momentum step holds its result).
    step : dict or None
        :func:`perception.momentum_balance.momentum_step` result (``mass`` in kg, ``c`` the
        smallest principal moment in kg m^2); None when not observable.
    state_at_zero : tuple of (3,), (3, 3), (3,), (3,) float
        True debris CoM (m, world), body -> world rotation, velocity (m/s, world) and angular
        velocity (rad/s, body frame) at time 0.
    target_to_body : (4, 4) float
        Truth's target -> B transform (m for the translation).
    frame : str, optional
        Name of B in the keys: 'target' (tracked with the mesh) or 'first_scan' (without);
        default from ``perception.model``.

    Returns
    -------
    dict
        The estimates, 1-sigma values and errors; each key names its unit and frame.
    """
    fit = before.fit
    com_body = before.line.com_body
    truth = scene.truth
    frame = frame or ("target" if scene.case.perception.model == "known" else "first_scan")
    com_truth_body = target_to_body[:3, :3] @ truth["com_target"] + target_to_body[:3, 3]
    true_moments = np.linalg.eigvalsh(truth["inertia_target"])[::-1]
    true_ratios = true_moments / true_moments[-1]
    _, rotation_true, _, omega_true = state_at_zero
    j_true = truth["inertia_target"]
    c_true = true_moments[-1]
    normalized = normalized_energy_and_momentum(before)
    true_l = rotation_true @ (j_true @ omega_true)
    out = {
        f"center_of_mass_{frame}_m": com_body.tolist(),
        "center_of_mass_std_m": np.sqrt(np.diag(before.line.covariance)[:3]).tolist(),
        "center_of_mass_error_m": float(np.linalg.norm(com_body - com_truth_body)),
        "inertia_ratios": fit.moments_[:2].tolist(),
        "inertia_ratios_std": fit.moments_std_.tolist(),
        "inertia_ratio_error_percent": _percent(fit.moments_[:2], true_ratios[:2]).tolist(),
        f"principal_axes_{frame}": fit.principal_to_body_.tolist(),
        "normalized_kinetic_energy_D_rad2_s2": normalized["D"],
        "normalized_kinetic_energy_error_percent": float(_percent(normalized["D"], omega_true @ j_true @ omega_true / c_true)),
        "normalized_angular_momentum_F_rad2_s2": normalized["F"],
        "normalized_angular_momentum_error_percent": float(_percent(normalized["F"], true_l @ true_l / c_true**2)),
        "angular_momentum_direction_world": normalized["direction_world"].tolist(),
        "angular_momentum_direction_error_deg": float(np.degrees(np.arccos(np.clip(
            normalized["direction_world"] @ true_l / np.linalg.norm(true_l), -1, 1)))),
        "true_mass_kg": truth["mass"],
        "true_principal_moments_kg_m2": true_moments.tolist(),
    }
    if step is None:
        return out
    mass, c = step["mass"], step["c"]
    moments = c.value * fit.moments_
    moments_std = np.sqrt((fit.moments_ * c.sigma) ** 2 + (c.value * np.r_[fit.moments_std_, 0.0]) ** 2)
    axes = fit.principal_to_body_
    energy = 0.5 * c.value * normalized["D"]
    out.update({
        # the scripting keys: estimates, and error magnitudes (largest over the moments)
        "mass_estimate": mass.value, "inertia_estimate": moments.tolist(),
        "mass_error_percent": float(abs(_percent(mass.value, truth["mass"]))),
        "inertia_error_percent": float(np.max(np.abs(_percent(moments, true_moments)))),
        "mass_kg": mass.value, "mass_std_kg": mass.sigma,
        "mass_error_signed_percent": float(_percent(mass.value, truth["mass"])),
        "principal_moments_kg_m2": moments.tolist(), "principal_moments_std_kg_m2": moments_std.tolist(),
        "principal_moments_error_percent": _percent(moments, true_moments).tolist(),
        f"inertia_{frame}_kg_m2": (axes @ np.diag(moments) @ axes.T).tolist(),
        "kinetic_energy_rotational_J": energy,
        "angular_momentum_world_N_m_s": (c.value * before.spin_per_c).tolist(),
        "linear_balance_misfit_N_s": mass.misfit, "angular_balance_misfit_N_m_s": c.misfit,
        "linear_balance_chi2": mass.chi2, "angular_balance_chi2": c.chi2,
    })
    return out


def _timing(tracker: DebrisTracker, frames: Frames) -> dict:
    """Registration time per frame of the tracked observation frames (the first frame's global
    search apart), and of the collision frames (re-acquisitions after contact included)."""
    seconds = np.array([a.seconds for a in tracker.alignments])
    cpu = np.array([a.cpu_seconds for a in tracker.alignments])
    phase = np.array(frames.phase)
    tracked = (phase == 0) & (np.arange(len(phase)) > 0)
    return {"registration_ms_per_frame": float(1e3 * seconds[tracked].mean()),
            "registration_cpu_ms_per_frame": float(1e3 * cpu[tracked].mean()),
            "registration_cpu_ms_median": float(1e3 * np.median(cpu[tracked])),
            "registration_ms_p95": float(1e3 * np.percentile(seconds[tracked], 95)),
            "first_frame_search_s": float(seconds[0]),
            "collision_registration_ms_per_frame": float(1e3 * seconds[phase == 1].mean()) if (phase == 1).any() else None,
            "ray_casting_ms_per_frame": float(1e3 * np.mean(frames.cast_seconds))}


def _tracking_figures(tracker, frames) -> dict:
    ok = np.array([a.ok for a in tracker.alignments])
    phase = np.array(frames.phase)
    error = np.degrees(np.array(frames.rotation_error, float))
    figures = {}
    for name, select in (("observation", phase == 0), ("collision", phase == 1)):
        good = error[select & ok]
        figures[name] = {"frames": int(select.sum()), "registered": int((select & ok).sum()),
                         "rotation_error_mean_deg": float(np.mean(good)) if len(good) else None,
                         "rotation_error_p95_deg": float(np.percentile(good, 95)) if len(good) else None}
    return figures


def perceive_case(case_path, out_dir, progress=None, case: Case | None = None, overwrite: bool = False,
                  pending=()) -> dict:
    """Run the perception stage of a case into ``out_dir`` (see module docstring; the folder is
    claimed by :func:`riskassess.products.outfolder.claim`, ``pending`` as in :func:`riskassess.stages.run.run_case`);
    returns the content of perception.json. A quantity the data cannot determine is reported under
    ``not_observable`` with the reason, never as a number.

    Parameters
    ----------
    case_path : str or Path
        The case file (TOML).
    out_dir : str or Path
        Output folder (claimed; never overwrites a user's file).
    progress : callable, optional
        ``progress(phase, done, total)``: frames for ``observation``/``collision``, simulated
        time (s) for ``simulation``.
    case : Case, optional
        The case already loaded from ``case_path``.
    overwrite : bool
        Replace a previous run's folder.
    pending : sequence
        As in :func:`riskassess.stages.run.run_case`.

    Returns
    -------
    dict
        The content of perception.json (SI units; frames named in the keys).
    """
    case_path = Path(case_path)
    case = case or load_case(case_path)
    scene = Scene.from_case(case, case_path.parent, str(case_path))
    folder = begin_run_folder(Path(out_dir), case_path, case, overwrite, "perceive")
    with folder.recording():
        return _perceive(case, scene, folder, progress, pending)


def _check_fit_explains_track(motion: FreeMotion) -> None:
    """Raise NotObservable when the torque-free fit does not explain the registered attitudes (more
    than MAX_MODEL_FREE_RESIDUAL_DEG rms) even from its other starts (perception/free_flight.py): the
    fit stopped in a wrong optimum. Measured on the featured debris with its mesh (seed 1, 20 s): every
    frame within 2.4 deg of the truth, the fit 103 deg rms from them, its ratios 18 % and D 6 times off;
    after the collision of the paper case (seed 0) a fit 96 deg rms off made the spin change look
    uncertain (1.2 rad/s) instead of wrong (docs/perception.md)."""
    if motion.attitude_residual_deg <= MAX_MODEL_FREE_RESIDUAL_DEG:
        return
    raise NotObservable(
        f"the torque-free fit does not explain the registered attitudes ({motion.attitude_residual_deg:.1f} deg rms, "
        f"at most {MAX_MODEL_FREE_RESIDUAL_DEG}): the fit did not converge to the tumble")


def _check_model_free_track(before: FreeMotion) -> None:
    """Raise NotObservable when a model-free track does not pin the tumble down: attitudes not
    explained by a torque-free motion, or inertia ratios left undetermined by it."""
    ratio_sigma = float(np.max(before.fit.moments_std_ / before.fit.moments_[:2]))
    if before.attitude_residual_deg <= MAX_MODEL_FREE_RESIDUAL_DEG and ratio_sigma <= MAX_MODEL_FREE_RATIO_SIGMA:
        return
    raise NotObservable(
        f"the model-free track does not determine the tumble (attitudes {before.attitude_residual_deg:.1f} deg rms "
        f"from the torque-free fit, at most {MAX_MODEL_FREE_RESIDUAL_DEG}; inertia ratios 1-sigma "
        f"{100 * ratio_sigma:.1f} %, at most {100 * MAX_MODEL_FREE_RATIO_SIGMA:.0f} %): the shape has too few features "
        "for scan-to-map registration without its mesh; use perception.model = 'known'")


#: Frames after which the known model is checked against the scans (3 s at 10 Hz: 6 checked frames);
#: a model found wrong then is not used for the rest of the observation (observe_tumble).
EARLY_CHECK_FRAMES = 30
#: A CoM measured this many of its 1-sigma from the model's (and more than MIN_COM_OFFSET) says the
#: model's mass distribution is wrong even where its shape is right.
COM_OFFSET_SIGMAS = 5.0
MIN_COM_OFFSET = 0.01   # m; the CoM line's own bias on a matching model is ~0.1-3 mm (docs/perception.md)


def _model_center_of_mass_offset(scene: Scene, before: FreeMotion) -> dict:
    """The measured CoM against the model's (target frame, with the mesh tracker): the offset (m), its
    size in the measurement's 1-sigma, and a statement when the model's mass distribution is off. The
    estimates themselves never use the model's CoM (the CoM is the body point on a straight line)."""
    body = scene.case.target.bodies[0]
    model_com = np.asarray(body.center_of_mass if body.center_of_mass is not None
                           else scene.model_mesh_target.center_mass, float)
    offset = before.line.com_body - model_com
    sigma = float(np.sqrt(max(np.trace(before.line.covariance[:3, :3]), 1e-18)))
    out = {"model_center_of_mass_offset_m": offset.tolist(), "model_center_of_mass_offset_sigmas":
           float(np.linalg.norm(offset) / sigma)}
    if np.linalg.norm(offset) > max(COM_OFFSET_SIGMAS * sigma, MIN_COM_OFFSET):
        out["model_mass_mismatch"] = (f"the measured CoM is {1e3 * np.linalg.norm(offset):.0f} mm from the model's "
                                      f"({np.linalg.norm(offset) / sigma:.0f} sigma): the model's mass distribution "
                                      "does not match the debris (the estimates use the measured CoM)")
    return out


def _perceive(case: Case, scene: Scene, folder, progress, pending) -> dict:
    """The stage's body (module docstring) into the claimed ``folder``."""
    p = case.perception
    rng = np.random.default_rng(p.seed)
    frames = Frames()
    wall = time.perf_counter()
    target_to_body = np.eye(4)
    # Open3D's RANSAC warnings go to stdout, which --json keeps for the answer.
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        if p.model == "known":
            symmetry_transforms = half_turn_symmetry_transforms(scene.model_mesh_target, 0.5 * p.registration.voxel)
            tracker = DebrisTracker(p.registration.voxel, p.registration.max_correspondence, p.registration.model_frames,
                                    *known_shape_model(scene.model_mesh_target, p.registration.voxel, p.seed),
                                    symmetries_body=symmetry_transforms, seed=p.seed, **_search_budget(p.registration))
            symmetries = [transform[:3, :3] for transform in symmetry_transforms]
            state_at_zero, check = observe_tumble(scene, tracker, frames, symmetries, rng, progress, EARLY_CHECK_FRAMES)
        else:
            # No mesh: no known symmetries either (the map's are not those of a catalogued shape).
            symmetries = [np.eye(3)]
            state_at_zero, tracker, target_to_body = observe_tumble_model_free(scene, frames, rng, progress)
        model_free = p.model == "none"
        answer = {"case": case.name, "perception_model": p.model, "observation_time_s": p.observation_time,
                  "not_observable": None}
        if p.model == "known":
            answer["model_check"] = check.as_dict()
            if check.mismatch:
                # The mesh does not explain the scans: track them again without it.
                answer["model_mismatch"] = ("the debris model of [target] does not match the scanned debris: "
                                            + "; ".join(check.reasons) + ". Tracked again without the model "
                                            "(scan to map, perception.model = 'none'); the estimates are in the "
                                            "first scan's frame")
                symmetries = [np.eye(3)]
                tracker, target_to_body = track_model_free(scene, frames)
                model_free = True
    answer["body_frame"] = "first_scan" if model_free else "target"
    answer["tracked_with"] = "scan-to-map" if model_free else "model"
    before = after = step = None
    try:
        before = fit_free_motion(tracker, _good(tracker, np.array(frames.phase) == 0), frames.time)
        answer["attitude_fit_residual_deg"] = before.attitude_residual_deg
        if model_free:
            _check_model_free_track(before)
        else:
            _check_fit_explains_track(before)
            answer.update(_model_center_of_mass_offset(scene, before))
    except NotObservable as exc:
        # Nothing to scale by the collision: stop before simulating it.
        answer["not_observable"] = f"before the collision: {exc}"
        return _conclude(folder, answer, tracker, frames, NetTrack(), None, wall, pending)
    tic = time.process_time()
    observation = (_observation_partners(tracker, frames, p.registration)
                   if model_free and p.registration.after_frames_scan_to_scan else None)
    if observation is not None:   # once, before the collision: the partners' normals, cells, poses in B
        answer["after_frames_partners_cpu_s"] = time.process_time() - tic
    frames.scans, frames.sensor_poses = [], []   # not needed beyond the observation

    collision = collision_case(scene.real_case, scene.truth["com_target"], *state_at_zero, scene.spec.rate)
    inputs = model_inputs(collision, scene.base)
    simulation = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    recorder = run_recorded(simulation, folder, progress=(lambda t: progress("simulation", t, case.simulation.end_time))
                            if progress else None)
    write_simulation(folder, recorder, simulation, collision)
    assembly = simulation.assembly
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        track = observe_collision(scene, tracker, frames, symmetries, rng, recorder, assembly, progress, target_to_body,
                                  before.line.com_body)
    times = np.array(frames.time)
    try:
        start_time = track.times[free_flight_start(track)]
        free_flight = _good(tracker, times >= start_time - 1e-9)
        reposed = None
        if observation is not None:
            reposed = _posed_scan_to_scan(tracker, frames, free_flight, observation, p.registration, target_to_body,
                                          symmetries)
            answer.update(_reposed_figures(reposed))
        after = fit_free_motion(tracker, free_flight, times,
                                before.line.com_body, before.fit.moments_, before.fit.principal_to_body_,
                                reposed.attitude_covariance if reposed is not None else None)
        answer["attitude_fit_residual_after_deg"] = after.attitude_residual_deg
        _check_fit_explains_track(after)
        origin = before.line.position_world([0.0])[0]
        others_after = others_momentum_after(assembly, recorder, track, after.times, origin)
        step = momentum_step(before, after, others_momentum_before(assembly, origin), others_after, origin)
        answer["free_flight_after_s"] = [float(after.times[0]), float(after.times[-1])]
        answer["observation_time_s"] = float(p.observation_time + after.times[-1])
    except NotObservable as exc:
        answer["not_observable"] = f"after the collision: {exc}"
    answer.update(estimates(scene, before, after, step, state_at_zero, target_to_body, answer["body_frame"]))
    return _conclude(folder, answer, tracker, frames, track, assembly, wall, pending)


def _observation_partners(tracker: DebrisTracker, frames: Frames, registration) -> ScanPartners:
    """The observation's frames as partners of :func:`perception.scan_to_scan.scan_to_scan_poses`: their thinned
    scans with normals, in B at their tracked poses (:func:`perception.scan_to_scan.scan_partners`)."""
    observed = tracker.alignments[:len(frames.scans)]
    thin = [thinned_scan(scan, registration.voxel) if len(scan) else np.zeros((0, 3)) for scan in frames.scans]
    return scan_partners(np.array([a.world_to_body for a in observed]), scan_clouds(thin, registration.voxel),
                         np.array([a.ok for a in observed]), registration.max_correspondence)


def _posed_scan_to_scan(tracker, frames, indices, partners, registration, target_to_body, symmetries) -> ReposedFrames:
    """Pose the free-flight frames ``indices`` again scan to scan to the observation's scans
    (:func:`perception.scan_to_scan.scan_to_scan_poses`, from their registered poses), keeping each frame's
    information; their attitude errors scored again."""
    starts = {int(k): tracker.alignments[k].world_to_body for k in indices}
    reposed = scan_to_scan_poses({k: frames.debris_returns[k] for k in starts}, starts, partners, registration.voxel)
    for k, pose in reposed.world_to_body.items():
        tracker.alignments[k] = dataclasses.replace(tracker.alignments[k], world_to_body=pose)
        frames.rotation_error[k] = rotation_error(tracker.alignments[k].body_to_world[:3, :3],
                                                  frames.true_target_to_world[k] @ target_to_body[:3, :3].T, symmetries)
    return reposed


def _reposed_figures(reposed: ReposedFrames) -> dict:
    """The answer's figures of the re-posing: frames, CPU (ms a frame) and the partners' pose scatter, 1-sigma
    (deg about each axis of B, rms; m along each, rms)."""
    partner = reposed.partner_covariance()
    frames = max(len(reposed.world_to_body), 1)
    return {"after_frames_scan_to_scan": len(reposed.world_to_body),
            "after_frames_scan_to_scan_ms_per_frame": 1e3 * reposed.cpu_seconds / frames,
            "after_frames_partner_sigma_deg": float(np.degrees(np.sqrt(np.trace(partner[:3, :3]) / 3))),
            "after_frames_partner_sigma_m": float(np.sqrt(np.trace(partner[3:, 3:]) / 3))}


def _conclude(folder, answer, tracker, frames, track: NetTrack, assembly, wall, pending) -> dict:
    """Add the timing and tracking figures (and the net's, after a collision run) to the answer,
    write the perception files and finish the folder: ``complete`` after the collision run (a
    quantity not observable after it is named in the answer), ``not_observable`` before it."""
    answer.update(_timing(tracker, frames))
    answer["tracking"] = _tracking_figures(tracker, frames)
    answer["search_budget"] = _search_budget_figures(tracker, frames)
    if tracker.grow_map:   # the map's growth after re-acquisitions (perception.registration.reacquire_grow_map)
        answer["map_growth"] = tracker.map_growth
    if assembly is not None:
        answer["net"] = _net_figures(track, assembly)
        _name_budget_cuts(answer)
    answer["wall_s"] = time.perf_counter() - wall
    _write_perception(folder, answer, tracker, frames, track)
    folder.finish("complete" if assembly is not None else "not_observable", pending)
    return answer


def _net_figures(track: NetTrack, assembly) -> dict:
    error = np.linalg.norm(np.array(track.positions) - np.array(track.true_positions), axis=2)
    return {"node_position_error_mean_m": float(error.mean()),
            "returns_per_frame_mean": float(np.mean(track.n_points)), "mass_kg": float(assembly.net.masses.sum())}


def _write_perception(folder, answer, tracker, frames, track: NetTrack) -> None:
    out = folder.path
    poses = np.array([a.body_to_world for a in tracker.alignments])
    results.atomic_write_npz(out / "perception.npz", {
        "time": np.array(frames.time), "phase": np.array(frames.phase), "ok": np.array([a.ok for a in tracker.alignments]),
        "target_to_world": poses, "true_target_to_world": np.array(frames.true_target_to_world),
        "true_com_world": np.array(frames.true_com_world), "rotation_error_rad": np.array(frames.rotation_error, float),
        "n_points": np.array(frames.n_points), "registration_s": np.array([a.seconds for a in tracker.alignments]),
        "tight_fitness": np.array([a.tight_fitness for a in tracker.alignments]),
        "over_budget": np.array([a.over_budget for a in tracker.alignments], bool),
        "net_time": np.array(track.times), "net_positions_world": np.array(track.positions),
        "net_true_positions_world": np.array(track.true_positions), "net_separation_m": np.array(track.separation)})
    results.atomic_write_json(out / "perception.json", answer)
    folder.add_files("perception.json", "perception.npz")
