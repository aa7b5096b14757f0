"""Model-free tracking (perception/scan_to_map.py) of a synthetic torque-free tumble, checked
against the truth: attitudes, the CoM as the one point of the first scan's frame on a straight
line, and the inertia ratios of the Euler-Poinsot fit."""
from types import SimpleNamespace

import numpy as np
from scipy.spatial.transform import Rotation

from perception.free_flight import fit_free_motion
from perception.registration import DebrisTracker, _cloud, known_shape_model
from perception.scan_to_map import alignments, track_scans
from tests.perception.conftest import (COM0, CORRESPONDENCE, OMEGA0, PAPER_MOMENTS, VELOCITY, VOXEL,  # noqa: F401
                                      featured_debris as _featured_debris)


def test_first_scan_defines_the_body_frame(tumble):
    pose = tumble.track.world_to_body[0]
    np.testing.assert_allclose(pose[:3, :3], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(pose[:3, 3], tumble.com_body - COM0, atol=1e-12)


def test_attitudes_follow_the_tumble_without_the_mesh(tumble):
    # Every frame registers (fitness >= 0.8). Attitude error bound: one frame is fixed to a few
    # hundredths of a degree by ~3000 points with 2 cm noise on faces ~1 m across (2 cm / (1 m
    # sqrt(3000)) ~ 0.02 deg); the map, built from scans registered before and thinned to 3 cm
    # voxels (1.7 deg at 1 m), carries their errors. Measured: here 1.1 deg mean, 2.4 deg worst;
    # bench/bench_scan_to_map.py over 5 seeds x 20 s: means 0.65-2.5 deg, worst frame 3.5 deg. With the
    # residuals taken to the map points' fitted planes (2026-11-27): here 1.07 deg mean, 1.44 deg worst;
    # rng seeds 0-6: means 0.24-1.15 deg, worst frame 1.46 deg (mostly the map's constant turn, which
    # B carries and the fits do not see).
    # Bounds: 3 deg on average (under two voxels at 1 m), 4.5 deg for every frame.
    track = tumble.track
    assert track.ok.all()
    errors = np.degrees([Rotation.from_matrix(np.linalg.inv(pose)[:3, :3] @ truth.T).magnitude()
                         for pose, truth in zip(track.world_to_body, tumble.body_to_world)])
    assert errors.max() < 4.5
    assert errors.mean() < 3.0


def test_center_of_mass_and_inertia_ratios_without_the_mesh(tumble):
    # The CoM is the point of B moving on a straight line (motion.center_of_mass_line) and the
    # normalized moments come from the torque-free fit of the attitudes (euler_poinsot), as with
    # the mesh. Truth: the tumble's origin (COM0 at t = 0) and the paper's moments / C.
    # The CoM is compared in the world (a frame-independent point: B itself is only known to the
    # map's constant turn). Tolerances: attitude errors of 1-2.5 deg over the up to 2.5 m between
    # scan points (array tip) and CoM move the fitted line by centimetres: 16 mm at t = 0 here,
    # 9-82 mm over the bench's 5 seeds x 20 s: 10 cm (12 cm in B, plus the map's constant turn).
    # The ratios: 0.6 and 0.8 % here (10 s) while the ICP's residuals went to the raw voxel means of the
    # map; with them taken to the means projected on their fitted planes (perception.normals.surface_planes:
    # the means of noisy returns form a slab a few voxels thick, which gave a slow, view-dependent attitude
    # error, docs/perception.md "Which property of the scan-made map") 0.10 and 0.14 % here, at most 0.27 %
    # over rng seeds 0-6 (the fixture with another rng). Bound 0.5 %: issue 26's goal for
    # the principal moments, of which the ratios are the observation's part (the old map's 0.6-0.9 % fail it).
    track = tumble.track
    tracker = SimpleNamespace(alignments=alignments(track, tumble.times))
    motion = fit_free_motion(tracker, np.flatnonzero(track.ok), tumble.times)
    assert np.linalg.norm(motion.line.position_world([0.0])[0] - COM0) < 0.10
    assert np.linalg.norm(motion.line.com_body - tumble.com_body) < 0.12
    np.testing.assert_allclose(motion.line.velocity_world, VELOCITY, atol=0.005)
    np.testing.assert_allclose(motion.fit.moments_, PAPER_MOMENTS / PAPER_MOMENTS[2], rtol=0.005)


def test_own_side_planes_keep_the_track(tumble):
    # The map's planes fitted to the neighbours seen from the point's own side (track_scans given the sensor
    # origins; the scans are in the sensor frame, the world here, so every origin is 0). The featured body's
    # faces are each seen from one side here, so the rule changes the map by tenths of a mm and the track must
    # stay within the same bounds as without it (test_attitudes_follow_the_tumble_without_the_mesh); measured on
    # these 40 frames: 1.20 deg mean, 1.50 deg worst (all neighbours 1.16 and 1.44). The rule's own effect is
    # tested on a plate seen from both sides (tests/perception/test_normals.py).
    frames = 40
    track = track_scans(tumble.scans[:frames], VOXEL, CORRESPONDENCE, sensors_world=np.zeros((frames, 3)))
    errors = np.degrees([Rotation.from_matrix(np.linalg.inv(pose)[:3, :3] @ truth.T).magnitude()
                         for pose, truth in zip(track.world_to_body, tumble.body_to_world[:frames])])
    assert track.ok.all()
    assert errors.max() < 4.5
    assert errors.mean() < 3.0


def _spin_angle_deg(alignment_records, times):
    """Angle (deg) of the free-flight fit's spin momentum from the true one, PAPER_MOMENTS / C * OMEGA0 (the
    tumble starts at the identity attitude, so body and world axes agree at t = 0)."""
    spin = fit_free_motion(SimpleNamespace(alignments=alignment_records), np.arange(len(times)), times).spin_per_c
    spin_true = PAPER_MOMENTS / PAPER_MOMENTS[2] * OMEGA0
    return np.degrees(np.arccos(np.clip(spin @ spin_true / np.linalg.norm(spin) / np.linalg.norm(spin_true), -1.0, 1.0)))


def test_the_spin_momentum_direction_from_the_scan_made_map_and_from_the_exact_model(tumble):
    # The direction of h = R I omega / C in the world is what the momentum step's C is sensitive to (a few
    # hundredths of a degree across h move C by tenths of a per cent on the featured debris, docs/perception.md,
    # percep21). Known answer: the torque-free truth's h. Registered against the exact mesh (the tracker's own
    # ICP from the true pose), the frames carry white noise only and h is 0.022-0.025 deg off (rng seeds 3, 0;
    # 101 frames of ~0.1 deg rms): bound 0.05 deg. Tracked without the mesh (the online scan-to-map pass), h is
    # 0.066-0.101 deg off over rng seeds 0-4 (here 0.066), a world-side bias of the view through the scan-made
    # map (the map registered from the true poses: 0.026 and 0.114 deg, seeds 3, 0), which the 20 s observations of
    # the featured debris show too: bound 0.15 deg, the size the model-free stage's 1-sigma has to carry.
    from_map = _spin_angle_deg(alignments(tumble.track, tumble.times), tumble.times)
    assert from_map < 0.15
    tracker = DebrisTracker(VOXEL, CORRESPONDENCE, 30, *known_shape_model(_featured_debris(), VOXEL, 0), seed=0)
    records = []
    for t, rotation, scan in zip(tumble.times, tumble.body_to_world, tumble.scans):
        truth = np.eye(4)
        truth[:3, :3], truth[:3, 3] = rotation.T, -rotation.T @ (COM0 + VELOCITY * t)
        pose = np.linalg.inv(tracker._icp(_cloud(scan).voxel_down_sample(VOXEL), truth))
        records.append(SimpleNamespace(body_to_world=pose, information=np.eye(6) * 1e4))
    assert _spin_angle_deg(records, tumble.times) < 0.05
