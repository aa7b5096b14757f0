"""Frames after the observation posed scan to scan to the observation's scans (perception.scan_to_scan), checked
against the synthetic torque-free tumble with a known answer: the spin momentum, and the covariance the frames
carry of their own (their errors and the spin momentum's over their 1-sigma)."""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from perception.free_flight import fit_free_motion
from perception.pose_graph import information_weighted_pose, scan_clouds
from perception.scan_to_map import alignments, thinned_scan
from perception.scan_to_scan import ReposedFrames, scan_partners, scan_to_scan_poses
from tests.perception.conftest import CORRESPONDENCE, OMEGA0, PAPER_MOMENTS, VOXEL
from tests.perception.test_scan_to_map import _spin_angle_deg

#: The tumble's first half is the "observation" (its online poses equal those of tracking it alone: the online
#: pass registers each scan to the map of the scans before it); its second half the frames posed after it.
SPLIT = 50


def test_equal_informations_average_the_poses():
    # Two poses turned +-0.2 rad about z from the start with equal information average to the start exactly (the
    # mean of +-theta), and with one of them 3 times as informative to theta (3 - 1) / 4 = 0.1 rad toward it.
    start = np.eye(4)
    plus, minus = np.eye(4), np.eye(4)
    plus[:3, :3] = Rotation.from_rotvec([0, 0, 0.2]).as_matrix()
    minus[:3, :3] = Rotation.from_rotvec([0, 0, -0.2]).as_matrix()
    np.testing.assert_allclose(information_weighted_pose(start, [plus, minus], [np.eye(6)] * 2), start, atol=1e-12)
    toward = information_weighted_pose(start, [plus, minus], [3 * np.eye(6), np.eye(6)])
    np.testing.assert_allclose(Rotation.from_matrix(toward[:3, :3]).as_rotvec(), [0, 0, 0.1], atol=1e-12)


def test_frames_sharing_a_partner_share_its_error():
    # Hand-worked: frame 0 posed to partners 7 and 8, frame 1 to 7 and 9, equal informations (gains I / 2). Their
    # partners deviate by +-d about x (frame 0) and +-d about y (frame 1): the pooled scatter over 1 + 1 degrees of
    # freedom is S = d^2 (x x^T + y y^T). A frame's mean of 2 partners has S / 4 + S / 4 = S / 2; the two frames
    # share partner 7 alone: S / 4.
    d = 0.01
    half = np.tile(np.eye(6) / 2, (2, 1, 1))
    deviations = {0: np.array([[d, 0, 0, 0, 0, 0], [-d, 0, 0, 0, 0, 0]]),
                  1: np.array([[0, d, 0, 0, 0, 0], [0, -d, 0, 0, 0, 0]])}
    reposed = ReposedFrames({0: np.eye(4), 1: np.eye(4)}, {0: [7, 8], 1: [7, 9]}, deviations, {0: half, 1: half})
    scatter = d**2 * np.diag([1.0, 1.0, 0.0])
    np.testing.assert_allclose(reposed.partner_covariance()[:3, :3], scatter, atol=1e-15)
    covariance = reposed.attitude_covariance([0, 1])
    np.testing.assert_allclose(covariance[:3, :3], scatter / 2, atol=1e-15)
    np.testing.assert_allclose(covariance[3:, 3:], scatter / 2, atol=1e-15)
    np.testing.assert_allclose(covariance[:3, 3:], scatter / 4, atol=1e-15)


@pytest.fixture(scope="module")
def reposed_tumble(tumble):
    """The second half's frames (5-10 s), started from their online poses (as the stage starts them from its
    registered poses), posed to the first half's scans at their online poses; the alignment records with them."""
    after = list(range(SPLIT, len(tumble.times)))
    clouds = scan_clouds([thinned_scan(scan, VOXEL) for scan in tumble.scans[:SPLIT]], VOXEL)
    partners = scan_partners(tumble.track.world_to_body[:SPLIT], clouds, tumble.track.ok[:SPLIT], CORRESPONDENCE)
    reposed = scan_to_scan_poses({k: tumble.scans[k] for k in after}, {k: tumble.track.world_to_body[k] for k in after},
                                 partners, VOXEL)
    records = alignments(tumble.track, tumble.times)
    for k in after:
        records[k].world_to_body = reposed.world_to_body[k]
    return SimpleNamespace(after=after, reposed=reposed, records=records)


