"""Threads passing through contact shapes (multibody/thread_crossing.py), against hand geometry."""
import numpy as np
import pytest
import trimesh

from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from multibody.net import NetTopology, thread_tension_strain
from multibody.thread_crossing import (
    clip_segments_convex,
    missed_load_bounds,
    pass_through_history,
    pass_throughs_shape,
)


def _through(mesh, a, b, com=np.zeros(3), body_to_lvlh=np.eye(3)):
    positions = np.array([a, b], float)
    return pass_throughs_shape(positions, np.array([[0, 1]]), com, body_to_lvlh, np.asarray(mesh.triangles),
                               np.asarray(mesh.face_normals), mesh.bounds[0], mesh.bounds[1])


PLATE = trimesh.creation.box(extents=[2.0, 2.0, 0.05])      # a 5 cm panel, like Envisat's array


def test_a_thread_across_a_thin_plate_passes_through_by_its_thickness():
    straight = _through(PLATE, [0.1, 0.2, -0.5], [0.1, 0.2, 0.5])
    assert straight.threads.tolist() == [0]
    assert straight.inside_length[0] == pytest.approx(0.05, rel=1e-12)
    assert straight.point_lvlh[0] == pytest.approx([0.1, 0.2, 0.0], abs=1e-12)
    # at 45 degrees the inside length is the thickness times sqrt(2)
    oblique = _through(PLATE, [-0.5, 0.0, -0.5], [0.5, 0.0, 0.5])
    assert oblique.inside_length[0] == pytest.approx(0.05 * np.sqrt(2.0), rel=1e-12)


def test_corner_cuts_ends_inside_misses_and_parallel_threads_are_not_pass_throughs():
    cube = trimesh.creation.box(extents=[1.0, 1.0, 1.0])
    # x + y = 0.9 cuts the +x/+y edge (adjacent faces, 90 degrees): the net wrapping an edge
    assert _through(cube, [0.6, 0.3, 0.0], [0.3, 0.6, 0.0]).threads.size == 0
    assert _through(cube, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]).threads.size == 0      # a node inside: node contact
    assert _through(cube, [0.7, -2.0, 0.0], [0.7, 2.0, 0.0]).threads.size == 0     # passes beside it
    assert _through(PLATE, [-2.0, 0.0, 0.03], [2.0, 0.0, 0.03]).threads.size == 0  # parallel, 5 mm above
    t_enter, t_exit, *_ = clip_segments_convex(np.array([[-2.0, 0.0, 0.03]]), np.array([[2.0, 0.0, 0.03]]),
                                               np.asarray(PLATE.triangles), np.asarray(PLATE.face_normals))
    assert t_exit[0] <= t_enter[0]


def test_chords_of_a_wrapped_cylinder_are_not_pass_throughs_but_a_thin_boom_crossed_is():
    drum = trimesh.creation.cylinder(radius=1.0, height=4.0, sections=64)
    # two nodes resting on the drum 0.6 rad apart: the chord sags 1 - cos(0.3) = 4.5 cm into it
    a, b = [np.cos(0.3), np.sin(0.3), 0.0], [np.cos(-0.3), np.sin(-0.3), 0.0]
    assert _through(drum, a, b).threads.size == 0
    boom = trimesh.creation.cylinder(radius=0.05, height=4.0, sections=64)
    crossed = _through(boom, [-1.0, 0.0, 0.5], [1.0, 0.0, 0.5])
    # across the axis: the diameter, to the facets' cos(pi/64) (0.12 %)
    assert crossed.inside_length[0] == pytest.approx(0.1, rel=2e-3)


def test_the_body_pose_carries_the_shape():
    body_to_lvlh = rotation_matrix_from_rotation_vector(np.array([0.3, -0.2, 0.5]))
    com = np.array([10.0, -3.0, 2.0])
    normal_lvlh = body_to_lvlh[:, 2]
    a, b = com - 0.5 * normal_lvlh, com + 0.5 * normal_lvlh
    found = _through(PLATE, a, b, com, body_to_lvlh)
    assert found.inside_length[0] == pytest.approx(0.05, rel=1e-12)
    assert found.point_lvlh[0] == pytest.approx(com, abs=1e-12)
    assert _through(PLATE, a, b).threads.size == 0     # the same thread against the plate at the origin


def test_tension_and_the_missed_load_bounds():
    positions = np.array([[0.0, 0.0, 0.0], [1.1, 0.0, 0.0], [1.1, 0.95, 0.0]])
    threads = np.array([[0, 1], [1, 2]])
    tension, _ = thread_tension_strain(positions, np.zeros_like(positions), threads, np.array([1.0, 1.0]),
                                       np.array([200.0, 200.0]), np.zeros(2))
    assert tension == pytest.approx([20.0, 0.0])     # 200 N/m x 0.1 m stretch; the second is slack
    crossings = _through(PLATE, [0.0, 0.0, -0.5], [0.0, 0.0, 0.5])
    force, moment = missed_load_bounds(crossings, np.array([20.0]), np.array([3.0, 4.0, 0.0]))
    assert force == 40.0 and moment == pytest.approx(40.0 * 5.0)    # twice the tension, at 5 m


def test_history_keeps_only_snapshots_with_pass_throughs():
    positions = np.array([[0.0, 0.0, -0.5], [0.0, 0.0, 0.5]])
    net = NetTopology(positions=positions, masses=np.ones(2), radii=np.full(2, 1e-3), threads=np.array([[0, 1]]),
                      rest_lengths=np.array([0.9]), stiffness=np.array([100.0]), damping=np.zeros(1),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0),
                      nodes_per_side=2, n_bullets=0)
    snapshots = np.array([positions, positions + [5.0, 0.0, 0.0]])     # the second is beside the plate
    history = pass_through_history([0.0, 0.1], snapshots, np.array([0.0, 0.1]), np.zeros((2, 1, 3)),
                                   np.tile(np.eye(3), (2, 1, 1, 1)), net, [[PLATE]])
    assert [h.time for h in history] == [0.0]
    assert history[0].by_body[0].threads.tolist() == [0] and history[0].tension == pytest.approx([10.0])
