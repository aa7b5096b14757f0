"""The observation's poses and its map optimized jointly: a pose graph over the repeated views of a tumble.

The online scan-to-map pass (:func:`perception.scan_to_map.track_scans`) registers each scan to a map made
from the scans before it, and the map is fused from those poses: an error frozen into the map early is seen
again by every later frame that looks at the same part, so the finished map is not a rigid copy of the body
and the registration to it carries a view-dependent bias (docs/perception.md, percep21: the fits' spin
momentum 0.05-0.08 deg off on the featured debris, the map 13-14 mm rms off the surface). Here the poses are
found again from **scan-to-scan** alignments only, each pair of frames that sees the same part of the body
giving one relative pose (an edge), and all poses found together by least squares over the edges (Open3D's
``global_optimization``, the multiway registration of Choi, Zhou & Koltun 2015): consecutive frames and
**loop closures** between frames that see the same side of the body one or more tumble periods apart. No
scan is registered to a fused map, so no map's error enters a pose; the map is fused afterwards from the
optimized poses (:func:`perception.scan_to_map._with_map`).

Frames: node k's pose is world -> B of frame k (it maps frame k's scan, world at its time, into B); an edge
(i, j) is T_ij = (world -> B)_j^-1 (world -> B)_i, which maps frame i's scan onto frame j's (both world,
at their own times). Frame 0's node is held (B stays the first scan's frame, as in the online pass).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import open3d as o3d
from scipy.spatial.transform import Rotation

from perception.point_to_plane import point_to_plane_information
from perception.scan_to_map import MapTrack, _cloud, _transform, _with_map

#: Edge of the coarse cells (m) whose shared occupancy says two frames see the same part of the body: 3
#: voxels of the case's 3 cm thinning, coarse enough that a pose error of a few cm does not split a cell.
OVERLAP_CELL = 0.1
#: Least share of the smaller frame's coarse cells also occupied by the other frame for a loop closure (a
#: pair of scans must share most of what they see for a scan-to-scan alignment to fix all six directions).
MIN_OVERLAP = 0.6
#: Loop closures per frame (to later frames), chosen by overlap: with the two frames after it each frame has
#: up to 2 + LOOP_EDGES edges; more edges cost scan-to-scan alignments and hardly change the poses.
LOOP_EDGES = 4
#: Consecutive edges per frame (frames i + 1 .. i + CHAIN_EDGES): the chain that holds the graph together.
CHAIN_EDGES = 2
#: A pair aligned with a smaller share of its points within the fine distance is no edge.
MIN_PAIR_FITNESS = 0.5
#: ICP iterations of a pairwise alignment at each level (coarse, fine).
PAIR_ITERATIONS = 30
#: Scan points a pairwise alignment uses (every k-th point of the thinned source).
PAIR_POINTS = 3000
#: A pairwise ICP level stops when its fitness and RMS distance change by less than this (relative).
PAIR_SETTLED = 1e-6


@dataclass
class PoseGraphResult:
    """Poses of the joint optimization and what it used.

    Attributes
    ----------
    world_to_body : (k, 4, 4) float   Optimized pose of each frame, world -> B (m); frame 0 held.
    edges : (e, 2) int                Frame pairs aligned (source, target).
    loop_closures : int               Of those, pairs more than CHAIN_EDGES frames apart.
    cpu_seconds : float               CPU time of the whole optimization (s, process time).
    """

    world_to_body: np.ndarray
    edges: np.ndarray
    loop_closures: int
    cpu_seconds: float


def coarse_cells(points_body, cell=OVERLAP_CELL) -> set:
    """The coarse cells (integer triples of ``cell`` (m) edges, frame B) occupied by points (n, 3) (m, frame B)."""
    return set(map(tuple, np.floor(np.asarray(points_body) / cell).astype(np.int64)))


def overlap_share(cells_a: set, cells_b: set) -> float:
    """Share of the smaller of two frames' coarse cells that the other frame occupies too."""
    return len(cells_a & cells_b) / max(min(len(cells_a), len(cells_b)), 1)