def test_after_frames_posed_scan_to_scan_give_the_spin_momentum_of_the_truth(tumble, reposed_tumble):
    # Known answer: the torque-free truth's h. Measured over rng seeds 0-4 (docs/perception.md, percep24; script
    # bench/results/percep24/synthetic_covariance_script.py.txt): 0.052, 0.061, 0.051, 0.056 (this fixture's), 0.128
    # deg; percep23's Open3D alignments with their coarse level 0.057, 0.064, 0.052, 0.059, 0.127; the same frames
    # registered to the map fused from the first half 0.090-0.143. Bound 0.15 deg, as percep23's (the worst seed
    # within it with 15 % to spare).
    assert _spin_angle_deg(reposed_tumble.records[SPLIT:], tumble.times[SPLIT:]) < 0.15


def _across_h(motion, h_true):
    """The fitted h's error across itself over its 1-sigma there (the chi of the two components across h)."""
    h, covariance = motion.spin_per_c, motion.spin_per_c_cov
    across = np.eye(3) - np.outer(h, h) / (h @ h)
    error = across @ (h_true * np.linalg.norm(h) / np.linalg.norm(h_true) - h)
    return float(np.sqrt(error @ np.linalg.pinv(across @ covariance @ across) @ error))


def test_the_reposed_frames_covariance_covers_the_spin_momentum_error(tumble, reposed_tumble):
    # The fit's own covariance knows only the frames' scatter about it; the frames' errors inherited from shared
    # partner scans do not scatter, and h came out 2.3-4.4 of that 1-sigma off the truth (rng seeds 0-4: 3.28, 4.38,
    # 2.28, 3.08, 4.43). With the frames' covariance propagated (ReposedFrames.attitude_covariance,
    # TorqueFreeFit.add_attitude_covariance): 1.38, 1.68, 0.98, 1.07 (this fixture's), 2.17 (script
    # bench/results/percep24/synthetic_covariance_script.py.txt). Bound 2.5: the worst seed's 2.17 with 15 % to
    # spare; not 2, which seed 4 misses (an error common to all the partners does not show in their scatter).
    after = np.array(reposed_tumble.after)
    tracker = SimpleNamespace(alignments=reposed_tumble.records)
    h_true = PAPER_MOMENTS / PAPER_MOMENTS[2] * OMEGA0
    motion = fit_free_motion(tracker, after, tumble.times, attitude_covariance=reposed_tumble.reposed.attitude_covariance)
    assert _across_h(motion, h_true) < 2.5
    assert motion.fit.attitude_covariance_scale_ >= 1.0


def test_the_reposed_frames_errors_over_their_own_1_sigma(tumble, reposed_tumble):
    # Each frame's attitude error from the truth (world -> B against the torque-free truth; B is the body frame at
    # t = 0 up to a constant body-side turn, the online pass's frame, taken out as the errors' mean: a change of B,
    # which h does not see, percep21) over its own 1-sigma (the diagonal block of the frames' covariance times the
    # after fit's scale). Measured rms of the normalized errors per axis over rng seeds 0-4: 1.52, 1.43, 1.07, 0.92
    # (this fixture's), 1.10 (without the scale 1.6-2.5: the partners of one frame see it from similar views and err
    # alike, so their scatter under-states their errors; the residuals about the fit bound them from below).
    # Bound 2: the worst seed's 1.52 with 30 % to spare.
    after = reposed_tumble.after
    errors = np.array([Rotation.from_matrix(reposed_tumble.reposed.world_to_body[k][:3, :3]
                                            @ tumble.body_to_world[k]).as_rotvec() for k in after])
    errors -= errors.mean(axis=0)
    motion = fit_free_motion(SimpleNamespace(alignments=reposed_tumble.records), np.array(after), tumble.times,
                             attitude_covariance=reposed_tumble.reposed.attitude_covariance)
    covariance = reposed_tumble.reposed.attitude_covariance(after) * motion.fit.attitude_covariance_scale_
    chi2 = [e @ np.linalg.solve(covariance[3 * a:3 * a + 3, 3 * a:3 * a + 3], e) for a, e in enumerate(errors)]
    assert np.sqrt(np.mean(chi2) / 3) < 2.0
