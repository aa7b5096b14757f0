"""Half-turn symmetries of the debris shape, and the tracker staying on one branch of them."""
import numpy as np
from scipy.spatial.transform import Rotation

from multibody.geometry import shape_mesh
from perception.registration import DebrisTracker, known_shape_model
from perception.shape import half_turn_symmetry_transforms


def test_ellipsoid_has_three_half_turns_and_a_box_offset_keeps_its_centre():
    # A triaxial ellipsoid (the paper's debris, semi-axes 0.65, 0.7, 0.9 m) maps onto itself by a
    # half turn about each principal axis: 4 transforms with the identity. An off-centre box
    # (centre at (1, 2, 3) m) has the same group, turning about its own centre, which stays put.
    ellipsoid = shape_mesh("ellipsoid", semi_axes=[0.65, 0.7, 0.9])
    assert len(half_turn_symmetry_transforms(ellipsoid, 0.015)) == 4
    box = shape_mesh("box", size=[1.0, 2.0, 3.0])
    box.apply_translation([1.0, 2.0, 3.0])
    transforms = half_turn_symmetry_transforms(box, 0.01)
    assert len(transforms) == 4
    for transform in transforms:
        np.testing.assert_allclose(transform[:3, :3] @ [1.0, 2.0, 3.0] + transform[:3, 3], [1.0, 2.0, 3.0], atol=1e-9)


def test_tracker_takes_the_variant_nearest_the_last_pose(paper_ellipsoid):
    # A pose flipped by one of the ellipsoid's half turns fits the surface exactly as well; the
    # tracker maps it back to the variant within the frame-to-frame turn of the reference
    # (here 5 deg away), so the attitude sequence has no 180 deg jumps.
    symmetries = half_turn_symmetry_transforms(paper_ellipsoid, 0.015)
    tracker = DebrisTracker(0.03, 0.1, 30, *known_shape_model(paper_ellipsoid, 0.03, seed=0),
                            symmetries_body=symmetries)
    reference = np.eye(4)
    reference[:3, :3] = Rotation.from_rotvec([0.4, -0.2, 1.0]).as_matrix()
    reference[:3, 3] = [-10.0, 0.3, 0.1]
    nearby = reference.copy()
    nearby[:3, :3] = Rotation.from_rotvec(np.radians(5.0) * np.array([0.0, 0.6, 0.8])).as_matrix() @ reference[:3, :3]
    for flip in symmetries:
        snapped = tracker._nearest_variant(flip @ nearby, reference)
        np.testing.assert_allclose(snapped, nearby, atol=1e-9)
