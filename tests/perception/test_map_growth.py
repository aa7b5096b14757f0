"""A scan-made map grows after a confirmed re-acquisition with the surface it lacked (the featured debris'
bus -x face, unseen in the observation; docs/perception.md, "The map grown after a re-acquisition"), and
only from frames that passed every check."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import perception.map_growth as map_growth
import perception.registration as registration
import perception.scan_to_map as scan_to_map
from multibody.geometry import shape_mesh
from perception.registration import Alignment, DebrisTracker, known_shape_model
from tests.perception.conftest import SENSOR, scan_of_body

POSITION = np.array([4.0, 0.0, 0.3])   # m, world: the bus at 4 m, as in test_reacquisition.py
HALF_X = 0.6                            # m: the bus' half length along x (1.2 x 1.0 x 1.6 m box)


@pytest.fixture(scope="module")
def bus():
    """The featured debris' bus (cases/featured_debris_perception_model_free.toml): a 1.2 x 1.0 x 1.6 m box."""
    return shape_mesh("box", size=[1.2, 1.0, 1.6])


def _one_sided_map(bus):
    """The bus' surface without its -x face (m, frame B = the box frame), with the faces' normals: a map
    made from views of the other sides only."""
    points, normals = known_shape_model(bus, 0.03, seed=0)
    kept = points[:, 0] > -HALF_X + 0.01
    return points[kept], normals[kept]


def _scan(bus, lidar, rotation, seed):
    """Returns (m, world) of the bus (body -> world ``rotation``, centre at POSITION), the sensor attitude
    and the true world -> B."""
    return scan_of_body(bus, lidar, rotation, POSITION, seed)


def _rotation(t):
    """body -> world rotation of the bus turning at 1.0 rad/s about world z (s): the sensor, on the world -x
    side of the bus, sees its +x and +-y faces at 0 s; over 0.1-1.6 s its -x face turns into view."""
    return Rotation.from_rotvec([0.0, 0.0, 1.0 * t]).as_matrix() @ Rotation.from_rotvec([0.0, 0.0, np.pi + 0.9]).as_matrix()


