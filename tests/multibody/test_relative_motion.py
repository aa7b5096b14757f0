"""The net's relative energy taken apart (multibody/relative_motion.py) against hand-derived answers."""
import numpy as np
import pytest

from multibody.net import net_kinetic_energy_relative_to_body
from multibody.relative_motion import (appendage_energy_relative_to_body, convex_distance, face_planes,
                                       nearest_body_relative_energy, rigid_split, velocity_field)

# a unit cube about its centre: 8 vertices, 12 triangles (either winding; face_planes orients them outward)
CUBE_VERTICES = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
CUBE_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def swinging_appendage_scene(rng, n=6):
    """A main body at rest-ish (spinning slowly) and an appendage hinged to it swinging at 0.3 rad/s about its own
    axis; n nodes glued to the appendage (moving with its velocity field) and one free bullet of 1.786 kg moving at
    0.4 m/s relative to the main body's field, nearest the main body. Returns what the functions take."""
    main_com, main_v, main_w = np.zeros(3), np.array([0.01, -0.02, 0.0]), np.array([0.0, 0.0, 0.02])
    app_com, app_w = np.array([0.0, 0.0, 11.6]), main_w + np.array([0.3, 0.0, 0.0])
    hinge = np.array([0.0, 0.0, 4.4])
    # the appendage's centre moves with the main body's field at the hinge plus its swing about the hinge
    app_v = velocity_field(hinge[None], main_com, main_v, main_w)[0] + np.cross(app_w, app_com - hinge)
    x_glued = app_com + rng.uniform(-1.0, 1.0, (n, 3)) * [2.5, 0.02, 7.0]
    v_glued = velocity_field(x_glued, app_com, app_v, app_w)
    x_bullet = np.array([[0.0, -2.5, 0.0]])
    own = np.array([[0.4, 0.0, 0.0]])
    v_bullet = velocity_field(x_bullet, main_com, main_v, main_w) + own
    x, v = np.vstack([x_glued, x_bullet]), np.vstack([v_glued, v_bullet])
    masses = np.append(np.full(n, 0.04223), 1.786)
    bodies = ((main_com, main_v, main_w), (app_com, app_v, app_w))
    fields = np.stack([velocity_field(x, *b) for b in bodies], axis=1)[None]      # (1, n+1, 2, 3)
    nearest = np.append(np.ones(n, int), 0)[None]
    return masses, x[None], v[None], fields, nearest, own, bodies


@pytest.mark.parametrize("seed", range(5))
def test_glued_nodes_read_zero_and_free_bullet_its_own_energy(seed):
    masses, x, v, fields, nearest, own, bodies = swinging_appendage_scene(np.random.default_rng(seed))
    energy = nearest_body_relative_energy(masses, v, fields, nearest)
    # nodes moving with the appendage's rigid field: zero relative to what they touch (round-off only, ~1e-30 J)
    assert np.all(energy["near"][0, :-1] < 1e-20)
    # ... but not relative to the main body: their whole relative energy is carried by the swing
    assert np.allclose(energy["main"][0, :-1], energy["carried"][0, :-1], rtol=1e-12, atol=1e-20)
    assert energy["main"][0, :-1].sum() > 1e-3
    # the free bullet reads its own kinetic energy relative to the main body, 1/2 1.786 0.4^2 = 0.14288 J, either way
    expected = 0.5 * 1.786 * 0.4 ** 2
    assert energy["near"][0, -1] == pytest.approx(expected, rel=1e-12)
    assert energy["main"][0, -1] == pytest.approx(expected, rel=1e-12)
    assert energy["carried"][0, -1] == pytest.approx(0.0, abs=1e-20)
    # E_main is the capture rule's T_rel (multibody.net), node by node summed
    main_com, main_v, main_w = bodies[0]
    assert energy["main"].sum() == pytest.approx(
        net_kinetic_energy_relative_to_body(masses, x[0], v[0], main_com, main_v, main_w), rel=1e-12)


