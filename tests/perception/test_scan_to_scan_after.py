"""Frames after the observation posed scan to scan to the observation's scans
(perception.pose_graph.scan_to_scan_poses), checked against the synthetic torque-free tumble with a known answer."""
import numpy as np
from scipy.spatial.transform import Rotation

from perception.pose_graph import adjoint, information_weighted_pose, scan_clouds, scan_to_scan_poses
from perception.scan_to_map import alignments, thinned_scan
from tests.perception.conftest import CORRESPONDENCE, VOXEL
from tests.perception.test_scan_to_map import _spin_angle_deg

#: The tumble's first half is the "observation" (its online poses equal those of tracking it alone: the online
#: pass registers each scan to the map of the scans before it); its second half the frames posed after it.
SPLIT = 50


def test_equal_informations_average_the_poses_and_the_adjoint_moves_a_twist():
    # Two poses turned +-0.2 rad about z from the start with equal information average to the start exactly (the
    # mean of +-theta), and with one of them 3 times as informative to theta (3 - 1) / 4 = 0.1 rad toward it.
    start = np.eye(4)
    plus, minus = np.eye(4), np.eye(4)
    plus[:3, :3] = Rotation.from_rotvec([0, 0, 0.2]).as_matrix()
    minus[:3, :3] = Rotation.from_rotvec([0, 0, -0.2]).as_matrix()
    np.testing.assert_allclose(information_weighted_pose(start, [plus, minus], [np.eye(6)] * 2), start, atol=1e-12)
    toward = information_weighted_pose(start, [plus, minus], [3 * np.eye(6), np.eye(6)])
    np.testing.assert_allclose(Rotation.from_matrix(toward[:3, :3]).as_rotvec(), [0, 0, 0.1], atol=1e-12)
    # the adjoint of a pure translation t maps a rotation w to (w, t x w): a point's velocity at the origin
    pose = np.eye(4)
    pose[:3, 3] = [1.0, 2.0, 3.0]
    np.testing.assert_allclose(adjoint(pose) @ np.r_[0, 0, 1.0, 0, 0, 0], np.r_[0, 0, 1.0, np.cross([1, 2, 3], [0, 0, 1])])


def test_after_frames_posed_scan_to_scan_give_the_spin_momentum_of_the_truth(tumble):
    # Known answer: the torque-free truth's h. The second half's frames (5-10 s), started from their online poses
    # (as the stage starts them from its registered poses), posed to the first half's scans at their online poses.
    # Measured over rng seeds 0-4 (bench/results/percep23/synthetic_after_frames.txt; 0.059 here, rng seed 3): h
    # 0.057, 0.064, 0.052, 0.059, 0.127 deg; the same frames registered by the stage's ICP to the map fused from
    # the first half 0.133, 0.095, 0.090, 0.080, 0.143 (higher on every seed), the online poses 0.130, 0.093, 0.078,
    # 0.063, 0.121, and the exact mesh from the truth turned 1 deg 0.026, 0.033, 0.031, 0.029, 0.045 (white noise of
    # 51 frames). Bound 0.15 deg: the worst seed (0.127) with 18 % to spare, the size the model-free stage's
    # 1-sigma carries (test_scan_to_map.py); under the map's worst (0.143) it cannot be, so not claimed here.
    after = range(SPLIT, len(tumble.times))
    starts = {k: tumble.track.world_to_body[k] for k in after}
    clouds = scan_clouds([thinned_scan(scan, VOXEL) for scan in tumble.scans[:SPLIT]], VOXEL)
    poses = scan_to_scan_poses({k: tumble.scans[k] for k in after}, starts, tumble.track.world_to_body[:SPLIT], clouds,
                               tumble.track.ok[:SPLIT], VOXEL, CORRESPONDENCE)
    records = alignments(tumble.track, tumble.times)[SPLIT:]
    for record, k in zip(records, after):
        record.world_to_body = poses[k]
    assert _spin_angle_deg(records, tumble.times[SPLIT:]) < 0.15