def _tracked(bus, lidar, reacquired, times, clutter_at=None):
    """The one-sided map's tracker (growth on) fed scans of the turning bus from two good frames with the
    truth's motion (tracked from the motion prediction); ``reacquired``: as after a confirmed
    re-acquisition. ``clutter_at``: that frame's returns replaced two thirds by points spread over a 3 m box."""
    tracker = DebrisTracker(0.03, 0.1, 30, *_one_sided_map(bus), seed=0, field_of_view=(lidar.fov_azimuth, lidar.fov_elevation),
                            ray_spacing=max(lidar.resolution_azimuth, lidar.resolution_elevation), grow_map=True,
                            free_space_lateral_bins=registration.MAP_LATERAL_BINS)
    tracker._reacquired = reacquired
    tracker.alignments = [Alignment(t, _scan(bus, lidar, _rotation(t), 0)[2], np.eye(6), 1.0, 0.0, 0.0, True, False, 0.0, 0)
                          for t in (times[0] - 0.2, times[0] - 0.1)]
    rng = np.random.default_rng(1)
    for k, t in enumerate(times):
        points, sensor_to_world, _ = _scan(bus, lidar, _rotation(t), k + 1)
        if k == clutter_at:
            points = np.vstack([points[: len(points) // 3], POSITION + rng.uniform(-1.5, 1.5, (2 * len(points) // 3, 3))])
        tracker.update(t, points, SENSOR, all_returns_world=points, sensor_to_world=sensor_to_world)
    return tracker


def _on_minus_x_face(points_body):
    """Map points (m, frame B) on the bus' -x face: within 1 cm of its plane, inside its outline."""
    return (np.abs(points_body[:, 0] + HALF_X) < 0.01) & (np.abs(points_body[:, 1]) < 0.5) & (np.abs(points_body[:, 2]) < 0.8)


def test_growth_rule_is_the_first_builds():
    # The growth's "shows new surface" share is the map's first build's (perception.scan_to_map.MAP_COVERED).
    assert map_growth.MAP_GROWTH_COVERED == scan_to_map.MAP_COVERED


def test_a_face_seen_only_after_the_reacquisition_joins_the_map(bus, c_fans_lidar):
    # The bus turns its unmapped -x face into view. After a confirmed re-acquisition, the frames tracked from
    # the motion prediction that pass their checks add it: the map's points on that face's plane cover it
    # (a 1.0 x 1.6 m face at a 3 cm voxel holds ~1800 voxels; measured 1639; bound: 1000, over half of it, from
    # 16 frames), each within 1 cm of the plane (the fitted planes' error at 2 cm range noise, 3 cm voxels: ~2 mm),
    # and every frame registered within 2 deg of the truth (measured 0.1-1.4 deg; the same 0.1-1.4 deg up to
    # 0.8 s without growth: the turn about z seen at grazing incidence). Without a confirmed re-acquisition the
    # map stays as built, and the track is lost where the -x face comes into view: at 1.0 s the true pose's tight
    # fitness is 0.79 < 0.8 (measured), as seed 3's true pose scored 0.64-0.72 on the one-sided map
    # (docs/perception.md, "The re-acquisition's candidates"); after it the bus' half turn fits (179.9 deg off).
    times = 0.1 * np.arange(1, 17)
    grown = _tracked(bus, c_fans_lidar, True, times)
    assert all(a.ok for a in grown.alignments[2:])
    for alignment, t in zip(grown.alignments[2:], times):
        error = Rotation.from_matrix(alignment.world_to_body[:3, :3] @ _rotation(t)).magnitude()
        assert np.degrees(error) < 2.0
    face = _on_minus_x_face(grown.model_points_body)
    assert face.sum() > 1000 and grown.map_growth
    added = grown.model_points_body[-sum(g["points_added"] for g in grown.map_growth):]
    assert np.all(np.abs(added[:, 0] + HALF_X)[_on_minus_x_face(added)] < 0.01)
    kept = _tracked(bus, c_fans_lidar, False, times[:10])
    assert not kept.map_growth and len(kept.model_points_body) == len(_one_sided_map(bus)[0])
    assert all(a.ok for a in kept.alignments[2:10]) and not kept.alignments[11].ok


def test_a_frame_that_failed_its_checks_adds_nothing(bus, c_fans_lidar):
    # The last frame cluttered (two thirds of its returns spread over a 3 m box: fails the tight fitness, 0.8):
    # it is not registered and grows nothing, while the frames before it, passed, grew the map.
    times = 0.1 * np.arange(1, 4)
    tracker = _tracked(bus, c_fans_lidar, True, times, clutter_at=2)
    assert all(a.ok for a in tracker.alignments[2:4]) and not tracker.alignments[4].ok
    assert [growth["time"] for growth in tracker.map_growth] == pytest.approx(times[:2])


def _frame(bus, lidar, t, ok):
    """A frame of the turning bus at ``t`` (s) registered at its true pose (passed or not), and its thinned scan."""
    points, _, truth = _scan(bus, lidar, _rotation(t), int(10 * t))
    scan = np.asarray(registration._cloud(points).voxel_down_sample(0.03).points)
    return Alignment(t, truth, np.eye(6), 1.0 if ok else 0.5, 0.0, 0.0, ok, False, 0.0, len(scan)), scan


@pytest.mark.parametrize("confirmed", [True, False])
def test_a_chain_grows_the_map_only_once_confirmed(bus, c_fans_lidar, confirmed):
    # The growth rule at a re-acquisition (DebrisTracker._grow_after_reacquisition): the frames of a pending chain
    # (failed until the motion confirms them) keep their scans and grow nothing; when the chain is confirmed
    # (its frames revised to passed), they and the confirming frame grow the map with the -x face they show
    # (frames at 1.0-1.3 s of the turn above: the face in view); a chain dropped instead grows nothing.
    tracker = DebrisTracker(0.03, 0.1, 30, *_one_sided_map(bus), seed=0, grow_map=True)
    times = (1.0, 1.1, 1.2)
    for t in times:   # pending chain frames: failed, a chain alive
        tracker._chains = [["a chain"]]
        alignment, scan = _frame(bus, c_fans_lidar, t, ok=False)
        tracker.alignments.append(alignment)
        tracker._grow_after_reacquisition(alignment, scan, tracked_with_motion=False)
    assert not tracker.map_growth and len(tracker._chain_scans) == 3
    tracker._chains = []
    confirming, scan = _frame(bus, c_fans_lidar, 1.3, ok=confirmed)
    if confirmed:   # _continue_chains revised the pending frames to their chain's passing alignments
        tracker.revised = [0, 1, 2]
        tracker.alignments[:3] = [_frame(bus, c_fans_lidar, t, ok=True)[0] for t in times]
    tracker.alignments.append(confirming)
    tracker._grow_after_reacquisition(confirming, scan, tracked_with_motion=False)
    assert not tracker._chain_scans
    if not confirmed:
        assert not tracker.map_growth and tracker._reacquired is False
        return
    assert tracker._reacquired and [g["time"] for g in tracker.map_growth] == [1.0, 1.1, 1.2, 1.3]
    assert _on_minus_x_face(tracker.model_points_body).sum() > 300