def test_appendage_energy_is_its_swing_about_the_hinge():
    # a 350 kg array swinging at 0.3 rad/s about a hinge 7.15 m from its centre on a body spinning at 0.02 rad/s:
    # T = 1/2 (I_c + m d^2) w^2 about the hinge axis (the parallel-axis theorem), I_c = 5964.36 kg m^2 (the case's)
    inertia = np.diag([5964.36, 6693.46, 729.24])
    main_com, main_v, main_w = np.zeros(3), np.array([0.01, -0.02, 0.0]), np.array([0.0, 0.0, 0.02])
    hinge, com = np.array([0.0, 0.0, 4.4375]), np.array([0.0, 0.0, 11.5875])
    omega = main_w + [0.3, 0.0, 0.0]
    velocity = velocity_field(hinge[None], main_com, main_v, main_w)[0] + np.cross(omega, com - hinge)
    energy = appendage_energy_relative_to_body(350.0, inertia, com[None], velocity[None], omega[None], np.eye(3)[None],
                                               main_com[None], main_v[None], main_w[None])
    assert energy[0] == pytest.approx(0.5 * (5964.36 + 350.0 * 7.15 ** 2) * 0.3 ** 2, rel=1e-12)
    # at rest relative to the main body: zero
    rigid = velocity_field(com[None], main_com, main_v, main_w)[0]
    still = appendage_energy_relative_to_body(350.0, inertia, com[None], rigid[None], main_w[None], np.eye(3)[None],
                                              main_com[None], main_v[None], main_w[None])
    assert still[0] == pytest.approx(0.0, abs=1e-20)


@pytest.mark.parametrize("seed", range(5))
def test_rigid_split_of_a_rigidly_moving_net_has_no_deformation(seed):
    rng = np.random.default_rng(seed)
    masses = rng.uniform(0.04, 1.8, 12)
    x = rng.normal(0.0, 3.0, (1, 12, 3))
    u_g, w = rng.normal(0.0, 0.3, 3), rng.normal(0.0, 0.1, 3)
    x_g = masses @ x[0] / masses.sum()
    u = u_g + np.cross(w, x - x_g)
    split = rigid_split(masses, x, u)
    # Koenig: the centre's 1/2 M |u_G|^2, the rotation's 1/2 w.J.w, nothing left (round-off, 1e-12 of the total)
    r = x[0] - x_g
    inertia = (masses * (r * r).sum(1)).sum() * np.eye(3) - np.einsum("n,ni,nj->ij", masses, r, r)
    assert split["centre"][0] == pytest.approx(0.5 * masses.sum() * u_g @ u_g, rel=1e-12)
    assert split["rotation"][0] == pytest.approx(0.5 * w @ inertia @ w, rel=1e-10)
    assert abs(split["deformation"][0]) < 1e-10 * (split["centre"][0] + split["rotation"][0])


def test_rigid_split_of_two_nodes_flying_apart_is_all_deformation():
    # two equal nodes moving apart along their line at +-0.5 m/s: no centre motion, no rotation (L = 0),
    # T = 2 x 1/2 x 1 kg x 0.25 = 0.25 J of deformation
    x = np.array([[[-1.0, 0, 0], [1.0, 0, 0], [0, 1e-3, 0]]])
    u = np.array([[[-0.5, 0, 0], [0.5, 0, 0], [0, 0, 0]]])
    split = rigid_split(np.array([1.0, 1.0, 1e-9]), x, u)
    assert split["centre"][0] == pytest.approx(0.0, abs=1e-15)
    assert split["deformation"][0] == pytest.approx(0.25, rel=1e-6)


def test_convex_distance_of_a_cube():
    normals, offsets = face_planes(CUBE_VERTICES, CUBE_FACES)
    points = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, -0.7, 0.1], [1.5, 1.5, 0.0]])
    d = convex_distance(points, normals, offsets)
    # centre: -0.5 (the face half-width); in front of a face: the gap; past an edge: the larger face gap (a lower
    # bound of the true 1 x sqrt(2) = 1.414 m)
    assert d == pytest.approx([-0.5, 1.5, 0.2, 1.0], abs=1e-12)
