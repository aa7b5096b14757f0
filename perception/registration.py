"""Point-cloud registration of the tumbling debris, and a check that an alignment really succeeded.

:class:`DebrisTracker` registers each scan to a model of the debris (frame-to-model): the
model is the union of the first ``model_frames`` registered scans (frame-to-frame while it
grows), in the body frame **B** (axes of the world frame at the first scan, origin at the
first scan's centroid), then frozen, so later frames do not drift. A known shape (catalogue,
CAD) can be given instead; it is the model from the start.

Each frame is seeded with the pose predicted from the last two (constant rotation and
translation rates) and refined by point-to-plane ICP with Tukey weights, coarse to fine. The
ICP is our own Gauss-Newton loop on one KD-tree of the model, built when the model changes
(Open3D's ``registration_icp`` builds one per call), and a level stops once a step no longer
moves the scan across the surface: on the near-axisymmetric debris, steps keep wandering about
the weakly seen long axis without improving the fit, so a test on the step size alone never stops.

Without a motion prediction the frame is searched: seed attitudes are ranked by a coarse ICP on
a heavily thinned scan, and only the best few distinct results are refined and checked. The
seeds are small turns of the last pose when it is one frame old (a good frame after a failed or
no frame), attitudes over all of SO(3) otherwise: the first frame against a known shape, and
after the track was lost for frames (a collision may have changed the spin a lot). When the
check below fails, the frame is started again from a global FPFH + RANSAC alignment to the model.

``update(..., gate=...)`` registers, when a motion prediction exists, only the scan points near
the predicted model: returns of other objects (net threads in front of the debris) are dropped.

Why a check of its own: Open3D's ``fitness`` and ``inlier_rmse`` are computed inside the
correspondence distance that ICP itself used, so an ICP that slid into a wrong pose (users
report it beyond ~45 degrees of initial error) still reports a high fitness. The check uses
figures that a wrong pose cannot all pass:

* **tight fitness**: share of scan points within 3 sigma of the model surface (sigma: the
  measured point-to-plane scatter), not within the loose ICP distance;
* **free-space violation**: share of the sensor's viewing directions along which the posed
  model lies in front of what the LiDAR measured: the ray would have stopped on the model,
  so the pose contradicts the measurement;
* **innovation**: rotation between the registered and the predicted pose; a jump larger than
  the motion allows (a symmetric flip of a near-symmetric body) fails even when the surface fits;
* **unseen model** (given the sensor's attitude and field of view): share of the posed model's
  directions in the field where no ray returned; the free-space violation only judges directions
  with returns, so a box-like body's half turn with its far parts sticking into empty space passed.

After a lost track a pose found by the search over all attitudes is not accepted alone: each passing
pose starts a chain, the next frames must continue it as one rigid motion (small-turn search, then
the constant-rate prediction within the innovation limit) until the chain's view of the body has
turned by CONFIRMING_VIEW_TURN (a box-like body's half turn is a rigid motion too, told apart only
when the side that differs comes into view), and only a single surviving chain is accepted, its
frames revised after the fact (``revised``). Two surviving chains leave every frame
failed: a wrong pose that passes is worse than a failed frame.

**Search budget.** A search over all attitudes costs seconds of CPU (1000 seeds), and a lost track
searches every frame: on the featured debris after the net contact 2-12 s CPU a frame, one stage 35
min wall. ``search_cpu_per_frame`` and ``search_cpu_per_run`` (s of ``time.process_time``) bound the
work of the frames that are not a plain ICP from the motion prediction (searches, chain
continuations, the global retry): a frame whose work passes its own limit, or the run's remaining
search time, is abandoned and recorded as not registered (``Alignment.over_budget``), never as the
best pose found so far; once the run's search time is spent, a lost track is not searched again
(tracked frames go on as before). CPU time depends on the machine: which frames a budget cuts may
differ between machines, and the answer names them.

The surface figures (tight fitness, sigma, information) are taken on about ``CHECKED_POINTS``
evenly spread scan points: shares to ~1 %, the information scaled to the whole scan.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import open3d as o3d
import trimesh
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from perception.nearest_grid import NearestPointGrid
from perception.map_growth import unmapped_surface
from perception.point_to_plane import point_to_plane_information, tukey_normal_equations
from perception.pose_motion import predict_pose, propagate_pose
from perception.visibility import free_space_violation, unseen_model_share, visible_side_centroid

reg = o3d.pipelines.registration

#: Acceptance limits of an alignment (see module docstring).
MIN_TIGHT_FITNESS = 0.8          # share of points within 3 sigma; a correct pose leaves only outliers (net, noise tails)
MAX_FREE_SPACE_VIOLATION = 0.05  # share of viewing directions where the model blocks a measured return
MAX_INNOVATION = np.radians(10.0)  # rad; the constant-rate prediction is good to ~0.2 deg for 2.3 rad/s tumbles at 10 Hz
SEARCH_TURN = np.radians(30.0)     # rad; largest turn between frames searched without a prediction (3 rad/s at 10 Hz, paper Sec. 2)
MIN_POINTS = 50                    # thinned scan points below which a frame is not registered (too few for the check)
#: With a map built from the scans as the model (model-free tracking), a model point blocks the free
#: space only if it lies in front of the nearest returns of its own viewing bin and of the 8 bins about
#: it (free_space_violation's lateral_bins): a silhouette off by up to one bin (2 voxels, 6 cm at any
#: range) is the map's own error, not free space. On the featured debris' collision frames (0.6-6.1 s,
#: 1.5-16 m) the true pose violated 0.055-0.076 on 11 of 56 frames, all at 11-16 m (limit 0.05; ICP from
#: it up to 0.096 on 14), the violating model points at grazing incidence on the silhouette, 10-32 cm in
#: front of the background return of their bin; the map's points lie 1.7 cm (median), 4.4 cm (p90) off the true surface. With one bin the
#: truth scores 0.000 on every frame (docs/perception.md, "Why the near-truth poses were rejected").
MAP_LATERAL_BINS = 1
MAX_UNSEEN = 0.02  # share of the posed model's viewing directions inside the field of view with no return near them

#: Effort of the ICP and of the search.
ICP_ITERATIONS = 15     # per level, at most; from a good prediction a level settles in 1-4
# A level has settled when a step moves the matched points by less than this (m, rms along their
# normals). Tighter fine levels only wander longer about the weak axis (1e-4 m: no better, 30 % slower).
COARSE_SETTLED = 1e-3   # m; the coarse level only has to reach the fine level's basin
FINE_SETTLED = 1.5e-4   # m; <1 % of the case's 2 cm range noise
SEARCH_SETTLED = 5e-3   # m; ranking search seeds: only their order matters (1e-2 ranks the truth low)
CHECKED_POINTS = 1000   # scan points in the coarse ICP level and in the check (shares to ~1 %)
SEARCH_VOXELS = 4       # the search ranks its seeds on the scan thinned to this many voxels (~300 points)
SEARCH_REFINED = 6      # best-ranked distinct seeds refined and checked (an ellipsoid's 4 symmetric poses, spares)
DISTINCT_TURN = np.radians(5.0)  # rad; ranked poses closer than this in attitude are one result
# Attitudes seeding the search after a lost track: with 240 the nearest was 15-23 deg from the truth and
# no seed reached it (featured debris after the net contact, 1.5-3.3 s); with 1000 it was found.
LOST_SEEDS = 1000
DEPTH_BUFFER_POINTS = 3000  # model points placing the visible-side seeds (a few per 12 cm cell of a 2 m body)
CONFIRMING_FRAMES = 3   # a re-acquired pose and the two frames continuing it (the last one predicted from the motion)
# ... and the chain must have seen the body from directions this far apart (in the body frame): a box-like
# body's half turn moves rigidly too, and is told from the truth only once the view shows the side that
# differs. Featured debris after the net contact (seed 0): a chain of the bus' half turn (176 deg off)
# passed 3 frames and was accepted at 3.7 s; it broke at 4.1 s, the view then turned 23 deg from its
# first frame. 45 deg [assumed]: about twice that.
CONFIRMING_VIEW_TURN = np.radians(45.0)
MAX_CHAINS = 3          # candidate poses of a re-acquisition followed through the next frames
# Best refined candidates of a search after a lost track searched again over small turns about themselves
# (_polished); 0: off. Tried offline, not adopted (docs/perception.md, "Free-space refinement, tried offline").
POLISHED = 0
# A lost track's re-acquisition is chosen by continuity with the attitude propagated at the last registered
# rates (DebrisTracker's continuity_turn) only this long (s) after the last registered frame. Measured on 10
# re-acquisitions after the net contact of the featured debris (model-free, percep14's and percep15's captures,
# bench/perception_reacquire_continuity.py): the debris turns at 1.1-1.6 rad/s, the net changes the rate by
# ~0.25 rad/s, the two-frame rate is off by up to 0.22 rad/s; the propagation lay 4-56 deg from the truth for
# gaps 0.3-2.1 s, but 48-104 deg for gaps 3.2-3.7 s. Beyond 2.5 s the truth may lie nearer the half turn of the
# propagation than the propagation: no choice by continuity there.
CONTINUITY_GAP = 2.5
SEARCH_SCREENED = 40    # best-fitting distinct seeds of a search over all attitudes screened by the check before refining
AMBIGUOUS_TURN = np.radians(15.0)  # rad; passing poses this far apart (beyond the known symmetries) start chains of their own


class SearchBudgetSpent(Exception):
    """A frame's search passed its CPU limit or the run's remaining search time (module docstring)."""


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
    """Identity and rotations spread over SO(3) (fixed seed: reproducible), for a frame without
    a usable last pose (first frame against a known model, track lost for frames)."""
    return [np.eye(3)] + list(Rotation.random(count, random_state=12345).as_matrix())


def _seeds(start, pivot, turns) -> list[np.ndarray]:
    """world_to_body poses: ``start`` turned by each of ``turns`` (body frame) about the world
    point ``pivot``, which keeps its place in B (turning about the model origin would swing the
    scan off the model)."""
    seeds = []
    for turn in turns:
        seed = start.copy()
        seed[:3, :3] = turn @ start[:3, :3]
        seed[:3, 3] = start[:3, 3] + start[:3, :3] @ pivot - seed[:3, :3] @ pivot
        seeds.append(seed)
    return seeds


def _turn_angle(rotation, other) -> float:
    """Angle (rad) of the rotation between two rotation matrices."""
    return float(np.arccos(np.clip((np.trace(rotation @ other.T) - 1) / 2, -1.0, 1.0)))


def _distinct(poses, count) -> list[np.ndarray]:
    """The first ``count`` poses whose attitudes differ by more than DISTINCT_TURN from all kept before."""
    kept = []
    for pose in poses:
        if all(_turn_angle(pose[:3, :3], other[:3, :3]) > DISTINCT_TURN for other in kept):
            kept.append(pose)
            if len(kept) == count:
                break
    return kept


def _view_turn(chain) -> float:
    """Largest angle (rad) between a chain's viewing direction at its second frame and at a later one,
    in the body frame: how far round the body the chain has looked as one motion. From the second
    frame: the jump from the searched pose to the small-turn search after it is not a view of the
    body from elsewhere (a wrong start's jump measured 48 deg at once)."""
    if len(chain) < 3:
        return 0.0
    first = chain[1].view_body
    return max(float(np.arccos(np.clip(first @ later.view_body, -1.0, 1.0))) for later in chain[2:])


def _score(alignment) -> float:
    """Ranks candidate alignments: checks passed first, then tight fitness less the shares of
    directions where the model blocks a return or lies where no ray returned."""
    return float(alignment.ok) + alignment.tight_fitness - alignment.free_space_violation - alignment.unseen


def failed_checks(alignment, has_motion) -> list[str]:
    """Names of the checks of the frame (module docstring) that ``alignment`` fails: "fitness" (tight
    fitness below MIN_TIGHT_FITNESS), "free space" (violation above MAX_FREE_SPACE_VIOLATION), "unseen"
    (unseen model share above MAX_UNSEEN), "innovation" (turn from the prediction above MAX_INNOVATION,
    judged only ``has_motion``); empty for a passing alignment, which is how :meth:`DebrisTracker._judge` sets
    ``ok``. Written as "not within the limit", so a non-finite figure fails its check."""
    failed = [name for name, bad in (("fitness", not alignment.tight_fitness >= MIN_TIGHT_FITNESS),
                                     ("free space", not alignment.free_space_violation <= MAX_FREE_SPACE_VIOLATION),
                                     ("unseen", not alignment.unseen <= MAX_UNSEEN),
                                     ("innovation", has_motion and not alignment.innovation <= MAX_INNOVATION)) if bad]
    return failed


@dataclass
class Alignment:
    """One frame's registration.

    world_to_body : (4, 4) float   Transform taking world points into the model frame B.
    information : (6, 6) float     Point-to-plane information of (rotation, translation), B frame,
                                   left perturbation of ``world_to_body`` (1/rad^2, 1/m^2).
    n_points : int                 Scan points registered (after thinning and gating).
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
    cpu_seconds: float = 0.0   # process time of the registration (s; all threads, at least the one-core time)
    unseen: float = 0.0        # share of the posed model's directions in the field of view with no return near them
    over_budget: bool = False  # the frame's search was abandoned: its CPU limit or the run's search time spent
    view_body: np.ndarray | None = None  # unit direction sensor -> scan centroid in frame B at this pose
    searched: bool = False     # the frame needed more than an ICP from the motion prediction (counts against the budget)

    @property
    def body_to_world(self) -> np.ndarray:
        return np.linalg.inv(self.world_to_body)


def _cloud(points, normals_radius=None) -> o3d.geometry.PointCloud:
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, float)))
    if normals_radius:
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=normals_radius, max_nn=30))
    return cloud


def _thinned(points, count) -> np.ndarray:
    """Every k-th point, k the largest keeping at least ``count`` (all when fewer): the stride runs
    over the whole list (Open3D's voxel output in hash order, a ray-cast scan in scan-line order),
    so the points kept spread over the whole surface."""
    return points[::max(1, len(points) // count)]


def _sample_spacing(points) -> float:
    """Median distance (m) from a scan point to its nearest neighbour: the voxel when the scan is
    denser than the thinning, the LiDAR's ray spacing at far range. Taken over every 4th point
    (the same median, 1.5 instead of 4.5 ms for 3000 points)."""
    distance, _ = cKDTree(points, balanced_tree=False).query(points[::4], k=2)
    return float(np.median(distance[:, 1]))


def _transform(points, matrix) -> np.ndarray:
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def _rigid_inverse(matrix) -> np.ndarray:
    inverse = np.eye(4)
    inverse[:3, :3] = matrix[:3, :3].T
    inverse[:3, 3] = -matrix[:3, :3].T @ matrix[:3, 3]
    return inverse


def _twist(step) -> np.ndarray:
    """Transform of a (rotation vector, translation) step (6,) (rad, m); Rodrigues' formula."""
    angle = np.linalg.norm(step[:3])
    k = np.array([[0.0, -step[2], step[1]], [step[2], 0.0, -step[0]], [-step[1], step[0], 0.0]])
    matrix = np.eye(4)
    if angle > 0:
        matrix[:3, :3] += np.sin(angle) / angle * k + (1 - np.cos(angle)) / angle**2 * (k @ k)
    matrix[:3, 3] = step[3:]
    return matrix


def known_shape_model(mesh, voxel, seed) -> tuple[np.ndarray, np.ndarray]:
    """Registration model of a known debris mesh (frame B = target frame): surface samples (n, 3)
    (m) about 0.4 voxel apart (denser than the thinned scan), with their faces' exact outward normals (n, 3).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The debris surface (m, target frame, which becomes frame B).
    voxel : float
        The tracker's scan thinning (m); sets the sample spacing.
    seed : int
        Seed of the surface sampling (reproducible samples).

    Returns
    -------
    points_body : (n, 3) float
        Surface samples (m, frame B).
    normals_body : (n, 3) float
        Outward unit normals of the faces they lie on (frame B).
    """
    count = int(np.ceil(mesh.area / (0.4 * voxel) ** 2))
    points, faces = trimesh.sample.sample_surface(mesh, count, seed=seed)
    return points, mesh.face_normals[faces]


def nearer_propagation(candidates, propagated, limit) -> list:
    """The candidate alignments whose attitude lies within ``limit`` (rad) of ``propagated``
    (world_to_body, (4, 4)), best-scored first (:func:`_score`).

    A half turn that maps a box-like body onto itself fits the scans as well as the truth; what tells
    them apart is the motion: the attitude cannot jump by more than the rates' error times the time
    lost. With ``limit`` below 90 deg only one of a pose and its half turn about any axis can be kept.
    """
    kept = [c for c in candidates if _turn_angle(c.world_to_body[:3, :3], propagated[:3, :3]) <= limit]
    return sorted(kept, key=_score, reverse=True)


def _chain_prediction(chain, time_s) -> np.ndarray:
    """world_to_body of a candidate chain (a list of :class:`Alignment`, at least two) at ``time_s`` (s):
    :func:`predict_pose` from its last two frames at the next frame, :func:`propagate_pose` at their
    rates across frames the chain missed."""
    last, before = chain[-1], chain[-2]
    steps = (time_s - last.time) / (last.time - before.time)
    if abs(steps - 1.0) < 1e-6:
        return predict_pose(last.world_to_body, before.world_to_body)
    return propagate_pose(last.world_to_body, before.world_to_body, steps)


class DebrisTracker:
    """Frame-to-model registration of one rigid debris (see module docstring).

    Parameters
    ----------
    voxel : float               Scan thinning (m); also the model's point spacing.
    max_correspondence : float  ICP correspondence distance at the coarse level (m).
    model_frames : int          Frames merged into the model before it is frozen.
    model_points_body : (n, 3)  Known shape (m, frame B), optional: the model from the start.
    model_normals_body : (n, 3) Outward unit normals of those points (frame B), optional: a
                                known mesh's face normals, used as they are (no thinning, no
                                normal estimation, which blurs a faceted surface's normals over
                                a few voxels and biased the fitted inertia ratios by ~0.04 %).
    symmetries_body : list of (4, 4), optional
                                Transforms of frame B that map the model onto itself (the
                                shape's half turns, :mod:`perception.shape`). A frame searched
                                without a motion prediction takes the variant nearest the last
                                pose: the surface cannot tell them apart, and a jump between them
                                breaks the torque-free fit of the free flight (seen once after a
                                failed frame at 18 m: a 176 deg flip made the collision "not observable").
    field_of_view : (2,) float, optional
                                The LiDAR's full field of view (rad): azimuth, elevation. With it, and
                                the sensor attitude given to :meth:`update`, the check also counts the
                                model's directions in the field where the rays met nothing
                                (:func:`unseen_model_share`).
    ray_spacing : float         The LiDAR's larger angular step between rays (rad); the unseen-model
                                check's bins span at least 3 of them.
    seed : int                  Seed of the global (RANSAC) alignments: Open3D's generator is
                                re-seeded with ``seed`` + the frame number before each, so a run
                                repeats exactly (unseeded, two runs of one case tracked 189 and
                                194 of 201 frames once a re-acquisition was needed).
    search_cpu_per_frame : float
                                Largest CPU time (s) of one frame's search work (searches, chain
                                continuations, global retry); beyond it the frame is not registered.
                                Default: no limit.
    search_cpu_per_run : float  Largest CPU time (s) of all frames' search work together; once spent,
                                a lost track is not searched again. Default: no limit.
    free_space_lateral_bins : int
                                Viewing bins about a model point that the free-space check also
                                compares it with (``free_space_violation``'s ``lateral_bins``): 0 for
                                an exact mesh, :data:`MAP_LATERAL_BINS` for a map built from scans.
    continuity_turn : float, optional
                                Largest turn (rad) between a re-acquired attitude after a lost track and
                                the attitude propagated at the last registered rates
                                (:meth:`propagated_world_to_body`): the search also starts from the
                                propagation, and candidates beyond it start no chain. A box-like body's
                                half turn fits the scans as well as the truth; the rates do not allow it
                                (:func:`nearer_propagation`). Default None: off.
    chain_missed_frames : int   Consecutive frames a candidate chain after a lost track (of at least two
                                frames, so with a motion) may fail and still go on, its next frame predicted
                                across the gap; the failed frames stay failed. 0 (default): a chain is
                                dropped at its first failed frame.
    grow_map : bool             After a lost track's re-acquisition is confirmed (a single chain that passed
                                every check of each of its frames and turned its view by CONFIRMING_VIEW_TURN),
                                the chain's frames and every later frame registered from the motion prediction
                                that passes every check add the surface their scans show and the map lacks
                                (:meth:`_grow_map`). Pending chains' frames, failed frames, searched frames
                                without a motion and all frames before the first confirmed re-acquisition add
                                nothing. False (default): the model stays as given.
    """

    def __init__(self, voxel=0.03, max_correspondence=0.1, model_frames=30, model_points_body=None,
                 model_normals_body=None, symmetries_body=None, seed=0, field_of_view=None, ray_spacing=0.0,
                 search_cpu_per_frame=np.inf, search_cpu_per_run=np.inf, free_space_lateral_bins=0,
                 continuity_turn=None, chain_missed_frames=0, grow_map=False):
        self.voxel = voxel
        self.grow_map = bool(grow_map)
        self._reacquired = False             # a re-acquisition has been confirmed (the map may grow from then on)
        self._chain_scans = {}               # time (s) -> thinned scan (m, world) of frames of pending chains
        self.map_growth = []                 # one dict per map growth: time (s), frames, points added
        self.continuity_turn = continuity_turn
        self.chain_missed_frames = int(chain_missed_frames)
        # None: off; a list: every candidate pose a lost track's search or chain produced, one dict each
        # (:meth:`_log_candidates`), to see offline why a pose was or was not re-acquired
        self.candidate_log = None
        self.free_space_lateral_bins = int(free_space_lateral_bins)
        self.search_cpu_per_frame = float(search_cpu_per_frame)
        self.search_cpu_per_run = float(search_cpu_per_run)
        self.search_cpu_spent = 0.0          # CPU time (s) of the frames' search work so far (the run's budget)
        self._frame_deadline = np.inf        # process time (s) at which the frame's search work is abandoned
        self.field_of_view = None if field_of_view is None else np.asarray(field_of_view, float)
        self.ray_spacing = float(ray_spacing)
        self._frame_sensor_to_world = None   # sensor attitude of the frame being registered, for the unseen-model check
        self._passing_alignments = []        # passing alignments of the last search other than the kept one
        self._searched = False               # the frame being registered has done search work
        self._chains = []                    # candidate pose sequences after a lost track (see _continue_chains)
        self._chain_misses = []              # consecutive frames each chain has failed (at most chain_missed_frames)
        self.revised = []                    # indices of earlier frames whose alignment the last update replaced
        self.symmetries_body = [np.eye(4)] if symmetries_body is None else [np.asarray(s, float) for s in symmetries_body]
        self.seed = seed
        self._frame_spacing = None   # scan sample spacing (m) of the frame being registered
        self._frame_returns = None   # all returns of the frame being registered (m, world), for the free-space check
        self.max_correspondence = max_correspondence
        self.model_frames = model_frames
        self.alignments: list[Alignment] = []
        self._model = None
        self._frames_in_model = 0
        if model_points_body is not None:
            # A known shape (catalogue or CAD): the model is complete and frozen from the start.
            self._set_model(model_points_body, model_normals_body)
            self._frames_in_model = model_frames
            self._freeze_model()

    # -- model -----------------------------------------------------------------------
    def _set_model(self, points_body, normals_body=None):
        cloud = _cloud(points_body)
        if normals_body is None:
            cloud = cloud.voxel_down_sample(self.voxel)
            cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=4 * self.voxel, max_nn=30))
        else:
            cloud.normals = o3d.utility.Vector3dVector(np.asarray(normals_body, float))
        # ICP and the surface check use every model point; the global search (FPFH) and the
        # free-space check a voxel-spaced copy, which is all they resolve.
        self._model_points = np.asarray(cloud.points)
        self._model_normals = np.asarray(cloud.normals)
        self._tree = cKDTree(self._model_points)
        self._nearest = self._tree
        self._model = cloud if normals_body is None else cloud.voxel_down_sample(self.voxel)
        self._coarse_points = np.asarray(self._model.points)
        # (a voxel thinning averages the normals it merges: back to unit length)
        normals = np.asarray(self._model.normals)
        self._coarse_normals = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
        self._features = None

    @property
    def model_points_body(self) -> np.ndarray:
        """(n, 3) the debris model (m), frame B."""
        return self._model_points

    def distance_to_model(self, points_body, upper) -> np.ndarray:
        """Distance (n,) (m) of points (n, 3) (m, frame B) to the nearest model point; inf beyond ``upper`` (m).

        Parameters
        ----------
        points_body : (n, 3) float
            Query points (m, frame B).
        upper : float
            Largest distance looked for (m).
        """
        return self._tree.query(points_body, distance_upper_bound=upper)[0]

    def _model_features(self):
        if self._features is None:
            self._features = reg.compute_fpfh_feature(
                self._model, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * self.voxel, max_nn=100))
        return self._features

    def _start_model(self, time_s, points) -> Alignment:
        """The first scan becomes the model; its centroid is the origin of B."""
        pose = np.eye(4)
        pose[:3, 3] = -points.mean(axis=0)
        self._set_model(_transform(points, pose))
        return Alignment(time_s, pose, np.zeros((6, 6)), 1.0, 0.0, 0.0, True, False, 0.0, len(points))

    def _grow_model(self, alignment, points):
        """Merges a good scan into the model until ``model_frames`` are in (the first scan is the model already)."""
        if alignment.ok and self._frames_in_model < self.model_frames:
            if self._frames_in_model:
                self._set_model(np.vstack([self._model_points, _transform(points, alignment.world_to_body)]))
            self._frames_in_model += 1
            if self._frames_in_model == self.model_frames:
                self._freeze_model()

    def _freeze_model(self):
        """The model no longer changes: ICP and the check look nearest points up in a table
        (:mod:`perception.nearest_grid`, ~10x faster than the KD-tree) of a third of a voxel."""
        self._nearest = NearestPointGrid(self._model_points, self.voxel / 3, self.max_correspondence)

    def _grow_after_reacquisition(self, alignment, points_world, tracked_with_motion) -> None:
        """The map growth rule (``grow_map``): the scans of pending chains' frames are kept; when a chain is
        confirmed (``revised``), its frames and the confirming one grow the map, in time order; afterwards a
        frame does when it passed every check from the motion prediction (``tracked_with_motion``)."""
        if self._chains:
            self._chain_scans[alignment.time] = points_world
        if self.revised:
            self._reacquired = True
            frames = [(self.alignments[i], self._chain_scans.get(self.alignments[i].time)) for i in self.revised]
            frames = sorted(frames + [(alignment, points_world)], key=lambda frame: frame[0].time)
        elif self._reacquired and alignment.ok and tracked_with_motion:
            frames = [(alignment, points_world)]
        else:
            frames = []
        if not self._chains:
            self._chain_scans = {}
        for confirmed, points in frames:
            if points is not None and confirmed.ok:
                self._grow_map(confirmed.time, _transform(points, confirmed.world_to_body))

    def _grow_map(self, time_s, points_body) -> int:
        """Adds to the map (the model, frame B) the surface a registered scan (n, 3) (m, frame B) shows and the
        map lacks (:func:`perception.map_growth.unmapped_surface`); the points already in the map are kept as
        they are. Returns the number of points added (each growth recorded in ``map_growth``)."""
        points, normals = unmapped_surface(points_body, self._model_points, self._tree, self.voxel,
                                           self.max_correspondence)
        if not len(points):
            return 0
        self._set_model(np.vstack([self._model_points, points]), np.vstack([self._model_normals, normals]))
        self._freeze_model()
        self.map_growth.append({"time": float(time_s), "points_added": len(points), "map_points": len(self._model_points)})
        return len(points)

    # -- one frame -------------------------------------------------------------------
    def update(self, time_s, points_world, sensor_world, gate=None, all_returns_world=None,
               sensor_to_world=None) -> Alignment:
        """Register one scan (n, 3) (m, world frame) taken from ``sensor_world`` (3,) (m).

        Parameters
        ----------
        time_s : float
            Time of the scan (s); recorded in the :class:`Alignment`.
        points_world : (n, 3) float
            Scan returns (m, world frame).
        sensor_world : (3,) float
            Sensor position at the scan (m, world frame), for the free-space check.
        gate : float, optional
            With a motion prediction, register only the scan points within ``gate`` (m) of the
            model at the predicted pose (to the nearest model point, ``voxel`` apart): returns of
            other objects, e.g. net threads in front of the debris, are dropped.
        all_returns_world : (m, 3) float, optional
            Every return of the frame (m, world), when ``points_world`` is a selection of them (the
            debris' returns without those taken as net): the free-space check needs all of them.
            A return of anything shows free space up to it; without the returns dropped as net, a
            bin where the net lies on the debris keeps only deeper returns and the debris surface
            in front of them counts as a contradiction. Measured on the featured debris at the first
            collision frame (net 7 cm off the bus): correct pose (0.2 deg from the prediction,
            tight fitness 0.99) rejected with 7.4 % of the bins violated (limit 5 %).
        sensor_to_world : (3, 3) float, optional
            Sensor -> world rotation at the scan. With the tracker's ``field_of_view``, a pose whose
            model covers more than MAX_UNSEEN of its directions in the field where no ray returned
            fails the check (:func:`unseen_model_share`); needs ``all_returns_world`` when
            ``points_world`` is a selection.

        Returns
        -------
        Alignment
            The frame's pose (world -> B), information and check figures; also appended to
            ``alignments``.
        """
        start, cpu_start = time.perf_counter(), time.process_time()
        self._frame_deadline = cpu_start + min(self.search_cpu_per_frame, self.search_cpu_per_run - self.search_cpu_spent)
        self.revised = []
        self._frame_returns = None if all_returns_world is None else np.asarray(all_returns_world, float)
        self._frame_sensor_to_world = None if sensor_to_world is None else np.asarray(sensor_to_world, float)
        scan = _cloud(points_world).voxel_down_sample(self.voxel)
        tracked_with_motion = False
        if self._model is None:   # the first scan starts the model and defines the frame B
            alignment = self._start_model(time_s, np.asarray(scan.points))
        else:
            predicted, has_motion = self.prediction()
            if gate is not None and has_motion:
                scan = self._gated(scan, predicted, gate)
            alignment = self._track_within_budget(time_s, scan, predicted, has_motion, sensor_world)
            self._frame_spacing = None
            tracked_with_motion = has_motion
        self._frame_returns = self._frame_sensor_to_world = None
        alignment.seconds = time.perf_counter() - start
        alignment.cpu_seconds = time.process_time() - cpu_start
        if alignment.searched:
            self.search_cpu_spent += alignment.cpu_seconds
        self.alignments.append(alignment)
        self._grow_model(alignment, np.asarray(scan.points))
        if self.grow_map and len(self.alignments) > 1:
            self._grow_after_reacquisition(alignment, np.asarray(scan.points), tracked_with_motion)
        return alignment

    def _gated(self, scan, predicted, gate) -> o3d.geometry.PointCloud:
        """The scan points within ``gate`` (m) of a model point at the ``predicted`` pose."""
        gap, _ = self._tree.query(_transform(np.asarray(scan.points), predicted), distance_upper_bound=gate)
        return scan.select_by_index(np.flatnonzero(np.isfinite(gap)))

    def _track_within_budget(self, time_s, scan, predicted, has_motion, sensor_world) -> Alignment:
        """:meth:`_track`, its search work abandoned at the frame's deadline (module docstring, "Search
        budget"): the frame is then not registered, its pose the prediction (or the last good pose), and
        candidate chains are dropped (a chain continues frame by frame only)."""
        self._searched = False
        try:
            alignment = self._track(time_s, scan, predicted, has_motion, sensor_world)
        except SearchBudgetSpent:
            self._chains, self._chain_misses, self._passing_alignments = [], [], []
            pose = predicted if predicted is not None else np.eye(4)
            alignment = Alignment(time_s, pose, np.zeros((6, 6)), 0.0, 1.0, np.inf, False, False, 0.0,
                                  len(scan.points), over_budget=True)
        alignment.searched = self._searched
        return alignment

    def _spend(self) -> None:
        """Marks the frame as doing search work; raises :class:`SearchBudgetSpent` past its deadline."""
        self._searched = True
        if time.process_time() > self._frame_deadline:
            raise SearchBudgetSpent

    def _track(self, time_s, scan, predicted, has_motion, sensor_world) -> Alignment:
        points = np.asarray(scan.points)
        # one spacing per frame for every check of it (a search checks up to SEARCH_REFINED poses)
        self._frame_spacing = _sample_spacing(points) if len(points) >= MIN_POINTS else None
        if len(points) < MIN_POINTS:   # e.g. everything gated away: record the frame as failed, do not guess
            self._chains, self._chain_misses = [], []   # a chain continues frame by frame only
            pose = predicted if predicted is not None else np.eye(4)
            return Alignment(time_s, pose, np.zeros((6, 6)), 0.0, 1.0, np.inf, False, False, 0.0, len(points))
        if self._chains:
            return self._continue_chains(time_s, scan, sensor_world)
        if has_motion:
            alignment = self._judge(time_s, points, self._icp(scan, predicted), predicted, sensor_world, True)
        elif self.alignments and self.alignments[-1].ok:
            # One frame since the last good pose: the body turned by at most SEARCH_TURN.
            alignment = self._search(time_s, scan, predicted, _turn_candidates(SEARCH_TURN), sensor_world,
                                     label="one frame after a good one")
        else:
            # No pose yet, or the track was lost for frames (a collision may have changed the spin a lot).
            alignment = self._search(time_s, scan, self._acquisition_start(points, predicted),
                                     _orientation_candidates(LOST_SEEDS if self.alignments else 240), sensor_world,
                                     visible_side=True, polish=bool(self.alignments), label="all attitudes")
            if self.continuity_turn is not None and any(a.ok for a in self.alignments):
                alignment = self._continuous_candidates(time_s, scan, alignment, sensor_world)
            if alignment.ok and any(a.ok for a in self.alignments):
                return self._start_chains(alignment)   # a lost track: the motion decides (_continue_chains)
        if not alignment.ok:
            alignment = self._retry_from_global(time_s, scan, alignment, predicted, has_motion, sensor_world)
        return alignment

    def propagated_world_to_body(self, time_s) -> np.ndarray | None:
        """world_to_body at ``time_s`` (s) carried from the last two consecutive good frames at their
        constant rotation and translation rates (:func:`propagate_pose`); None without such a pair."""
        for later, earlier in zip(self.alignments[::-1], self.alignments[-2::-1]):
            if later.ok and earlier.ok and later.time > earlier.time:
                return propagate_pose(later.world_to_body, earlier.world_to_body,
                                      (time_s - later.time) / (later.time - earlier.time))
        return None

    def _continuous_candidates(self, time_s, scan, found, sensor_world) -> Alignment:
        """A lost track's search result ``found`` and its other passing poses, joined by a small-turn
        search about the propagated attitude, kept only within ``continuity_turn`` of it
        (:func:`nearer_propagation`); the best-scored kept one is returned (the others in
        ``_passing_alignments``), or ``found`` marked failed when none is kept. More than
        CONTINUITY_GAP after the last good frame, ``found`` as it is (the propagation no longer tells)."""
        propagated = self.propagated_world_to_body(time_s)
        last_good = next((a.time for a in reversed(self.alignments) if a.ok), None)
        if propagated is None or time_s - last_good > CONTINUITY_GAP:
            return found
        candidates = [found] + self._passing_alignments
        from_propagation = self._search(time_s, scan, propagated, _turn_candidates(SEARCH_TURN), sensor_world,
                                        visible_side=True, label="small turns of the propagation")
        candidates += [from_propagation] + self._passing_alignments
        kept = nearer_propagation([c for c in candidates if c.ok], propagated, self.continuity_turn)
        if not kept:
            self._passing_alignments = []
            return Alignment(**{**found.__dict__, "ok": False})
        self._passing_alignments = kept[1:]
        return kept[0]

    def _log_candidates(self, time_s, stage, candidates, has_motion) -> None:
        """Appends to ``candidate_log`` (when on) one dict per candidate: time (s), stage, world_to_body,
        the check's figures, the checks failed (:func:`failed_checks`) and the turn from the attitude
        propagated at the last registered rates (rad; NaN without it)."""
        if self.candidate_log is None:
            return
        propagated = self.propagated_world_to_body(time_s)
        for candidate in candidates:
            turn = np.nan if propagated is None else _turn_angle(candidate.world_to_body[:3, :3], propagated[:3, :3])
            self.candidate_log.append({
                "time": time_s, "stage": stage, "world_to_body": candidate.world_to_body.copy(), "ok": candidate.ok,
                "tight_fitness": candidate.tight_fitness, "free_space_violation": candidate.free_space_violation,
                "unseen": candidate.unseen, "innovation": candidate.innovation,
                "failed": failed_checks(candidate, has_motion), "turn_from_propagation": turn})

    def _log_chains(self, time_s, survivors) -> None:
        """Appends to ``candidate_log`` (when on) the chains surviving a frame: their lengths and view
        turns (rad, :func:`_view_turn`), the numbers a confirmation waits for."""
        if self.candidate_log is not None:
            self.candidate_log.append({"time": time_s, "stage": "chains", "lengths": [len(c) for c in survivors],
                                       "view_turns": [_view_turn(c) for c in survivors]})

    def _start_chains(self, alignment) -> Alignment:
        """The passing poses of a search after a lost track (the kept one and the others, one per
        attitude beyond the model's known symmetries, at most MAX_CHAINS), each the start of a chain
        the next frames must continue (:meth:`_continue_chains`); the frame counts as failed until then."""
        starts = [alignment]
        for other in self._passing_alignments:
            if len(starts) < MAX_CHAINS and all(
                    min(_turn_angle((symmetry @ other.world_to_body)[:3, :3], kept.world_to_body[:3, :3])
                        for symmetry in self.symmetries_body) > AMBIGUOUS_TURN for kept in starts):
                starts.append(other)
        self._chains = [[start] for start in starts]
        self._chain_misses = [0] * len(self._chains)
        return Alignment(**{**alignment.__dict__, "ok": False})

    def _continue_chains(self, time_s, scan, sensor_world) -> Alignment:
        """One more frame for each candidate chain after a lost track: the second frame by the
        small-turn search from the chain's pose, the third by ICP from the constant-rate prediction
        of the two (the check with the innovation limit: one angular velocity). Chains failing the
        check are dropped, or, with ``chain_missed_frames``, carried over up to that many consecutive failed
        frames (predicted across them, :func:`_chain_prediction`; a chain then alive without this frame still
        counts as an alternative). After CONFIRMING_FRAMES frames, and once the chain's view of the body has
        turned by CONFIRMING_VIEW_TURN (a half turn of a box-like body moves rigidly too and is told apart
        only when the differing side comes into view), a single surviving chain is the track: its
        frames replace the pending ones (their indices in ``revised``). Several surviving chains are
        poses the scans cannot tell apart: every frame of them stays failed.

        Why: a box-like body's near half turn can pass every check of one frame (featured debris,
        2.2 s after the start of the run in: tight fitness 0.99, free-space violation 0.046, 177 deg
        from the truth), and the paper's ellipsoid after a lost track passed a pose 61 deg from the
        truth beside the truth (a turn about its near-symmetry axis); a wrong pose the next frames
        continue as one rigid motion is much rarer than one that fits one frame.
        """
        points = np.asarray(scan.points)
        alive, misses, tried = [], [], []
        for chain, missed in zip(self._chains, self._chain_misses):
            self._spend()
            if len(chain) == 1:
                # seeds on the visible side: the debris may have moved beyond the coarse ICP's reach in
                # one frame (0.3 m at the featured debris' 3.15 m/s after the contact; seeds at the
                # last pose's place ended 30 deg off the truth there)
                candidate = self._search(time_s, scan, chain[-1].world_to_body, _turn_candidates(SEARCH_TURN),
                                         sensor_world, visible_side=True, label="chain's second frame")
            else:
                predicted = _chain_prediction(chain, time_s)
                candidate = self._judge(time_s, points, self._icp(scan, predicted), predicted, sensor_world, True)
                self._log_candidates(time_s, f"chain's frame {len(chain) + 1}", [candidate], has_motion=True)
            tried.append(candidate)
            if candidate.ok:
                alive.append(chain + [candidate])
                misses.append(0)
            elif len(chain) >= 2 and missed < self.chain_missed_frames:
                alive.append(chain)   # carried over this failed frame
                misses.append(missed + 1)
        self._chains, self._chain_misses = alive, misses
        self._log_chains(time_s, alive)
        survivors = [chain for chain in alive if any(chain[-1] is candidate for candidate in tried)]   # passed this frame
        if not survivors:
            best = max(tried, key=_score)
            return Alignment(**{**best.__dict__, "ok": False})
        if len(survivors[0]) < CONFIRMING_FRAMES or _view_turn(survivors[0]) < CONFIRMING_VIEW_TURN:
            return Alignment(**{**survivors[0][-1].__dict__, "ok": False})
        self._chains, self._chain_misses = [], []
        if len(alive) > 1:   # two rigid motions explain the scans: no answer rather than a guess
            return Alignment(**{**survivors[0][-1].__dict__, "ok": False})
        self._revise(survivors[0][:-1])
        return survivors[0][-1]

    def _revise(self, confirmed) -> None:
        """The pending frames of a confirmed chain (its alignments but the current frame's) replace the
        frames registered at their times (indices in ``revised``)."""
        index_at = {alignment.time: index for index, alignment in enumerate(self.alignments)}
        for alignment in confirmed:
            index = index_at[alignment.time]
            previous = self.alignments[index]
            self.alignments[index] = Alignment(**{**alignment.__dict__, "time": previous.time,
                                                  "seconds": previous.seconds, "cpu_seconds": previous.cpu_seconds})
            self.revised.append(index)

    def _retry_from_global(self, time_s, scan, failed, predicted, has_motion, sensor_world) -> Alignment:
        """The frame again from FPFH + RANSAC; kept when it passes or fits tighter than ``failed``."""
        self._spend()
        reference = failed.world_to_body if predicted is None else predicted
        pose = self._nearest_variant(self._icp(scan, self._global(scan, reference)), reference)
        points = np.asarray(scan.points)
        retry = self._judge(time_s, points, pose, reference, sensor_world, has_motion, global_init=True)
        self._log_candidates(time_s, "global (FPFH + RANSAC)", [retry], has_motion)
        return retry if retry.ok or retry.tight_fitness > failed.tight_fitness else failed

    def predicted_world_to_body(self) -> np.ndarray | None:
        """The next frame's expected pose (world -> B): from the motion of the last two good
        frames, else the last good pose; None before any good frame."""
        return self.prediction()[0]

    def prediction(self) -> tuple[np.ndarray | None, bool]:
        """Predicted pose (None before any good frame) and whether it carries the motion (two
        consecutive good frames); without the motion, the last good pose."""
        last = self.alignments[-2:]
        if len(last) == 2 and all(a.ok for a in last):
            return predict_pose(last[1].world_to_body, last[0].world_to_body), True
        return next((a.world_to_body for a in reversed(self.alignments) if a.ok), None), False

    def _acquisition_start(self, points, last) -> np.ndarray:
        """Pose putting the scan centroid on the model centroid, at the last good attitude if any."""
        start = np.eye(4)
        if last is not None:
            start[:3, :3] = last[:3, :3]
        start[:3, 3] = self._model_points.mean(axis=0) - start[:3, :3] @ points.mean(axis=0)
        return start

    def _search(self, time_s, scan, start, turns, sensor_world, visible_side=False, polish=False,
                label="search") -> Alignment:
        """Without a motion prediction: ``start`` turned by each of ``turns`` about the scan
        centroid (a smooth body, the paper's ellipsoid, gives ICP a basin of only a few degrees),
        each seed ranked by one coarse ICP level on a heavily thinned scan; the best SEARCH_REFINED
        distinct results are refined and checked, the best-checked kept (the other passing ones in
        ``self._passing_alignments``). With ``visible_side`` each seed's scan centroid is put on the centroid of
        the model's side the sensor sees at that attitude (:meth:`_visible_side_seeds`). With ``polish``
        the best refined results are searched again about themselves (:meth:`_polished`). ``label`` names
        the search in ``candidate_log``."""
        points = np.asarray(scan.points)
        thin = np.asarray(scan.voxel_down_sample(SEARCH_VOXELS * self.voxel).points)
        seeds = (self._visible_side_seeds(start, points, sensor_world, turns) if visible_side
                 else _seeds(start, points.mean(axis=0), turns))
        fits = []
        for seed in seeds:
            self._spend()
            fits.append(self._icp_level(thin, seed, self.max_correspondence, SEARCH_SETTLED))
        fits.sort(key=lambda fit: -fit[1])
        ranked = [pose for pose, _ in fits]
        if visible_side:
            # A half turn of a box-like body fits the seen side about as well as the truth and outranks
            # it on the fit alone; the free space (both checks) tells them apart before the refinement.
            ranked = _distinct(ranked, SEARCH_SCREENED)
            screened = []
            for pose in ranked:
                self._spend()
                screened.append(self._judge(time_s, points, pose, start, sensor_world, False))
            ranked = [ranked[i] for i in np.argsort([-_score(a) for a in screened], kind="stable")]
        refined = []
        for pose in _distinct(ranked, SEARCH_REFINED):
            self._spend()
            refined.append(self._judge(time_s, points, self._nearest_variant(self._icp(scan, pose), start), start,
                                       sensor_world, False))
        if polish:
            refined += self._polished(time_s, scan, refined, sensor_world)
        best = max(refined, key=_score)
        self._passing_alignments = [candidate for candidate in refined if candidate.ok and candidate is not best]
        self._log_candidates(time_s, label, refined, has_motion=False)
        return best

    def _polished(self, time_s, scan, refined, sensor_world) -> list[Alignment]:
        """The POLISHED best-scored of a search's ``refined`` candidates searched again over small
        turns on the visible side (as a chain's second frame), with the passing results of each.
        Why (offline, featured debris after the net contact): the all-attitude search's nearest seed
        lies 17-19 deg from the truth, and its refined pose stops 7-9 deg and 10-13 cm off in a local
        minimum that more ICP does not leave; searched again about it, 1.5-4 deg."""
        polished = []
        for candidate in sorted(refined, key=_score, reverse=True)[:POLISHED]:
            polished.append(self._search(time_s, scan, candidate.world_to_body, _turn_candidates(SEARCH_TURN),
                                         sensor_world, visible_side=True, label="polish"))
            polished += self._passing_alignments
        return polished

    def _visible_side_seeds(self, start, points, sensor_world, turns) -> list[np.ndarray]:
        """world_to_body seeds: ``start``'s attitude turned by each of ``turns``, placed so that the
        scan centroid lands on the centroid of the model's side seen from the sensor at that attitude
        (:func:`visible_side_centroid`). A scan shows one side: its centroid lies about half the
        body's depth in front of the model centroid, beyond the coarse ICP's reach
        (``max_correspondence``) on a 1-2 m body seen from 2-6 m (the featured debris after the net
        contact: with the centroids matched, every seed ended 0.8-1.2 m off)."""
        centroid = points.mean(axis=0)
        view_world = (centroid - sensor_world) / max(np.linalg.norm(centroid - sensor_world), 1e-9)
        # a few model points per depth-buffer cell are enough for a centroid (1000 seeds: seconds saved)
        model = _thinned(self._coarse_points, DEPTH_BUFFER_POINTS)
        seeds = []
        for turn in turns:
            self._spend()
            seed = np.eye(4)
            seed[:3, :3] = turn @ start[:3, :3]
            side = visible_side_centroid(model, seed[:3, :3] @ view_world, SEARCH_VOXELS * self.voxel)
            seed[:3, 3] = side - seed[:3, :3] @ centroid
            seeds.append(seed)
        return seeds

    def _nearest_variant(self, pose, reference) -> np.ndarray:
        """Of the poses S @ ``pose`` (world -> B) the surface cannot tell apart, the one whose
        attitude is nearest ``reference``'s."""
        variants = [symmetry @ pose for symmetry in self.symmetries_body]
        return min(variants, key=lambda variant: _turn_angle(variant[:3, :3], reference[:3, :3]))

    def _icp(self, scan, initial) -> np.ndarray:
        """Point-to-plane ICP, robust to outliers (Tukey loss) such as net threads lying on the
        debris: a coarse level on about CHECKED_POINTS scan points within ``max_correspondence``,
        then a fine one on all points within a third of it."""
        points = np.asarray(scan.points)
        pose, _ = self._icp_level(_thinned(points, CHECKED_POINTS), initial, self.max_correspondence, COARSE_SETTLED)
        pose, _ = self._icp_level(points, pose, self.max_correspondence / 3, FINE_SETTLED)
        return pose

    def _icp_level(self, points, pose, distance, settled) -> tuple[np.ndarray, float]:
        """Gauss-Newton point-to-plane steps (Tukey weights, k = distance / 2) on the nearest model
        points within ``distance``, until a step moves the matched points by less than ``settled``
        (m, rms along the normals). Returns the pose and the fit: mean weight over all points."""
        weight_sum = 0.0
        for _ in range(ICP_ITERATIONS):
            body = _transform(points, pose)
            _, nearest = self._nearest.query(body, distance_upper_bound=distance)
            hessian, gradient, weight_sum, count = tukey_normal_equations(
                body, nearest, self._model_points, self._model_normals, distance / 2)
            if count < 6:   # too few matches to fix 6 degrees of freedom
                break
            try:
                step = np.linalg.solve(hessian, -gradient)
            except np.linalg.LinAlgError:   # degenerate matches (e.g. all on one plane)
                break
            pose = _twist(step) @ pose
            if step @ hessian @ step < settled**2 * weight_sum:
                break
        return pose, float(weight_sum / max(len(points), 1))

    def _global(self, scan, fallback) -> np.ndarray:
        """FPFH + RANSAC alignment of the scan to the model (for large, unpredicted motion)."""
        scan = o3d.geometry.PointCloud(scan)
        scan.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=4 * self.voxel, max_nn=30))
        features = reg.compute_fpfh_feature(scan, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * self.voxel, max_nn=100))
        o3d.utility.random.seed(self.seed + len(self.alignments))
        result = reg.registration_ransac_based_on_feature_matching(
            scan, self._model, features, self._model_features(), True, 3 * self.voxel,
            reg.TransformationEstimationPointToPoint(False), 3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(3 * self.voxel)],
            reg.RANSACConvergenceCriteria(20000, 0.999))
        return result.transformation if result.fitness > 0 else fallback

    # -- the check -------------------------------------------------------------------
    def _judge(self, time_s, points_world, pose, predicted, sensor_world, has_motion, global_init=False) -> Alignment:
        tight, sigma, information = self._surface_fit(points_world, pose)
        body_to_world = _rigid_inverse(pose)
        model_world = _transform(self._coarse_points, body_to_world)
        range_scale = np.median(np.linalg.norm(points_world - sensor_world, axis=1))
        returns = points_world if self._frame_returns is None or not len(self._frame_returns) else self._frame_returns
        violation = free_space_violation(returns, model_world, sensor_world, 2 * self.voxel / range_scale,
                                         3 * sigma + self.voxel, self._coarse_normals @ body_to_world[:3, :3].T,
                                         self._frame_spacing or _sample_spacing(points_world), self.free_space_lateral_bins)
        innovation = _turn_angle(pose[:3, :3], predicted[:3, :3])
        unseen = 0.0
        if self.field_of_view is not None and self._frame_sensor_to_world is not None:
            unseen = unseen_model_share(model_world, returns, sensor_world, self._frame_sensor_to_world,
                                        self.field_of_view, max(2 * self.voxel / range_scale, 3 * self.ray_spacing))
        view = points_world.mean(axis=0) - sensor_world
        alignment = Alignment(time_s, pose, information, tight, violation, innovation, False, global_init, 0.0,
                              len(points_world), unseen=unseen,
                              view_body=pose[:3, :3] @ view / max(np.linalg.norm(view), 1e-12))
        alignment.ok = not failed_checks(alignment, has_motion)
        return alignment

    def _surface_fit(self, points_world, pose) -> tuple[float, float, np.ndarray]:
        """Tight fitness, point-to-plane scatter sigma (m) and information of the posed scan, from
        about CHECKED_POINTS of its points (information scaled to all of them)."""
        checked = _thinned(points_world, CHECKED_POINTS)
        points_body = _transform(checked, pose)
        gap, nearest = self._nearest.query(points_body, distance_upper_bound=self.max_correspondence)
        matched = np.isfinite(gap)   # points beyond the correspondence distance are misfits
        points_body, normals = points_body[matched], self._model_normals[nearest[matched]]
        distance = np.einsum("ij,ij->i", points_body - self._model_points[nearest[matched]], normals)
        inliers = np.abs(distance) < self.max_correspondence / 3
        sigma = max(float(np.sqrt(np.mean(distance[inliers] ** 2))) if inliers.sum() > 6 else self.voxel, 1e-4)
        information = (point_to_plane_information(points_body[inliers], normals[inliers], sigma)
                       * len(points_world) / max(len(checked), 1))
        tight = np.count_nonzero(np.abs(distance) < 3 * sigma) / max(len(checked), 1)
        return float(tight), sigma, information
