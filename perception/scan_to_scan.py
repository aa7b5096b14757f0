"""Frames seen after the observation posed scan to scan to the observation's scans, with a covariance of their own.

The free flight after the collision is registered online to the map fused from the observation; that map is not a
rigid copy of the body, and a frame registered to it carries a view-dependent attitude error (docs/perception.md,
percep21-22). Here each such frame is posed again by point-to-plane ICP to the :data:`PARTNERS` observation scans
that share most of its surface, each scan held at its online pose in B, and the partners' poses are averaged with
their information (percep22-23). Percep24 made it cheap and gave it a covariance:

* **Each partner is put in B once** (:func:`scan_partners`: points and normals moved by its online pose, its coarse
  cells) and its exact nearest-point index (:class:`perception.nearest_grid.CellList`) built when first used and
  kept; a frame's alignment to a partner is then the online pass's compiled ICP
  (:func:`perception.scan_to_map.register_to_map`) with the pairwise alignment's Tukey cut-off (the level's whole
  distance, as Open3D's ``TukeyLoss(k=distance)`` of :func:`perception.pose_graph.pair_alignment` had), not
  Open3D's ICP, which rebuilds a KD-tree of the target on every call; and its fine level only: a frame starts at
  its pose registered to the map, within a fraction of a degree and about a centimetre of each partner's optimum
  (the partners' scatter: 0.15-0.42 deg, 5-10 mm), well inside the fine level's third of the correspondence
  distance; the coarse level, made for a start centimetres off, with its cut-off at the whole 0.1 m let outliers
  pull a few alignments by up to a degree (docs/perception.md, percep24: seed 0's frames 0.390 -> 0.329 deg rms
  from the truth, 30.6 -> 25.7 ms CPU a frame). It keeps about a tenth of its start's error (a 0.3 deg start turn
  left 0.034 deg median, 0.2 deg at most, seed 3): a tighter stop is still to be measured (docs, percep24).
* **A frame's pose inherits its partners' errors.** A partner's online pose error e_j (a left perturbation in B)
  moves every frame aligned to it by e_j; frames that share partners share those errors, so they are correlated
  from frame to frame and do not show as scatter about the torque-free fit, which is all the fit's own covariance
  sees. The partners of one frame disagree by their errors (and by the pairwise alignments'), so their scatter
  about the frame's mean measures the per-partner error covariance S (pooled over the frames,
  :meth:`ReposedFrames.partner_covariance`); the frames' attitude errors then have the covariance
  :meth:`ReposedFrames.attitude_covariance`, which the after fit propagates into the spin momentum
  (:meth:`perception.euler_poinsot.TorqueFreeFit.add_attitude_covariance`).

.. math::
   \\hat x_k = \\sum_j A_{kj} x_{kj},\\quad A_{kj} = \\Big(\\sum_i \\Lambda_{ki}\\Big)^{-1} \\Lambda_{kj},\\qquad
   S = \\frac{\\sum_k \\sum_j (x_{kj} - \\hat x_k)(x_{kj} - \\hat x_k)^T}{\\sum_k (n_k - 1)},\\qquad
   \\operatorname{cov}(\\hat x_k, \\hat x_l) = \\sum_{j \\in P_k \\cap P_l} A_{kj} S A_{lj}^T

(x: twists, rotation vector then translation; P_k the partners of frame k). The pairwise alignment's own error is
counted in S as if it were shared too: conservative (it is counted once more than it is, within a frame's n_k terms).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix

from perception.pose_graph import LOOP_EDGES, MIN_PAIR_FITNESS, OVERLAP_CELL, information_weighted_pose, twist_of
from perception.scan_to_map import FINE_POINTS, LazyNormals, _transform, map_index, map_information, register_to_map, thinned_scan

#: Observation scans each later frame is aligned to (those of most coarse overlap): as many as a frame's loop
#: closures in the pose graph, the count percep22 measured the after frames with (docs/perception.md).
PARTNERS = LOOP_EDGES
#: Tukey cut-off of a pairwise alignment, as a share of each level's correspondence distance: the whole distance,
#: as Open3D's ``TukeyLoss(k=distance)`` in :func:`perception.pose_graph.pair_alignment` (percep22-23's alignments).
PAIR_CUTOFF = 1.0
#: Offset of the coarse cells' integer coordinates in :func:`cell_keys` (21 bits an axis: cells of 0.1 m within
#: +-100 km of B's origin).
KEY_OFFSET = 1 << 20


def cell_keys(points_body, cell=OVERLAP_CELL) -> np.ndarray:
    """Sorted unique keys (int64) of the coarse cells of ``cell`` (m) edges occupied by points (n, 3) (m, frame B):
    :func:`perception.pose_graph.coarse_cells` as one integer a cell (21 bits an axis)."""
    index = np.floor(np.asarray(points_body, float) / cell).astype(np.int64) + KEY_OFFSET
    return np.unique((index[:, 0] << 42) | (index[:, 1] << 21) | index[:, 2])


@dataclass
class ScanPartners:
    """The observation's thinned scans as partners of the scan-to-scan poses, each in B at its online pose.

    Attributes
    ----------
    frames : (p,) int                          Observation frame of each partner (row).
    points_body : list of (n_j, 3) float       Its thinned scan, frame B at its online pose (m).
    normals_body : list of (n_j, 3) float      Their unit normals (4 voxels, 30 nearest; frame B).
    keys : (c,) int                            Sorted coarse-cell keys occupied by any partner (:func:`cell_keys`).
    occupancy : (p, c) sparse float            1 where a partner occupies a cell.
    cell_count : (p,) int                      Cells each partner occupies.
    max_correspondence : float                 Coarse correspondence distance (m); the fine level a third.
    indexes : dict of int -> (CellList, LazyNormals)   Nearest-point indexes by row, built when first used.
    """

    frames: np.ndarray
    points_body: list
    normals_body: list
    keys: np.ndarray
    occupancy: csr_matrix
    cell_count: np.ndarray
    max_correspondence: float
    indexes: dict = field(default_factory=dict)

    def index(self, row):
        """Partner ``row``'s nearest-point index and its normals in the index's order (built once, then kept)."""
        if row not in self.indexes:
            index = map_index(self.points_body[row], self.max_correspondence)
            self.indexes[row] = index, LazyNormals.given(self.normals_body[row], index)
        return self.indexes[row]

    def most_overlapping(self, keys, count) -> np.ndarray:
        """Rows of the ``count`` partners sharing the largest share of the smaller one's cells with a frame's
        cells ``keys`` (:func:`cell_keys`), largest first, ties in frame order (the share of
        :func:`perception.pose_graph.overlap_share`, on integer keys)."""
        if not len(self.keys):
            return np.zeros(0, int)
        position = np.clip(np.searchsorted(self.keys, keys), 0, len(self.keys) - 1)
        seen = np.zeros(len(self.keys))
        seen[position[self.keys[position] == keys]] = 1.0
        share = (self.occupancy @ seen) / np.maximum(np.minimum(self.cell_count, len(keys)), 1)
        return np.argsort(-share, kind="stable")[:count]


def scan_partners(observation_poses, observation_clouds, ok, max_correspondence) -> ScanPartners:
    """The registered observation frames with normals as :class:`ScanPartners`.

    Parameters
    ----------
    observation_poses : (k, 4, 4) float      Pose world -> B of each observation frame (online; m).
    observation_clouds : list of Open3D clouds   Their thinned scans with normals, world (m;
                                             :func:`perception.pose_graph.scan_clouds`).
    ok : (k,) bool                           Frames registered (the only partners).
    max_correspondence : float               Coarse correspondence distance (m).

    Returns
    -------
    ScanPartners
    """
    frames, points, normals, keys = [], [], [], []
    for j in np.flatnonzero(ok):
        cloud = observation_clouds[j]
        if not cloud.has_normals():   # fewer points than a normal's neighbourhood
            continue
        pose = np.asarray(observation_poses[j], float)
        frames.append(int(j))
        points.append(_transform(np.asarray(cloud.points), pose))
        normals.append(np.asarray(cloud.normals) @ pose[:3, :3].T)
        keys.append(cell_keys(points[-1]))
    every = np.unique(np.concatenate(keys)) if keys else np.zeros(0, np.int64)
    rows = np.repeat(np.arange(len(keys)), [len(k) for k in keys])
    columns = np.searchsorted(every, np.concatenate(keys)) if keys else np.zeros(0, np.int64)
    occupancy = csr_matrix((np.ones(len(rows)), (rows, columns)), shape=(len(keys), len(every)))
    return ScanPartners(np.array(frames, int), points, normals, every, occupancy,
                        np.array([len(k) for k in keys], int), float(max_correspondence))


def aligned_to_partner(scan_world, start, partners: ScanPartners, j):
    """Pose world -> B (4, 4) of a thinned scan (n, 3) (m, world) aligned to partner row j from ``start`` (world -> B),
    its point-to-plane information (6, 6) (rotation first, left perturbation in B; 1/rad^2, 1/m^2; residual scatter
    measured) and its fitness (share of the scan within the fine distance)."""
    index, normals = partners.index(j)
    pose, fitness, _ = register_to_map(scan_world, partners.points_body[j], normals, start,
                                       partners.max_correspondence, index=index, cutoff_share=PAIR_CUTOFF,
                                       fine_only=True)
    # on the fine level's points: the partners' informations of a frame only weigh each other (the same points for
    # all), and their scale does not reach the covariance (ReposedFrames.partner_covariance)
    fine = scan_world[::max(1, len(scan_world) // FINE_POINTS)]
    information = map_information(fine, pose, partners.points_body[j], partners.normals_body[j],
                                  partners.max_correspondence, index)
    return pose, information, fitness


@dataclass
class ReposedFrames:
    """Frames posed scan to scan (:func:`scan_to_scan_poses`) and what their covariance is made of.

    Attributes
    ----------
    world_to_body : dict of int -> (4, 4) float   Pose world -> B of each frame (m).
    partners : dict of int -> list of int         Observation frames each was aligned to (kept ones).
    deviations : dict of int -> (n, 6) float      Each partner's pose minus the frame's (twist, left, B).
    gains : dict of int -> (n, 6, 6) float        A_kj: the share of partner j's pose in the frame's mean.
    cpu_seconds : float                           CPU time of the posing (s, process time).
    """

    world_to_body: dict
    partners: dict
    deviations: dict
    gains: dict
    cpu_seconds: float = 0.0

    def partner_covariance(self) -> np.ndarray:
        """S (6, 6): the scatter of the partners' poses about their frames' means, pooled over the frames with
        n_k - 1 degrees of freedom each (rad^2, rad m, m^2); zeros when no frame had two partners."""
        scatter = sum((d.T @ d for d in self.deviations.values() if len(d) > 1), np.zeros((6, 6)))
        dof = sum(len(d) - 1 for d in self.deviations.values() if len(d) > 1)
        return scatter / dof if dof else np.zeros((6, 6))

    def attitude_covariance(self, indices) -> np.ndarray:
        """Covariance (3n, 3n) (rad^2) of the attitude errors (left perturbations in B) of frames ``indices``, from
        the errors they inherit from shared partners: block (k, l) = sum over shared j of A_kj S A_lj^T (rotation
        rows). Frames not posed here get zero rows."""
        partner = self.partner_covariance()
        rows = {}
        for a, k in enumerate(indices):
            for j, gain in zip(self.partners.get(int(k), []), self.gains.get(int(k), [])):
                rows.setdefault(j, []).append((a, gain[:3]))
        covariance = np.zeros((3 * len(indices), 3 * len(indices)))
        for shared in rows.values():
            for a, gain_a in shared:
                for b, gain_b in shared:
                    covariance[3 * a:3 * a + 3, 3 * b:3 * b + 3] += gain_a @ partner @ gain_b.T
        return covariance


def scan_to_scan_pose(scan_world, start, partners: ScanPartners, chosen):
    """World -> B (4, 4) of one frame's thinned scan from its alignments to the partners ``chosen`` (from
    ``start``), partners aligned with a fitness under MIN_PAIR_FITNESS dropped, the rest averaged with their
    information (:func:`perception.pose_graph.information_weighted_pose`). Also the partners kept, their
    deviations from the mean (n, 6) and their gains A_kj (n, 6, 6)."""
    kept, poses, informations = [], [], []
    for j in chosen:
        pose, information, fitness = aligned_to_partner(scan_world, start, partners, j)
        if fitness >= MIN_PAIR_FITNESS:
            kept.append(j)
            poses.append(pose)
            informations.append(information)
    mean = information_weighted_pose(start, poses, informations)
    deviations = np.array([twist_of(pose @ np.linalg.inv(mean)) for pose in poses]).reshape(-1, 6)
    total = sum(informations, np.zeros((6, 6)))
    gains = (np.array([np.linalg.solve(total, information) for information in informations]).reshape(-1, 6, 6)
             if np.linalg.matrix_rank(total) == 6 else np.zeros((0, 6, 6)))
    return mean, (kept if len(gains) else []), deviations[:len(gains)], gains


def scan_to_scan_poses(scans_by_frame, starts, partners: ScanPartners, voxel, count=PARTNERS) -> ReposedFrames:
    """World -> B of frames seen after the observation, each posed scan to scan to the ``count`` partners of
    largest coarse overlap at its start, not to a map fused from them (whose view-dependent bias the frames then
    carry: docs/perception.md, percep21 and percep22).

    Parameters
    ----------
    scans_by_frame : dict of int -> (n, 3) float   The frames' scans (m, world at their times).
    starts : dict of int -> (4, 4) float           Starting pose world -> B of each (the tracker's), also where its
                                                   overlap with the partners is judged.
    partners : ScanPartners                        The observation's scans in B (:func:`scan_partners`).
    voxel : float                                  Scan thinning (m).
    count : int                                    Partners a frame is aligned to.

    Returns
    -------
    ReposedFrames   (a frame with no partner aligned keeps its start and gets no covariance terms)
    """
    tic = time.process_time()
    reposed = ReposedFrames({}, {}, {}, {})
    for k, scan in scans_by_frame.items():
        source = thinned_scan(scan, voxel)
        chosen = partners.most_overlapping(cell_keys(_transform(source, starts[k])), count)
        (reposed.world_to_body[k], rows, reposed.deviations[k],
         reposed.gains[k]) = scan_to_scan_pose(source, starts[k], partners, chosen)
        reposed.partners[k] = [int(partners.frames[row]) for row in rows]
    reposed.cpu_seconds = time.process_time() - tic
    return reposed
