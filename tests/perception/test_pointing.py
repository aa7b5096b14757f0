"""The pan-tilt mount's aim (perception/pointing.py): the CoM carried through a lost track, the
search pattern, and the re-acquisition of a debris that flies off while its track is lost."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from perception.lidar import cast, sensor_to_platform
from perception.pointing import SEARCH_ELEVATIONS, Pointing
from perception.registration import DebrisTracker, known_shape_model
from perception.shape import half_turn_symmetry_transforms, rotation_error

SENSOR = np.zeros(3)
UP = np.array([0.0, 0.0, 1.0])


def _pose(rotation, translation):
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, translation
    return pose


def test_lost_track_aims_at_the_com_carried_by_its_velocity():
    # A body turning at 2 rad/s whose CoM (0.3 m off the origin of B) moves at 3 m/s: three good
    # frames fix the CoM velocity exactly (a straight line through exact points), and a lost track
    # that still sees returns aims where the CoM is, not where it was.
    com_body, velocity = np.array([0.3, 0.0, 0.1]), np.array([0.5, 0.0, 3.0])
    pointing = Pointing(com_body)
    for t in (0.0, 0.1, 0.2):
        rotation = Rotation.from_rotvec([0.0, 0.0, 2.0 * t]).as_matrix()
        com_world = np.array([6.0, 0.0, 0.0]) + velocity * t
        pointing.record(t, _pose(rotation, com_world - rotation @ com_body), seen=True)
    for t in (0.3, 0.4, 0.5):
        pointing.record(t, None, seen=True)
    # exact arithmetic up to rounding (1e-9 m)
    np.testing.assert_allclose(pointing.aim(1.0, SENSOR, UP), np.array([6.0, 0.0, 0.0]) + velocity, atol=1e-9)


def test_a_lost_track_that_sees_nothing_widens_in_elevation():
    # Nothing seen for k frames: the boresight turns by SEARCH_ELEVATIONS[k - 1] towards the mount's
    # up axis about the predicted direction, at the predicted range (geometry, to 1e-9 rad).
    pointing = Pointing(np.zeros(3))
    pointing.record(0.0, _pose(np.eye(3), [6.0, 0.0, 0.0]), seen=True)
    for k in range(1, len(SEARCH_ELEVATIONS) + 1):
        pointing.record(0.1 * k, None, seen=False)
        aim = pointing.aim(0.1 * k + 0.1, SENSOR, UP)
        assert np.linalg.norm(aim) == pytest.approx(6.0)
        assert np.arctan2(aim[2], aim[0]) == pytest.approx(SEARCH_ELEVATIONS[k - 1], abs=1e-9)
    pointing.record(2.0, None, seen=True)   # something seen again: back on the prediction
    np.testing.assert_allclose(pointing.aim(2.1, SENSOR, UP), [6.0, 0.0, 0.0], atol=1e-12)


def _fly_off(mesh, com_body, lidar, aim_of, symmetries, frames=24, lost=range(3, 13)):
    """The debris leaves the sensor at 3 m/s across the line of sight (towards the mount's up
    axis, the field's narrow 30 deg), turning at 0.6 rad/s; frames in ``lost`` give the tracker no
    returns (the net covering it). ``aim_of(tracker, pointing, t)`` aims the mount. Returns the
    alignments, the true body -> world rotations and the returns per frame."""
    tracker = DebrisTracker(0.03, 0.1, 30, *known_shape_model(mesh, 0.03, 0), symmetries_body=symmetries, seed=0)
    pointing = Pointing(com_body)
    rng = np.random.default_rng(0)
    truths, returns = [], []
    for k in range(frames):
        t = 0.1 * k
        rotation = Rotation.from_rotvec(np.array([0.5, 0.3, 0.2]) * t).as_matrix()
        com_world = np.array([6.0, 0.0, 0.0]) + np.array([0.0, 0.0, 3.0]) * t
        aim = aim_of(tracker, pointing, t)
        sensor_to_world = sensor_to_platform(np.array([1.0, 0.0, 0.0]) if aim is None else aim - SENSOR, UP)
        vertices = np.asarray(mesh.vertices) @ rotation.T + com_world - rotation @ com_body
        scan = cast(lidar, [((vertices - SENSOR) @ sensor_to_world, mesh.faces)], t, rng).points_sensor
        points = scan @ sensor_to_world.T + SENSOR
        returns.append(len(points))
        alignment = tracker.update(t, points[:0] if k in lost else points, SENSOR)
        seen = k not in lost and len(points) >= 50
        # a failed frame that shows the debris aims at its returns next, as the stage's debris_blob (only
        # the debris is scanned here: their centroid)
        pointing.record(t, alignment.body_to_world if alignment.ok else None, seen, points.mean(axis=0) if seen else None)
        truths.append(rotation)
    return tracker.alignments, truths, returns


def _last_good_pose_aim(tracker, pointing, t):
    """The stage's aim before perception/pointing.py: the CoM at the tracker's predicted pose, which
    is the last good pose, standing still, once a frame has failed."""
    predicted = tracker.predicted_world_to_body()
    if predicted is None:
        return None
    body_to_world = np.linalg.inv(predicted)
    return body_to_world[:3, :3] @ pointing.com_body + body_to_world[:3, 3]


def test_debris_leaving_during_a_lost_track_is_found_again(paper_ellipsoid, c_fans_lidar):
    # The paper's debris (its mesh known). Track lost from 0.3 to 1.2 s (no returns given to the
    # tracker, nothing "seen", so the mount runs its search pattern: its frame after the loss looks
    # 55 deg low, the next one on the carried CoM); the debris meanwhile climbs 2.7 m across a
    # 30 deg field at 6 m. The mount finds it again and the tracker with it at once: every frame
    # from 1.4 s on registered (measured 0.4-1.9 deg from the truth up to the ellipsoid's half
    # turns; bound 3 deg: one frame of the known mesh at 6-8 m is good to ~1 deg, the search's first
    # frame after the loss admits more). Aimed at the last good pose instead (the stage before this
    # change), the debris leaves the field for good: no returns at all from 1.1 s on.
    # (The re-acquired pose is accepted once the next frames continue it as one rigid motion and the
    # view of the body has turned 45 deg, perception/registration.py, _continue_chains: at 0.6 rad/s
    # about 13 frames, so the run goes on to 3.5 s and the pending frames are revised then; meanwhile
    # the mount aims at the debris' returns. A box-like body's near half turns are rejected by the
    # unseen-model check and the chains: tests/perception/test_reacquisition.py.)
    symmetries = half_turn_symmetry_transforms(paper_ellipsoid, 0.015)
    com_body = np.zeros(3)   # the ellipsoid's centre
    alignments, truths, returns = _fly_off(paper_ellipsoid, com_body, c_fans_lidar,
                                           lambda tracker, pointing, t: pointing.aim(t, SENSOR, UP), symmetries,
                                           frames=36)
    assert min(returns[14:]) > 1000
    assert all(a.ok for a in alignments[14:])
    errors = [rotation_error(a.body_to_world[:3, :3], truth, [s[:3, :3] for s in symmetries])
              for a, truth in zip(alignments[14:], truths[14:])]
    assert np.degrees(max(errors)) < 3.0
    standing, _, standing_returns = _fly_off(paper_ellipsoid, com_body, c_fans_lidar, _last_good_pose_aim, symmetries)
    assert max(standing_returns[11:]) == 0 and not any(a.ok for a in standing[11:])
