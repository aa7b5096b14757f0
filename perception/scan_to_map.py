"""Model-free pose tracking of a tumbling debris: scan-to-map registration with a map built on the fly.

Without the debris mesh, the body frame **B** is defined by the first scan: axes of the world
frame at that scan, origin at its centroid (the CoM is unknown; it is found later as the one point
of B that moves on a straight line, :func:`perception.motion.center_of_mass_line`). Each scan is
registered to a map of the debris surface in B, built from the scans already registered and
thinned to one point per voxel (point-to-plane Gauss-Newton ICP with a Tukey kernel, on an exact
cell-list nearest-point index of the map, :class:`perception.nearest_grid.CellList`), starting
from the pose predicted at constant rotation and translation rates. Each ICP level is one compiled loop; a
scan point's nearest map point is looked up again only once it has moved far enough for it to change
(:func:`perception.nearest_grid.nearest_in_cells_kept`), and a rebuilt map's normals are computed when first
matched (:class:`LazyNormals`): the same track, 2-2.4 times less CPU (docs/perception.md, "Registration
speed"). The map grows with every registered scan, so a frame is registered to all the
surface seen before, not to its predecessor alone: the error does not accumulate from frame to
frame once the body has shown all its sides (one tumble period).

Drift while the map grows: the first frames are registered to a map made of a few partial views,
and their errors are frozen into the map; the motion prior (:func:`register_with_motion_prior`)
keeps later frames from sliding along what the partial map hardly constrains.

The first pose change (frame 1 against frame 0) has no motion prediction: seed turns up to
:data:`SEARCH_TURN` are tried (ICP on a smooth near-spheroid has a basin of only a few degrees) and
the one whose ICP leaves the scan closest to the map is kept.

Functions here are pure (arrays in, arrays out); Open3D point clouds (thinning, normals) stay inside.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import open3d as o3d
from numba import njit

from multibody.maths.rotations import (
    rotation_matrix_from_rotation_vector,
    rotation_vector_from_matrix,
)
from perception.nearest_grid import CellList, nearest_in_cells_kept
from perception.normals import fill_planes, surface_planes
from perception.point_to_plane import point_to_plane_information, tukey_normal_equations
from perception.registration import Alignment, _rigid_inverse, _turn_candidates

#: Largest turn between the first two frames searched without a motion prediction (rad): 3 rad/s at
#: 10 Hz (Tang et al. 2023, Sec. 2, the tumble rates considered).
SEARCH_TURN = np.radians(30.0)
#: A registration whose share of scan points within the correspondence distance of the map is below
#: this is a failed frame (a correct pose leaves only outliers such as net returns and noise tails).
MIN_FITNESS = 0.8
#: ICP iterations per level, at most (coarse, fine); from a good prediction a level settles in a few.
COARSE_ITERATIONS = 20
FINE_ITERATIONS = 20
#: Scan points of the coarse and fine ICP levels (every k-th point of the thinned scan): the fine
#: level's 3000 points pin a frame's attitude to a tenth of a degree on a featured body, more cost little.
COARSE_POINTS = 1000
FINE_POINTS = 3000
#: The map (voxel means and normals) is rebuilt with the scans registered since its last build when
#: a scan shows new surface (fewer than MAP_COVERED of its points within the fine correspondence
#: distance of the map) or MAP_INTERVAL frames after the last build: rebuilding every frame cost
#: 90 ms of normal estimation on a 19 000-point map, more than the registration.
MAP_COVERED = 0.95
MAP_INTERVAL = 10
#: An ICP level has settled when a step moves points at BODY_SIZE (m) from the origin by less than
#: SETTLED (m): <1 % of the 2 cm range noise of the paper's LiDAR.
BODY_SIZE = 1.0
SETTLED = 1e-4
#: Tukey cut-off of the ICP's point-to-plane residuals, as a share of the level's correspondence
#: distance. Half of it (1.7 cm at the fine level, 1.9 times the measured 0.8-1.0 cm scatter of the
#: residuals) is what makes the iteration walk: with the nearest map points re-associated every
#: iteration the steepest weights keep moving, steps of 0.002-0.005 deg were still taken after 100
#: iterations and one frame moved 1.4 deg in 300 (featured body, frames 30-60 of seed 0); with the full
#: distance (3.7 scatters) the same frames stop moving within ~30 iterations, and frozen correspondences
#: settle in ~10 with either. Kept at 0.5: the full distance did not make a frame cheaper at the 0.1 mm
#: stop and moved the inertia ratios from -0.23/-0.26 and -0.22/-0.28 % to -1.04/-1.26 and +0.54/+0.65 %
#: (seeds 0, 1, 10 s), though the attitudes improved (docs/perception.md, "ICP creep").
TUKEY_CUTOFF = 0.5
#: Scan points below which a frame is not registered (too few to fix 6 degrees of freedom reliably).
MIN_POINTS = 50


@dataclass
class MapTrack:
    """Result of model-free tracking.

    Attributes
    ----------
    world_to_body : (k, 4, 4) float   Pose of each frame: world -> B (m); identity rotation at frame 0.
    ok : (k,) bool                    Frame registered (fitness at least :data:`MIN_FITNESS`).
    fitness : (k,) float              Share of scan points within the correspondence distance of the map.
    rmse : (k,) float                 RMS point-to-map distance of those points (m).
    information : (k, 6, 6) float     Point-to-plane information of (rotation, translation), B frame
                                      (1/rad^2, 1/m^2), as :class:`perception.registration.Alignment`.
    seconds : (k,) float              Registration time of each frame (s), online pass.
    map_points : (n, 3) float         The debris surface map, frame B (m), one point per voxel.
    map_normals : (n, 3) float        Its unit normals (frame B), estimated from the map.
    cpu_seconds : (k,) float          CPU time of each frame's registration (s, process time: all
                                      threads, so at least the one-core time).
    """

    world_to_body: np.ndarray
    ok: np.ndarray
    fitness: np.ndarray
    rmse: np.ndarray
    information: np.ndarray
    seconds: np.ndarray
    map_points: np.ndarray
    map_normals: np.ndarray
    cpu_seconds: np.ndarray | None = None


@dataclass
class LazyNormals:
    """Unit normals of a map's points (frame B) and the points projected on their fitted planes, by row
    of its index's sorted points (:class:`perception.nearest_grid.CellList`), computed when a scan point
    is first matched to them.

    A map rebuild changes every point (the voxel means are re-averaged), and estimating all ~20 000-50 000
    normals took ~0.2-0.5 s CPU a rebuild, ~25 ms a frame on average; a frame's scan meets a few thousand
    of them. Each normal and plane point is the one :func:`surface_map` gives (PCA of the ``max_nn``
    nearest within ``radius``; :func:`perception.normals.fill_planes`).

    The ICP's point-to-plane residuals are taken to the plane points, not to the voxel means: a map
    of scans with 2 cm range noise thinned to 3 cm voxels is a slab of voxel means a few layers thick
    about the surface, and a scan registered to the raw means carries a slow, view-dependent attitude
    error (0.23-0.35 deg rms about B's third axis against a fixed map of the scans at their true poses;
    0.018 deg with the means projected on their fitted planes; docs/perception.md, "Which property of
    the scan-made map", helper percep14). The nearest-point search stays on the voxel means.

    Attributes
    ----------
    sorted_normals : (n, 3) float   Normals by sorted row (rows not ``known``: undefined).
    known : (n,) bool               Rows computed.
    radius : float                  Neighbourhood radius (m).
    max_nn : int                    Most neighbours.
    sorted_plane_points : (n, 3) float   Each sorted point moved along its normal onto its fitted plane
                                    (m, frame B; rows not ``known``: undefined); allocated when not given.
    sorted_views : (n, 3) float     Each sorted point's mean direction towards the sensor (frame B): the planes are
                                    fitted to the neighbours seen from the point's side
                                    (:func:`perception.normals.fill_planes`); zeros (side unknown) when not given.
    """

    sorted_normals: np.ndarray
    known: np.ndarray
    radius: float
    max_nn: int
    sorted_plane_points: np.ndarray = None
    sorted_views: np.ndarray = None

    def __post_init__(self):
        if self.sorted_plane_points is None:
            self.sorted_plane_points = np.empty_like(self.sorted_normals)
        if self.sorted_views is None:
            self.sorted_views = np.zeros_like(self.sorted_normals)

    @classmethod
    def given(cls, normals, index) -> LazyNormals:
        """Every normal known: ``normals`` (n, 3) in the order of the index's points, resorted.

        Parameters
        ----------
        normals : (n, 3) float       Unit normals of the map points (frame B).
        index : CellList             The map's index (:func:`map_index`).

        Returns
        -------
        LazyNormals                  The plane points are the map points themselves (a map given with its normals
                                     is taken as the surface).
        """
        return cls(np.ascontiguousarray(np.asarray(normals, float)[index.order]), np.ones(len(index.order), np.bool_),
                   0.0, 0, np.ascontiguousarray(index.sorted_points))


def _cloud(points) -> o3d.geometry.PointCloud:
    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, float)))


def _transform(points, matrix) -> np.ndarray:
    return np.asarray(points) @ matrix[:3, :3].T + matrix[:3, 3]


def views_towards(points, sensor) -> np.ndarray:
    """Unit directions (n, 3) from points (n, 3) (m) to the sensor origin (3,) (m, same frame) that saw them."""
    towards = np.asarray(sensor, float) - np.asarray(points, float)
    return towards / np.maximum(np.linalg.norm(towards, axis=1, keepdims=True), 1e-12)


def voxel_means(points, voxel, views) -> tuple[np.ndarray, np.ndarray]:
    """One point (the mean) per ``voxel`` (m) cell of points (n, 3) (m), with the mean of their ``views``
    (n, 3) (directions towards the sensor, same frame): Open3D's voxel thinning, the views carried as its normals.

    Returns
    -------
    points : (p, 3) float, views : (p, 3) float    Voxel means (m) and their mean views (not normalized), same frame.
    """
    cloud = _cloud(points)
    cloud.normals = o3d.utility.Vector3dVector(np.asarray(views, float))
    cloud = cloud.voxel_down_sample(voxel)
    return np.asarray(cloud.points), np.nan_to_num(np.asarray(cloud.normals))   # zero views may come back 0/0


def thinned_scan(points_world, voxel) -> np.ndarray:
    """One point (the mean) per ``voxel`` (m) cell of a scan (n, 3) (m, world): the points ICP uses.

    Parameters
    ----------
    points_world : (n, 3) float    Scan points, world frame (m).
    voxel : float                  Voxel edge (m).

    Returns
    -------
    (p, 3) float                   Voxel means, world frame (m), p <= n.
    """
    return np.asarray(_cloud(points_world).voxel_down_sample(voxel).points)


def surface_map(points_body, voxel, views_body=None) -> o3d.geometry.PointCloud:
    """Map cloud of surface points (n, 3) (m, frame B): one point (the mean) per ``voxel`` cell,
    moved along its normal onto the plane fitted to its 4-voxel neighbourhood (30 nearest; with
    ``views_body``, those seen from the point's side, :func:`perception.normals.fill_planes`), with that
    normal. The mean over a cell averages the range noise of the scans merged into it; the
    projection takes out what is left across the surface (:class:`LazyNormals`).

    Parameters
    ----------
    points_body : (n, 3) float     Registered surface points, frame B (m).
    voxel : float                  Voxel edge (m); the normals use a radius of 4 voxels.
    views_body : (n, 3) float, optional   Directions from the points towards the sensor that saw them, frame B.

    Returns
    -------
    open3d PointCloud              Voxel means on their fitted planes with unit normals, frame B (m).
    """
    if views_body is None:
        means, views = np.asarray(_cloud(points_body).voxel_down_sample(voxel).points), None
    else:
        means, views = voxel_means(points_body, voxel, views_body)
    # Open3D's estimate_normals(KDTreeSearchParamHybrid(4 voxel, 30)) gives the same normals, in
    # 1.3-1.5 times the CPU time (perception/normals.py)
    plane_points, normals = surface_planes(means, 4 * voxel, 30, views)
    cloud = _cloud(plane_points)
    cloud.normals = o3d.utility.Vector3dVector(normals)
    return cloud


def map_index(map_points, max_correspondence) -> CellList:
    """Nearest-point index of a map (n, 3) (m, frame B) for the ICP's correspondence distances
    (coarse ``max_correspondence``, fine a third of it; m): exact, cells of the fine distance, rebuilt
    with the map in a few ms (:class:`perception.nearest_grid.CellList`).

    Parameters
    ----------
    map_points : (n, 3) float      Map points, frame B (m).
    max_correspondence : float     Coarse correspondence distance (m).

    Returns
    -------
    perception.nearest_grid.CellList
    """
    return CellList(map_points, max_correspondence / 3, max_correspondence)


def register_to_map(scan_world, map_points, map_normals, initial_world_to_body, max_correspondence,
                    index=None, cutoff_share=TUKEY_CUTOFF, fine_only=False) -> tuple[np.ndarray, float, float]:
    """Point-to-plane ICP (Tukey kernel) of a thinned scan to the map, coarse then fine, without a
    motion prior (:func:`register_with_motion_prior` with a zero prior information).

    Parameters
    ----------
    scan_world : (n, 3) float                 Thinned scan points, world frame (m).
    map_points, map_normals : (m, 3) float    Map and unit normals, frame B (m).
    initial_world_to_body : (4, 4)            Starting pose, world -> B.
    max_correspondence : float                Coarse correspondence distance (m); the fine level uses a third.
    index : CellList, optional              :func:`map_index` of the map (built here when not given).
    cutoff_share : float                      Tukey cut-off as a share of each level's correspondence distance.
    fine_only : bool                          Only the fine level (a start already within its distance).

    Returns
    -------
    world_to_body : (4, 4) float, fitness : float (-), rmse : float (m): the share of scan points
    within the fine distance of a map point and their RMS distance (m), as Open3D's ICP reports them.
    """
    index = map_index(map_points, max_correspondence) if index is None else index
    return _register(scan_world, map_points, map_normals, initial_world_to_body, max_correspondence, None, index,
                     cutoff_share, fine_only)


def register_with_motion_prior(scan_world, map_points, map_normals, predicted_world_to_body, max_correspondence,
                               prior_sigma, index=None) -> np.ndarray:
    """Point-to-plane ICP (Tukey kernel) of a thinned scan to the map, regularized towards the
    pose predicted from the motion: the Gauss-Newton steps minimize
    ``sum w r^2 / s^2 + d^T P d`` with r the point-to-plane residuals (Tukey weights w, cut-off
    TUKEY_CUTOFF times the level's correspondence distance, scatter s a third of that cut-off), d the pose's
    difference from the prediction and P = diag(1 / prior_sigma^2).

    Why: on a smooth near-spheroid the turn about the near-symmetry axis barely changes the fit
    of a partial view (the paper's ellipsoid: a 7 deg error fitted as well as the truth), so
    plain ICP of a scan to a partial map slides along that valley by degrees each frame and the
    map, built from those poses, follows: 10-50 deg of drift in 8 s measured with Open3D's ICP.
    The prior holds the poorly seen direction at the prediction and leaves the well seen ones to
    the scan (their data information is hundreds of times larger).

    Parameters
    ----------
    scan_world : (n, 3) float                 Thinned scan, world frame (m).
    map_points, map_normals : (m, 3) float    Map and unit normals, frame B (m).
    predicted_world_to_body : (4, 4) float    Predicted pose, world -> B.
    max_correspondence : float                Coarse correspondence distance (m); fine level a third.
    prior_sigma : (6,) float or None          1-sigma of the prediction: rotation (rad), translation (m);
                                              None: no prior (plain ICP from the given pose).
    index : CellList, optional              :func:`map_index` of the map (built here when not given).

    Returns
    -------
    world_to_body : (4, 4) float
    """
    return _register(scan_world, map_points, map_normals, predicted_world_to_body, max_correspondence, prior_sigma,
                     index)[0]


def _register(scan_world, map_points, map_normals, predicted_world_to_body, max_correspondence, prior_sigma, index,
              cutoff_share=TUKEY_CUTOFF, fine_only=False):
    """:func:`register_with_motion_prior`'s pose, and :func:`map_fit`'s fitness and RMS distance at it
    (from the fine level's last look-up when that level used every scan point)."""
    index = map_index(map_points, max_correspondence) if index is None else index
    pose = np.array(predicted_world_to_body, float)
    prior_information = np.zeros(6) if prior_sigma is None else 1.0 / np.asarray(prior_sigma, float) ** 2
    scan_world = np.ascontiguousarray(scan_world, dtype=float)
    if not isinstance(map_normals, LazyNormals):
        map_normals = LazyNormals.given(map_normals, index)
    levels = ((max(1, len(scan_world) // COARSE_POINTS), max_correspondence, COARSE_ITERATIONS),
              (max(1, len(scan_world) // FINE_POINTS), max_correspondence / 3, FINE_ITERATIONS))
    for step, distance, iterations in levels[1:] if fine_only else levels:
        shells = max(int(np.ceil(distance / index.cell)), 1)
        pose, fitness, rmse = _icp_level(np.ascontiguousarray(scan_world[::step]), pose, _rigid_inverse(predicted_world_to_body),
                          prior_information, prior_sigma is not None, distance, cutoff_share * distance, iterations,
                          BODY_SIZE, SETTLED, index.low, index.cell, index.shape, index.starts,
                          index.sorted_points, shells, map_normals.sorted_normals, map_normals.sorted_plane_points,
                          map_normals.known, index.largest_cell, map_normals.radius, map_normals.max_nn,
                          map_normals.sorted_views)
    if step > 1:
        fitness, rmse = map_fit(scan_world, pose, index, max_correspondence / 3)
    return pose, fitness, rmse


@njit(cache=True, inline="always")
def _points_in_body_into(world_to_body, points_world, body):
    """``body[k] = world_to_body @ [points_world[k], 1]`` for every point (a 4 x 4 homogeneous pose),
    written out so numba keeps it one loop without temporaries."""
    for k in range(len(points_world)):
        for a in range(3):
            body[k, a] = (world_to_body[a, 0] * points_world[k, 0] + world_to_body[a, 1] * points_world[k, 1]
                          + world_to_body[a, 2] * points_world[k, 2] + world_to_body[a, 3])


@njit(cache=True)
def _icp_level(points_world, pose, reference_inverse, prior_information, with_prior, distance, cutoff, iterations,
               body_size, settled, low, cell, shape, starts, map_points, shells, map_normals, plane_points,
               normal_known, largest_cell, normal_radius, normal_neighbours, map_views):
    """One ICP level of :func:`register_with_motion_prior`, compiled: per iteration the points posed,
    their nearest map points within ``distance`` (exact: :func:`perception.nearest_grid.nearest_in_cells_kept`
    looks a point up again only when it moved far enough for its nearest point to change), the Tukey
    normal equations, the regularized Gauss-Newton step (left, frame B), and the stop once a step's
    rotation (rad) times ``body_size`` (m) plus its translation is below ``settled`` (m). Returns the
    pose, and the share of the points within ``distance`` of the map at it and their RMS distance (m;
    NaN without any), as :func:`map_fit`.
    ``map_points``: the cell list's sorted points (the nearest-point search); ``map_normals`` and
    ``plane_points``: their normals and their projections on their fitted planes (same order; the
    point-to-plane residuals), those not ``normal_known`` computed (:func:`perception.normals.fill_planes`)
    once a point is matched, from the neighbours seen from its side (``map_views``, sorted order)."""
    n = len(points_world)
    body = np.empty((n, 3))
    kept_points, kept_index, kept_safe = np.zeros((n, 3)), np.full(n, -1, np.int64), np.full(n, -1.0)
    gap, nearest = np.empty(n), np.empty(n, np.int64)
    scatter2 = (cutoff / 3) ** 2      # the Tukey cut-off at 3 scatters
    difference = np.zeros(6)
    for _ in range(iterations):
        _points_in_body_into(pose, points_world, body)
        nearest_in_cells_kept(body, low, cell, shape, starts, map_points, distance, shells,
                              kept_points, kept_index, kept_safe, gap, nearest)
        fill_planes(nearest, map_points, low, cell, shape, starts, largest_cell, normal_radius, normal_neighbours,
                    map_normals, plane_points, normal_known, map_views)
        hessian, gradient, _, count = tukey_normal_equations(body, nearest, plane_points, map_normals, cutoff)
        if count < 6:
            break
        if with_prior:
            delta = pose @ reference_inverse
            difference[:3] = rotation_vector_from_matrix(np.ascontiguousarray(delta[:3, :3]))
            difference[3:] = delta[:3, 3]
        system = hessian / scatter2
        for a in range(6):
            system[a, a] += prior_information[a]
        rhs = -(gradient / scatter2 + prior_information * difference)
        if not _solvable(system):   # degenerate matches (all on one plane) and no prior
            break
        step = np.linalg.solve(system, rhs)
        twist = np.eye(4)
        twist[:3, :3] = rotation_matrix_from_rotation_vector(step[:3])
        twist[:3, 3] = step[3:]
        pose = twist @ pose
        if np.sqrt(step[0] ** 2 + step[1] ** 2 + step[2] ** 2) * body_size \
                + np.sqrt(step[3] ** 2 + step[4] ** 2 + step[5] ** 2) < settled:
            break
    _points_in_body_into(pose, points_world, body)
    nearest_in_cells_kept(body, low, cell, shape, starts, map_points, distance, shells,
                          kept_points, kept_index, kept_safe, gap, nearest)
    inside, squares = 0, 0.0
    for k in range(n):
        if np.isfinite(gap[k]):
            inside += 1
            squares += gap[k] ** 2
    return pose, inside / max(n, 1), np.sqrt(squares / inside) if inside else np.nan


@njit(cache=True)
def _solvable(system) -> bool:
    """Whether a (6, 6) normal matrix is invertible (numpy's solve would raise LinAlgError): its
    LU pivots all nonzero, which numba's solve checks the same way."""
    return abs(np.linalg.det(system)) > 0.0


def map_fit(scan_world, world_to_body, map_tree, distance) -> tuple[float, float]:
    """Share of scan points (n, 3) (world) within ``distance`` (m) of a map point (index of the
    map, frame B) at the pose world -> B (4, 4), and their RMS distance (m).

    Parameters
    ----------
    scan_world : (n, 3) float      Thinned scan points, world frame (m).
    world_to_body : (4, 4) float   Pose world -> B (m for the translation).
    map_tree : CellList or cKDTree   Nearest-point index of the map points, frame B (m).
    distance : float               Correspondence distance (m).

    Returns
    -------
    fitness : float (-), rmse : float (m; NaN when no point is within ``distance``).
    """
    gap, _ = map_tree.query(_transform(scan_world, world_to_body), distance_upper_bound=distance)
    inside = np.isfinite(gap)
    return float(inside.mean()), float(np.sqrt(np.mean(gap[inside] ** 2))) if inside.any() else np.nan


def predict_world_to_body(previous, before) -> np.ndarray:
    """world -> B at the next frame from the last two (4, 4) at constant rotation and translation
    rates (equal frame spacing).

    Parameters
    ----------
    previous : (4, 4) float   world -> B at the last frame (m for the translation).
    before : (4, 4) float     world -> B at the frame before it.

    Returns
    -------
    (4, 4) float              Predicted world -> B at the next frame.
    """
    return previous @ np.linalg.inv(before) @ previous


def search_pose(scan_world, map_points, map_normals, start_world_to_body, max_correspondence,
                index=None) -> tuple[np.ndarray, float, float]:
    """Pose of a scan without a motion prediction: ``start`` turned about the scan centroid by each
    of the seed turns (:data:`SEARCH_TURN`), each refined by ICP (:func:`register_to_map`); the best
    fit (fitness, then RMS distance) is kept.

    Parameters
    ----------
    scan_world : (n, 3) float                 Thinned scan points, world frame (m).
    map_points, map_normals : (m, 3) float    Map and unit normals, frame B (m).
    start_world_to_body : (4, 4) float        Pose world -> B the seeds turn (last registered frame's).
    max_correspondence : float                Coarse correspondence distance (m); the fine level uses a third.
    index : CellList, optional              :func:`map_index` of the map (built here when not given).

    Returns
    -------
    world_to_body : (4, 4) float, fitness : float (-), rmse : float (m) of the best seed's fine level.
    """
    index = map_index(map_points, max_correspondence) if index is None else index
    pivot = np.mean(scan_world, axis=0)
    best = None
    for turn in _turn_candidates(SEARCH_TURN):
        seed = np.array(start_world_to_body, float)
        seed[:3, :3] = turn @ start_world_to_body[:3, :3]
        seed[:3, 3] = start_world_to_body[:3, :3] @ pivot + start_world_to_body[:3, 3] - seed[:3, :3] @ pivot
        pose, fitness, rmse = register_to_map(scan_world, map_points, map_normals, seed, max_correspondence, index)
        if best is None or (round(fitness, 2), -rmse) > (round(best[1], 2), -best[2]):
            best = (pose, fitness, rmse)
    return best


def map_information(scan_world, world_to_body, map_points, map_normals, max_correspondence, index=None) -> np.ndarray:
    """Point-to-plane information (6, 6) of a registered scan (rotation first, frame B, 1/rad^2 and
    1/m^2): the scan points within a third of ``max_correspondence`` of the map, on the planes of
    their nearest map points, residual scatter measured. ``index``: :func:`map_index` of the map if built.

    Parameters
    ----------
    scan_world : (n, 3) float                 Thinned scan points, world frame (m).
    world_to_body : (4, 4) float              Registered pose world -> B (m for the translation).
    map_points, map_normals : (m, 3) float    Map points (m) and unit normals, frame B.
    max_correspondence : float                Coarse correspondence distance (m); points within a
                                              third of it count.
    index : CellList, optional              :func:`map_index` of the map (built here when not given).

    Returns
    -------
    (6, 6) float                              Information of (rotation, translation), frame B
                                              (1/rad^2, 1/m^2, 1/(rad m)); zeros below 6 matches.
    """
    body = _transform(scan_world, world_to_body)
    index = map_index(map_points, max_correspondence) if index is None else index
    gap, nearest = index.query(body, distance_upper_bound=max_correspondence / 3)
    matched = np.isfinite(gap)
    if matched.sum() < 6:
        return np.zeros((6, 6))
    normals = map_normals[nearest[matched]]
    distance = np.einsum("ij,ij->i", body[matched] - map_points[nearest[matched]], normals)
    sigma = max(float(np.sqrt(np.mean(distance**2))), 1e-4)
    return point_to_plane_information(body[matched], normals, sigma)


#: 1-sigma of a constant-rate pose prediction one frame ahead: rotation (rad), translation (m). A
#: torque-free tumble of the paper's rates (2.3 rad/s, up to ~2 rad/s^2 of angular acceleration)
#: departs from constant rate by 0.5 alpha dt^2 ~ 0.6 deg in 0.1 s; 1 deg also covers the
#: prediction's own error from the last two poses.
PRIOR_SIGMA = np.r_[np.full(3, np.radians(1.0)), np.full(3, 0.01)]


def track_scans(scans_world, voxel, max_correspondence, prior_sigma=PRIOR_SIGMA, second_pose=None,
                sensors_world=None) -> MapTrack:
    """Scan-to-map tracking of a sequence of scans (frames equally spaced in time).

    Parameters
    ----------
    scans_world : list of (n_k, 3) float   Scans of the debris, world frame (m).
    voxel : float                          Scan thinning and map spacing (m).
    max_correspondence : float             ICP correspondence distance, coarse level (m).
    prior_sigma : (6,) float               1-sigma of the motion prediction (rad, m), see
                                           :func:`register_with_motion_prior`.
    second_pose : (4, 4) float, optional   world -> B of the second registered frame, instead of
                                           the search (a pose known from elsewhere).
    sensors_world : (k, 3) float, optional  Sensor origin of each scan, world frame (m): the map keeps each
                                           point's mean direction to the sensor and fits its plane to the
                                           neighbours seen from its side (the two faces of a thin part apart;
                                           :func:`perception.normals.fill_planes`). None: all neighbours (the
                                           stage's choice: on the featured debris the rule changed the map by
                                           < 0.3 mm rms and did not help; docs/perception.md, "The thin array's
                                           two faces").

    Returns
    -------
    MapTrack
    """
    thin = [thinned_scan(s, voxel) if len(s) else np.zeros((0, 3)) for s in scans_world]
    views = ([np.zeros_like(t) for t in thin] if sensors_world is None
             else [views_towards(t, sensor) for t, sensor in zip(thin, np.asarray(sensors_world, float))])
    k = len(thin)
    poses = np.tile(np.eye(4), (k, 1, 1))
    ok = np.zeros(k, bool)
    fitness, rmse, seconds, cpu = np.zeros(k), np.full(k, np.nan), np.zeros(k), np.zeros(k)
    points = normals = index = map_views = None
    pending, pending_views, built = [], [], 0
    for i, scan in enumerate(thin):
        tic, cpu_tic = time.perf_counter(), time.process_time()
        if len(scan) < MIN_POINTS:
            seconds[i] = time.perf_counter() - tic
            continue
        if points is None:   # the first scan defines B: world axes, origin at its centroid
            poses[i, :3, 3] = -scan.mean(axis=0)
            points, normals, index, map_views = _built_map(_transform(scan, poses[i]), voxel, max_correspondence,
                                                           views[i] @ poses[i][:3, :3].T)
            built = i
            ok[i], fitness[i], rmse[i] = True, 1.0, 0.0
            seconds[i] = time.perf_counter() - tic
            continue
        good = np.flatnonzero(ok[:i])
        if len(good) >= 2 and good[-1] == i - 1 and good[-2] == i - 2:
            pose, fitness[i], rmse[i] = _register(scan, points, normals,
                                                  predict_world_to_body(poses[i - 1], poses[i - 2]),
                                                  max_correspondence, prior_sigma, index)
        elif second_pose is not None and len(good) == 1:
            pose, fitness[i], rmse[i] = register_to_map(scan, points, normals, second_pose, max_correspondence, index)
        else:
            pose, fitness[i], rmse[i] = search_pose(scan, points, normals, poses[good[-1]], max_correspondence, index)
        poses[i] = pose
        ok[i] = fitness[i] >= MIN_FITNESS
        if ok[i]:
            pending.append(_transform(scan, pose))
            pending_views.append(views[i] @ pose[:3, :3].T)
            if fitness[i] < MAP_COVERED or i - built >= MAP_INTERVAL:
                points, normals, index, map_views = _built_map(np.vstack([points] + pending), voxel, max_correspondence,
                                                               np.vstack([map_views] + pending_views))
                pending, pending_views, built = [], [], i
        seconds[i] = time.perf_counter() - tic
        cpu[i] = time.process_time() - cpu_tic
    if points is None:
        return MapTrack(poses, ok, fitness, rmse, np.zeros((k, 6, 6)), seconds, np.zeros((0, 3)), np.zeros((0, 3)), cpu)
    return _with_map(thin, poses, ok, fitness, rmse, seconds, voxel, max_correspondence, cpu,
                     None if sensors_world is None else views)


def registered_again(track: MapTrack, thin, max_correspondence, prior_sigma=PRIOR_SIGMA) -> MapTrack:
    """The track with every registered frame registered again to the finished map, from its own pose (the
    motion prior centred there, so a direction the scan does not fix stays put), and its information at
    the new pose; the map is kept. The stage's ``perception.registration.map_second_pass`` (off: measured,
    not adopted).

    Why it was tried: the online pass registers frame i to the map of the frames before it (a partial map,
    built at the earlier frames' poses), and the finished map is built from those poses; on the featured
    debris the second pass moves the frames by 0.23-0.25 deg (median). Measured (docs/perception.md,
    percep21): it raises the model-free C by 0.17-0.40 % on five seeds (all five then within 0.2 %), but by
    turning the spin momentum before the collision the other way (C's share of h0 from -0.24..+0.04 % to
    +0.07..+0.25 %), i.e. by compensating the other terms' bias, not removing it; on a synthetic tumble with a
    known answer it takes h further from the truth (0.066-0.101 -> 0.076-0.130 deg, rng seeds 0-4).

    Parameters
    ----------
    track : MapTrack                   Result of the online pass (:func:`track_scans`).
    thin : list of (n_k, 3) float      The frames' thinned scans, world frame (m).
    max_correspondence : float         ICP correspondence distance, coarse level (m).
    prior_sigma : (6,) float           1-sigma of the prior about the frame's own pose (rad, m).

    Returns
    -------
    MapTrack                           Poses, fitness, RMS distance, information and CPU time of the
                                       frames registered again (CPU added); the map, ``ok`` and the
                                       online seconds as in ``track``.
    """
    index = map_index(track.map_points, max_correspondence)
    normals = LazyNormals.given(track.map_normals, index)
    poses, fitness, rmse = track.world_to_body.copy(), track.fitness.copy(), track.rmse.copy()
    information = track.information.copy()
    cpu = np.zeros(len(poses)) if track.cpu_seconds is None else track.cpu_seconds.copy()
    for i in np.flatnonzero(track.ok):
        cpu_tic = time.process_time()
        poses[i], fitness[i], rmse[i] = _register(thin[i], track.map_points, normals, poses[i], max_correspondence,
                                                  prior_sigma, index)
        information[i] = map_information(thin[i], poses[i], track.map_points, track.map_normals, max_correspondence,
                                         index)
        cpu[i] += time.process_time() - cpu_tic
    return MapTrack(poses, track.ok, fitness, rmse, information, track.seconds, track.map_points, track.map_normals, cpu)


def _built_map(points_body, voxel, max_correspondence, views_body=None):
    """Map points (n, 3) (frame B, m) of registered surface points, their normals (:class:`LazyNormals`,
    as :func:`surface_map`'s), their index and their mean views towards the sensor (frame B; zeros
    without ``views_body``)."""
    views_body = np.zeros_like(points_body) if views_body is None else views_body
    points, views = voxel_means(points_body, voxel, views_body)
    index = map_index(points, max_correspondence)
    normals = LazyNormals(np.empty((len(points), 3)), np.zeros(len(points), np.bool_), 4 * voxel, 30,
                          sorted_views=np.ascontiguousarray(views[index.order]))
    return points, normals, index, views


def _with_map(thin, poses, ok, fitness, rmse, seconds, voxel, max_correspondence, cpu=None, views=None) -> MapTrack:
    """The track with the map rebuilt from all registered scans and each frame's information; ``views``: each
    thinned scan's directions to the sensor (world), for :func:`surface_map`'s own-side planes."""
    registered = np.flatnonzero(ok)
    cloud = surface_map(np.vstack([_transform(thin[i], poses[i]) for i in registered]), voxel,
                        None if views is None else np.vstack([views[i] @ poses[i][:3, :3].T for i in registered]))
    points, normals = np.asarray(cloud.points), np.asarray(cloud.normals)
    index = map_index(points, max_correspondence)
    information = np.array([map_information(thin[i], poses[i], points, normals, max_correspondence, index) if ok[i]
                            else np.zeros((6, 6)) for i in range(len(thin))])
    return MapTrack(poses, ok, fitness, rmse, information, seconds, points, normals, cpu)


def alignments(track: MapTrack, times) -> list[Alignment]:
    """The track's frames as :class:`perception.registration.Alignment` records (one per frame,
    times (k,) in s), the form the free-motion fits (:func:`perception.free_flight.fit_free_motion`)
    and the stage read: pose world -> B, information, fitness as the tight fitness, online time.

    Parameters
    ----------
    track : MapTrack    Result of :func:`track_scans` (k frames).
    times : (k,) float  Time of each frame (s).

    Returns
    -------
    list of Alignment   k records, pose world -> B (m for the translation).
    """
    return [Alignment(float(t), track.world_to_body[i], track.information[i], float(track.fitness[i]), 0.0, 0.0,
                      bool(track.ok[i]), False, float(track.seconds[i]), 0,
                      float(track.cpu_seconds[i]) if track.cpu_seconds is not None else 0.0)
            for i, t in enumerate(times)]