def frame_pairs(poses, thin, ok) -> list[tuple[int, int]]:
    """Pairs (i, j), i < j, of registered frames to align: the next CHAIN_EDGES frames of each, and its
    LOOP_EDGES later frames of largest coarse overlap (at least MIN_OVERLAP, in B at the given poses).

    Parameters
    ----------
    poses : (k, 4, 4) float            Pose world -> B of each frame (the online pass's).
    thin : list of (n_k, 3) float      Thinned scans, world frame (m).
    ok : (k,) bool                     Frames registered.

    Returns
    -------
    list of (int, int)
    """
    frames = np.flatnonzero(ok)
    cells = {i: coarse_cells(_transform(thin[i], poses[i])) for i in frames}
    pairs = []
    for a, i in enumerate(frames):
        chain = list(frames[a + 1:a + 1 + CHAIN_EDGES])
        later = [(overlap_share(cells[i], cells[j]), j) for j in frames[a + 1 + CHAIN_EDGES:]]
        loops = [j for share, j in sorted(later, reverse=True)[:LOOP_EDGES] if share >= MIN_OVERLAP]
        pairs += [(int(i), int(j)) for j in chain + loops]
    return pairs


def scan_clouds(thin, voxel) -> list:
    """Open3D clouds of the thinned scans (world) with normals over 4 voxels (30 nearest), as the map's."""
    clouds = []
    for scan in thin:
        cloud = _cloud(scan)
        if len(scan) >= 30:
            cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=4 * voxel, max_nn=30))
        clouds.append(cloud)
    return clouds


