"""Point-cloud registration of the tumbling debris with Open3D, and a check that an
alignment really succeeded.

:class:`DebrisTracker` registers each scan to a model of the debris (frame-to-model): the
model is the union of the first ``model_frames`` registered scans (frame-to-frame while it
grows), in the body frame **B** (axes of the world frame at the first scan, origin at the
first scan's centroid), then frozen, so later frames do not drift. Each frame is seeded with
the pose predicted from the last two (constant rotation and translation rates) and refined
by point-to-plane ICP, coarse to fine. When the check below fails, the frame is started again
from a global FPFH + RANSAC alignment to the model.

Why a check of its own: Open3D's ``fitness`` and ``inlier_rmse`` are computed inside the
correspondence distance that ICP itself used, so an ICP that slid into a wrong pose (users
report it beyond ~45 degrees of initial error) still reports a high fitness. The check uses
three figures that a wrong pose cannot all pass:

* **tight fitness**: share of scan points within 3 sigma of the model surface (sigma: the
  measured point-to-plane scatter), not within the loose ICP distance;
* **free-space violation**: share of the sensor's viewing directions along which the posed
  model lies in front of what the LiDAR measured: the ray would have stopped on the model,
  so the pose contradicts the measurement;
* **innovation**: rotation between the registered and the predicted pose; a jump larger than
  the motion allows (a symmetric flip of a near-symmetric body) fails even when the surface fits.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

reg = o3d.pipelines.registration

#: Acceptance limits of an alignment (see module docstring).
MIN_TIGHT_FITNESS = 0.8          # share of points within 3 sigma; a correct pose leaves only outliers (net, noise tails)
MAX_FREE_SPACE_VIOLATION = 0.05  # share of viewing directions where the model blocks a measured return
MAX_INNOVATION = np.radians(10.0)  # rad; the constant-rate prediction is good to ~0.2 deg for 2.3 rad/s tumbles at 10 Hz
SEARCH_TURN = np.radians(30.0)     # rad; largest turn between frames searched without a prediction (3 rad/s at 10 Hz, paper Sec. 2)


def _turn_candidates(largest) -> list[np.ndarray]:
    """Identity and turns of largest/3, 2 largest/3 and largest about the 13 axes of a cube's
    faces, edges and corners (symmetric pairs), as rotation matrices."""
    axes = [np.array(a, float) for a in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, -1, 0), (1, 0, 1),
                                          (1, 0, -1), (0, 1, 1), (0, 1, -1), (1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1))]
    turns = [np.eye(3)]
    for axis in axes:
        for angle in (largest / 3, 2 * largest / 3, largest):
            for sign in (1, -1):
                turns.append(Rotation.from_rotvec(sign * angle * axis / np.linalg.norm(axis)).as_matrix())
    return turns


def _orientation_candidates(count=240) -> list[np.ndarray]:
    """Rotations spread over SO(3) (fixed seed: reproducible) for the first frame against a known model."""
    return list(Rotation.random(count, random_state=12345).as_matrix())


def _score(alignment) -> float:
    """Ranks candidate alignments: checks passed first, then tight fitness less violation."""
    return float(alignment.ok) + alignment.tight_fitness - alignment.free_space_violation


@dataclass
class Alignment:
    """One frame's registration.

    world_to_body : (4, 4) float   Transform taking world points into the model frame B.
    information : (6, 6) float     Point-to-plane information of (rotation, translation), B frame,
                                   left perturbation of ``world_to_body`` (1/rad^2, 1/m^2).
    """

    time: float
    world_to_body: np.ndarray
    information: np.ndarray
    tight_fitness: float
    free_space_violation: float
    innovation: float
    ok: bool
    global_init: bool
    seconds: float
    n_points: int

    @property
    def body_to_world(self) -> np.ndarray:
        return np.linalg.inv(self.world_to_body)


def _cloud(points, normals_radius=None) -> o3d.geometry.PointCloud:
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, float)))
    if normals_radius:
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=normals_radius, max_nn=30))
    return cloud


def point_to_plane_information(points_body, normals, sigma) -> np.ndarray:
    """Information (6, 6) of a point-to-plane alignment of scan points (n, 3) (B frame) on model
    planes with normals (n, 3), residual scatter ``sigma`` (m).

    Residual n.(q - m) for scan point q and its nearest model point m with normal n; its
    gradient with respect to a left rotation/translation of the pose is [(q x n), n].
    """
    jac = np.hstack([np.cross(points_body, normals), normals])
    return jac.T @ jac / sigma**2


def free_space_violation(points_world, model_world, sensor_world, bin_angle, margin) -> float:
    """Share of viewing directions (bins of ``bin_angle`` rad seen from the sensor) holding
    scan returns where a model point lies more than ``margin`` (m) in front of the nearest return."""
    def bins(points):
        d = points - sensor_world
        r = np.linalg.norm(d, axis=1)
        el = np.arcsin(np.clip(d[:, 2] / r, -1, 1))
        az = np.arctan2(d[:, 1], d[:, 0])
        return np.floor(el / bin_angle).astype(np.int64) * 1_000_003 + np.floor(az / bin_angle).astype(np.int64), r

    scan_bin, scan_range = bins(points_world)
    model_bin, model_range = bins(model_world)
    order = np.lexsort((scan_range, scan_bin))             # by bin, nearest return first
    first = np.r_[True, np.diff(scan_bin[order]) != 0]
    seen_bin, nearest = scan_bin[order][first], scan_range[order][first]
    slot = np.clip(np.searchsorted(seen_bin, model_bin), 0, len(seen_bin) - 1)
    seen = np.where(seen_bin[slot] == model_bin, nearest[slot], np.inf)
    blocked = np.unique(model_bin[np.isfinite(seen) & (model_range < seen - margin)])
    return len(blocked) / max(len(seen_bin), 1)


def _transform(points, matrix) -> np.ndarray:
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def predict_pose(previous, before) -> np.ndarray:
    """world_to_body at the next frame from the last two, at constant rotation and translation
    rates (equal frame spacing): T_next = (T_prev T_before^-1) T_prev."""
    return previous @ np.linalg.inv(before) @ previous


class DebrisTracker:
    """Frame-to-model registration of one rigid debris (see module docstring).

    Parameters
    ----------
    voxel : float               Scan thinning (m); also the model's point spacing.
    max_correspondence : float  ICP correspondence distance at the coarse level (m).
    model_frames : int          Frames merged into the model before it is frozen.
    """

    def __init__(self, voxel=0.03, max_correspondence=0.1, model_frames=30, model_points_body=None):
        self.voxel = voxel
        self.max_correspondence = max_correspondence
        self.model_frames = model_frames
        self.alignments: list[Alignment] = []
        self._model = None
        self._frames_in_model = 0
        if model_points_body is not None:
            # A known shape (catalogue or CAD): the model is complete and frozen from the start.
            self._set_model(model_points_body)
            self._frames_in_model = model_frames

    # -- model -----------------------------------------------------------------------
    def _set_model(self, points_body):
        cloud = _cloud(points_body).voxel_down_sample(self.voxel)
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=4 * self.voxel, max_nn=30))
        self._model = cloud
        self._model_points = np.asarray(cloud.points)
        self._model_normals = np.asarray(cloud.normals)
        self._tree = cKDTree(self._model_points)
        self._features = None

    @property
    def model_points_body(self) -> np.ndarray:
        """(n, 3) the debris model (m), frame B."""
        return self._model_points

    def _model_features(self):
        if self._features is None:
            self._features = reg.compute_fpfh_feature(
                self._model, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * self.voxel, max_nn=100))
        return self._features

    # -- one frame -------------------------------------------------------------------
    def update(self, time_s, points_world, sensor_world) -> Alignment:
        """Register one scan (n, 3) (m, world frame) taken from ``sensor_world`` (3,) (m)."""
        start = time.perf_counter()
        scan = _cloud(points_world).voxel_down_sample(self.voxel)
        points = np.asarray(scan.points)
        if not self.alignments:
            centroid_pose = np.eye(4)
            centroid_pose[:3, 3] = -points.mean(axis=0)
            if self._model is None:   # the first scan starts the model and defines the frame B
                self._set_model(_transform(points, centroid_pose))
                alignment = Alignment(time_s, centroid_pose, np.zeros((6, 6)), 1.0, 0.0, 0.0, True, False, 0.0,
                                      len(points))
            else:
                alignment = self._search(time_s, scan, points, centroid_pose, sensor_world, _orientation_candidates())
        else:
            alignment = self._track(time_s, scan, points, sensor_world)
        alignment.seconds = time.perf_counter() - start
        self.alignments.append(alignment)
        if alignment.ok and self._frames_in_model < self.model_frames:
            if self._frames_in_model:
                self._set_model(np.vstack([self._model_points, _transform(points, alignment.world_to_body)]))
            self._frames_in_model += 1
        return alignment

    def _track(self, time_s, scan, points, sensor_world) -> Alignment:
        predicted, has_motion = self._prediction()
        if has_motion:
            pose = self._icp(scan, predicted)
            alignment = self._judge(time_s, points, pose, predicted, sensor_world, True)
        else:
            alignment = self._search(time_s, scan, points, predicted, sensor_world)
        if not alignment.ok:
            pose = self._icp(scan, self._global(scan, predicted))
            retry = self._judge(time_s, points, pose, predicted, sensor_world, has_motion, global_init=True)
            if retry.ok or retry.tight_fitness > alignment.tight_fitness:
                alignment = retry
        return alignment

    def _prediction(self) -> tuple[np.ndarray, bool]:
        """Predicted pose and whether it carries the motion (two consecutive good frames)."""
        last = self.alignments[-2:]
        if len(last) == 2 and all(a.ok for a in last):
            return predict_pose(last[1].world_to_body, last[0].world_to_body), True
        good = [a for a in self.alignments if a.ok]
        return good[-1].world_to_body, False

    def _search(self, time_s, scan, points, start, sensor_world, turns=None) -> Alignment:
        """Without a motion prediction, ICP from rotations of the last pose spread over the
        largest turn expected between frames, keeping the best-checked result: a smooth body
        (the paper's ellipsoid) gives ICP a basin of only a few degrees."""
        best = None
        pivot = points.mean(axis=0)   # turn about the scan centroid (world), not the model origin
        for turn in _turn_candidates(SEARCH_TURN) if turns is None else turns:
            seed = start.copy()
            seed[:3, :3] = turn @ start[:3, :3]
            seed[:3, 3] = start[:3, 3] + start[:3, :3] @ pivot - seed[:3, :3] @ pivot
            pose = self._icp(scan, seed)
            candidate = self._judge(time_s, points, pose, start, sensor_world, False)
            if best is None or _score(candidate) > _score(best):
                best = candidate
        return best

    def _icp(self, scan, initial) -> np.ndarray:
        """Point-to-plane ICP, coarse (2x the correspondence distance) to fine, robust to outliers
        (Tukey loss) such as net threads lying on the debris."""
        pose = initial
        for distance, iterations in ((self.max_correspondence, 15), (self.max_correspondence / 3, 15)):
            result = reg.registration_icp(
                scan, self._model, distance, pose,
                reg.TransformationEstimationPointToPlane(reg.TukeyLoss(k=distance / 2)),
                reg.ICPConvergenceCriteria(1e-7, 1e-7, max_iteration=iterations))
            pose = result.transformation
        return pose

    def _global(self, scan, fallback) -> np.ndarray:
        """FPFH + RANSAC alignment of the scan to the model (for large, unpredicted motion)."""
        scan = o3d.geometry.PointCloud(scan)
        scan.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=4 * self.voxel, max_nn=30))
        features = reg.compute_fpfh_feature(scan, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * self.voxel, max_nn=100))
        result = reg.registration_ransac_based_on_feature_matching(
            scan, self._model, features, self._model_features(), True, 3 * self.voxel,
            reg.TransformationEstimationPointToPoint(False), 3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(3 * self.voxel)],
            reg.RANSACConvergenceCriteria(20000, 0.999))
        return result.transformation if result.fitness > 0 else fallback

    def _judge(self, time_s, points_world, pose, predicted, sensor_world, has_motion, global_init=False) -> Alignment:
        points_body = _transform(points_world, pose)
        _, nearest = self._tree.query(points_body)
        normals = self._model_normals[nearest]
        distance = np.einsum("ij,ij->i", points_body - self._model_points[nearest], normals)
        inliers = np.abs(distance) < self.max_correspondence / 3
        sigma = max(float(np.sqrt(np.mean(distance[inliers] ** 2))) if inliers.sum() > 6 else self.voxel, 1e-4)
        information = point_to_plane_information(points_body[inliers], normals[inliers], sigma)
        tight = float(np.mean(np.abs(distance) < 3 * sigma))
        body_to_world = np.linalg.inv(pose)
        model_world = _transform(self._model_points, body_to_world)
        range_scale = np.median(np.linalg.norm(points_world - sensor_world, axis=1))
        violation = free_space_violation(points_world, model_world, sensor_world, 2 * self.voxel / range_scale,
                                         3 * sigma + self.voxel)
        innovation = Rotation.from_matrix(pose[:3, :3] @ predicted[:3, :3].T).magnitude()
        ok = (tight >= MIN_TIGHT_FITNESS and violation <= MAX_FREE_SPACE_VIOLATION
              and (innovation <= MAX_INNOVATION or not has_motion))
        return Alignment(time_s, pose, information, tight, violation, innovation, bool(ok), global_init, 0.0,
                         len(points_world))
