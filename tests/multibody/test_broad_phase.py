"""The broad phase's skin flags exactly the nodes the full box pass flags (multibody.broad_phase).

The skin lets a node skip the box test while its clearance from every shape, less its own motion and the
shapes' since the skin was made, exceeds sqrt(3) times its reach; the claim is that the flags are then
the full pass's to the bit. Checked on a moving cloud of nodes around two boxes that translate and turn,
over enough evaluations to cross skins made for age and for growth, and with a non-finite body.
"""
import numpy as np
import pytest

from multibody.broad_phase import (
    SKIN_FULL_PASS_SHARE,
    SKIN_MAX_AGE,
    broad_phase_skin,
    flag_candidates,
    flag_candidates_skin,
)
from multibody.maths.rotations import rotation_matrix_from_rotation_vector


def _scene(rng, n_nodes, half_width=4.0):
    """Two bodies with one box each, a node cloud around them (m), reaches of a few mm to a few cm."""
    box_min = np.array([[-1.0, -0.4, -0.3], [-3.0, -0.05, -1.0]])
    box_max = np.array([[1.0, 0.6, 0.3], [3.0, 0.05, 1.0]])
    x = rng.uniform(-half_width, half_width, (3, n_nodes))
    velocity = rng.normal(0.0, 2.0, (3, n_nodes))
    return box_min, box_max, x, velocity


@pytest.mark.parametrize("half_width", [4.0, 1.5])   # few nodes near the boxes (the skin), many (the full pass)
def test_skin_flags_equal_the_full_pass_while_nodes_and_bodies_move(half_width):
    rng = np.random.default_rng(7)
    n_nodes, dt = 600, 2e-3
    box_min, box_max, x, velocity = _scene(rng, n_nodes, half_width)
    shape_body = np.array([0, 1])
    com = np.array([[0.0, 0.0, 0.0], [0.5, 1.5, 0.0]])
    com_rate = np.array([[0.3, -0.2, 0.1], [-0.5, 0.0, 0.4]])
    rotation_vector = np.array([[0.1, 0.2, 0.3], [1.0, -0.5, 0.2]])
    rate = np.array([[0.5, 0.0, 1.0], [0.0, 2.0, -1.0]])     # rad/s: the boxes turn by ~0.5 rad over the run
    skin = broad_phase_skin(n_nodes, 2)
    full = np.zeros((3, n_nodes), np.uint8)
    skipped = np.zeros((3, n_nodes), np.uint8)
    flagged = 0
    steps = 3 * SKIN_MAX_AGE // 2
    for k in range(steps):
        body_to_lvlh = np.array([rotation_matrix_from_rotation_vector(r) for r in rotation_vector])
        reach = rng.uniform(0.002, 0.05, n_nodes)
        shape_reach = rng.uniform(0.0, 0.02, 2)
        flag_candidates(x, reach, body_to_lvlh, com, shape_body, box_min, box_max, shape_reach, full)
        skipped[:] = 7      # stale values: every entry must be written
        flag_candidates_skin(x, reach, body_to_lvlh, com, shape_body, box_min, box_max, shape_reach, skipped, skin)
        np.testing.assert_array_equal(skipped, full, err_msg=f"evaluation {k}")
        flagged += int(full[2].sum())
        x += velocity * dt
        velocity += rng.normal(0.0, 5.0, velocity.shape) * dt    # jerky nodes, as in a strike
        com += com_rate * dt
        rotation_vector += rate * dt
    assert flagged > 1000                   # the scene has near nodes to find
    assert skin.counts[2] >= 2              # more than one skin made (age or growth)
    if half_width > 2.0:                    # the skin's own path: most node tests skipped
        assert 0 < skin.counts[3] < steps * n_nodes / 4
    else:                                   # crowded: the full pass ran instead
        assert skin.counts[1] > n_nodes // SKIN_FULL_PASS_SHARE


def test_skin_with_a_non_finite_body_flags_as_the_full_pass():
    rng = np.random.default_rng(3)
    box_min, box_max, x, _ = _scene(rng, 200)
    shape_body = np.array([0, 1])
    com = np.array([[0.0, 0.0, 0.0], [np.nan, 1.5, 0.0]])
    body_to_lvlh = np.array([np.eye(3), np.eye(3)])
    reach, shape_reach = np.full(200, 1.0), np.zeros(2)
    full = np.zeros((3, 200), np.uint8)
    skipped = np.zeros((3, 200), np.uint8)
    skin = broad_phase_skin(200, 2)
    for _ in range(3):
        flag_candidates(x, reach, body_to_lvlh, com, shape_body, box_min, box_max, shape_reach, full)
        flag_candidates_skin(x, reach, body_to_lvlh, com, shape_body, box_min, box_max, shape_reach, skipped, skin)
        np.testing.assert_array_equal(skipped, full)
    assert full[0].sum() > 0 and full[1].sum() == 0