def pair_alignment(source, target, source_to_target, max_correspondence):
    """Point-to-plane ICP of frame i's scan onto frame j's (both world at their times), from ``source_to_target``
    (4, 4): coarse at ``max_correspondence`` (m), then fine at a third of it, Tukey kernel at the level's distance.

    Returns
    -------
    transformation : (4, 4) float    T_ij, frame i's scan onto frame j's (m).
    information : (6, 6) float       Point-to-plane information of T_ij (rotation first, left perturbation in
                                     frame j's coordinates; 1/rad^2, 1/m^2), residual scatter measured.
    fitness : float                  Share of the source points within the fine distance.
    """
    step = max(len(source.points) // PAIR_POINTS, 1)
    sparse = source.uniform_down_sample(step) if step > 1 else source
    transformation = np.asarray(source_to_target, float)
    for distance in (max_correspondence, max_correspondence / 3):
        method = o3d.pipelines.registration.TransformationEstimationPointToPlane(
            o3d.pipelines.registration.TukeyLoss(k=distance))
        result = o3d.pipelines.registration.registration_icp(
            sparse, target, distance, transformation, method,
            o3d.pipelines.registration.ICPConvergenceCriteria(PAIR_SETTLED, PAIR_SETTLED, PAIR_ITERATIONS))
        transformation = np.asarray(result.transformation)
    pairs = np.asarray(result.correspondence_set)
    if len(pairs) < 6:
        return transformation, np.zeros((6, 6)), 0.0
    moved = _transform(np.asarray(sparse.points)[pairs[:, 0]], transformation)
    on, normals = np.asarray(target.points)[pairs[:, 1]], np.asarray(target.normals)[pairs[:, 1]]
    sigma = max(float(np.sqrt(np.mean(np.einsum("ij,ij->i", moved - on, normals) ** 2))), 1e-4)
    return transformation, point_to_plane_information(moved, normals, sigma), float(result.fitness)


def optimized_poses(poses, thin, ok, voxel, max_correspondence) -> PoseGraphResult:
    """The frames' poses world -> B from scan-to-scan alignments of :func:`frame_pairs`, optimized jointly
    (Open3D ``global_optimization``, Levenberg-Marquardt, every edge kept), frame 0 held.

    Parameters
    ----------
    poses : (k, 4, 4) float            Starting poses world -> B (the online pass's; m).
    thin : list of (n_k, 3) float      Thinned scans, world frame (m).
    ok : (k,) bool                     Frames registered; the others keep their pose and get no edge.
    voxel : float                      Scan thinning (m); normals over 4 voxels.
    max_correspondence : float         Coarse correspondence distance (m); the fine level uses a third.

    Returns
    -------
    PoseGraphResult
    """
    tic = time.process_time()
    frames = np.flatnonzero(ok)
    clouds = scan_clouds(thin, voxel)
    graph = o3d.pipelines.registration.PoseGraph()
    node_of = {int(i): n for n, i in enumerate(frames)}
    for i in frames:
        graph.nodes.append(o3d.pipelines.registration.PoseGraphNode(np.array(poses[i], float)))
    edges = []
    for i, j in frame_pairs(poses, thin, ok):
        start = np.linalg.inv(poses[j]) @ poses[i]
        transformation, information, fitness = pair_alignment(clouds[i], clouds[j], start, max_correspondence)
        if fitness < MIN_PAIR_FITNESS:
            continue
        graph.edges.append(o3d.pipelines.registration.PoseGraphEdge(node_of[i], node_of[j], transformation,
                                                                     information, uncertain=False))
        edges.append((i, j))
    option = o3d.pipelines.registration.GlobalOptimizationOption(
        max_correspondence_distance=max_correspondence / 3, edge_prune_threshold=0.25, reference_node=0)
    o3d.pipelines.registration.global_optimization(
        graph, o3d.pipelines.registration.GlobalOptimizationLevenbergMarquardt(),
        o3d.pipelines.registration.GlobalOptimizationConvergenceCriteria(), option)
    out = np.array(poses, float, copy=True)
    for n, i in enumerate(frames):
        out[i] = np.asarray(graph.nodes[n].pose)
    edges = np.array(edges, int).reshape(-1, 2)
    return PoseGraphResult(out, edges, int((np.diff(edges, axis=1) > CHAIN_EDGES).sum()), time.process_time() - tic)


def jointly_optimized(track: MapTrack, thin, voxel, max_correspondence) -> tuple[MapTrack, PoseGraphResult]:
    """The track with its poses from :func:`optimized_poses` and its map fused again from them (each frame's
    information against the new map).

    Parameters
    ----------
    track : MapTrack                   Result of the online pass (:func:`perception.scan_to_map.track_scans`).
    thin : list of (n_k, 3) float      The frames' thinned scans, world frame (m).
    voxel : float                      Scan thinning and map spacing (m).
    max_correspondence : float         ICP correspondence distance, coarse level (m).

    Returns
    -------
    MapTrack, PoseGraphResult
    """
    result = optimized_poses(track.world_to_body, thin, track.ok, voxel, max_correspondence)
    fused = _with_map(thin, result.world_to_body, track.ok, track.fitness, track.rmse, track.seconds, voxel,
                      max_correspondence, track.cpu_seconds)
    return fused, result


def twist_of(pose) -> np.ndarray:
    """Twist (6,) (rotation vector (rad), translation (m)) of a small pose change (4, 4)."""
    return np.r_[Rotation.from_matrix(pose[:3, :3]).as_rotvec(), pose[:3, 3]]


def information_weighted_pose(start, poses, informations) -> np.ndarray:
    """The pose (4, 4) world -> B that averages ``poses`` (world -> B, m) with their ``informations`` (6, 6) (left
    perturbations in B, rotation first; 1/rad^2, 1/m^2), linearized about ``start``; ``start`` when none.

    .. math:: \\delta = \\Big(\\sum_j \\Lambda_j\\Big)^{-1} \\sum_j \\Lambda_j\\, \\log(T_j T_0^{-1})
    """
    information_sum, weighted = np.zeros((6, 6)), np.zeros(6)
    for pose, information in zip(poses, informations):
        information_sum += information
        weighted += information @ twist_of(pose @ np.linalg.inv(start))
    if not information_sum.any():
        return start
    twist = np.linalg.solve(information_sum, weighted)
    delta = np.eye(4)
    delta[:3, :3], delta[:3, 3] = Rotation.from_rotvec(twist[:3]).as_matrix(), twist[3:]
    return delta @ start
