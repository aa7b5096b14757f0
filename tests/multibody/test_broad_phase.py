"""The kept candidate flags of the broad phase cover every per-step test (a Verlet list's skin)."""
import numpy as np
from scipy.spatial.transform import Rotation

from multibody.broad_phase import CANDIDATE_SKIN, update_candidates


def _per_step_flags(x_lvlh, reach, body_to_lvlh, com_lvlh, shape_body, box_min, box_max, shape_reach):
    """(ns, n) bool: node inside the shape's body-frame box grown by its reach plus the shape's (the
    test the contact pass needs every step), in numpy."""
    flags = []
    for s, b in enumerate(shape_body):
        centre = 0.5 * (box_min[s] + box_max[s])
        p = (x_lvlh - com_lvlh[b]) @ body_to_lvlh[b] - centre
        half = 0.5 * (box_max[s] - box_min[s])
        flags.append(np.all(np.abs(p) <= half + (reach[:, None] + shape_reach[s]), axis=1))
    return np.array(flags)


def test_kept_flags_are_a_superset_of_every_steps_flags_and_rebuild_rarely():
    """Nodes drifting at up to about 2 mm a step (20 m/s at 1e-4 s) and two bodies translating and turning:
    at each of 400 steps every node the per-step test keeps is flagged (no contact missed), and the box
    pass ran on fewer than a quarter of the steps."""
    rng = np.random.default_rng(5)
    n, step = 600, 1e-4
    x = rng.uniform(-3.0, 3.0, (n, 3))
    velocity = rng.normal(0.0, 3.0, (n, 3))
    shape_body = np.array([0, 0, 1], np.int64)
    box_min = np.array([[-1.0, -0.5, -0.5], [0.5, -0.2, -0.2], [-0.3, -0.3, -1.5]])
    box_max = np.array([[1.0, 0.5, 0.5], [2.5, 0.2, 0.2], [0.3, 0.3, 1.5]])
    com = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0]])
    com_velocity = np.array([[0.3, 0.0, 0.0], [0.0, -0.5, 0.2]])
    rotation_vector = np.zeros((2, 3))
    omega = np.array([[0.0, 0.0, 0.5], [0.8, 0.0, 0.0]])   # rad/s
    flags = np.zeros((len(shape_body) + 1, n), np.uint8)
    built_positions, built_bodies, built_grow = np.zeros((3, n)), np.zeros((2, 13)), np.zeros(1)
    rebuilds = 0
    for _ in range(400):
        velocity += rng.normal(0.0, 0.1, (n, 3))
        x += step * velocity
        com += step * com_velocity
        rotation_vector += step * omega
        body_to_lvlh = Rotation.from_rotvec(rotation_vector).as_matrix()
        reach = 0.01 + step * np.abs(velocity).sum(axis=1)
        shape_reach = step * (np.linalg.norm(com_velocity[shape_body], axis=1)
                              + np.linalg.norm(omega[shape_body], axis=1) * 2.6)
        rebuilds += update_candidates(np.ascontiguousarray(x.T), reach, body_to_lvlh, com, shape_body, box_min,
                                      box_max, shape_reach, flags, built_positions, built_bodies, built_grow)
        needed = _per_step_flags(x, reach, body_to_lvlh, com, shape_body, box_min, box_max, shape_reach)
        assert np.all(flags[:-1][needed] == 1)
        assert np.array_equal(flags[-1].astype(bool), flags[:-1].astype(bool).any(axis=0))
        assert needed.any()
    assert 1 <= rebuilds < 100
    assert built_grow[0] >= CANDIDATE_SKIN
