"""Threads that pass through a contact shape: what node-based contact cannot see.

Contact acts on the net's nodes only (paper eq. 6, a node sphere against a surface), as in the seed
paper's model. A thread between two nodes that lie on opposite sides of a thin part (Envisat's 5 cm
solar array, the 0.16 m ASAR antenna, a 10 cm boom) therefore passes through it without a force:
the load that thread would put on the part is missing from the run. This module finds such threads
in the recorded net snapshots so the verdict can say so (``structures.verdict``).

A thread *passes through* a convex shape when both its nodes are outside and the segment between
them enters through one face and leaves through a face turned away from it (normals at more than
120 degrees, :data:`OPPOSITE_FACES_COS`): it crossed the part's whole thickness. A chord cutting a
box's edge (adjacent faces, 90 degrees) or sagging into a cylinder between two resting nodes (nearly
parallel faces) is the net's discretization wrapping a curved or edged surface, not a pass-through.

The load the part would have taken from a passing thread is at most twice its tension (the thread
turned back on itself round the part), applied where it crosses: :func:`missed_load_bounds` sums
that bound about a point.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multibody.geometry import contact_shapes_body_frame
from multibody.net import thread_tension_strain

#: Cosine of the angle between the entry and exit face normals below which a crossing thread went
#: through the part from one side to the other (120 degrees: a box's opposite faces are at 180,
#: adjacent ones at 90; a cylinder's sides seen by a chord of a quarter turn are at 90).
OPPOSITE_FACES_COS = -0.5


@dataclass(frozen=True)
class PassThroughs:
    """Threads passing through one shape at one instant.

    Attributes
    ----------
    threads : (c,) int            Thread indices.
    inside_length : (c,) float    Length of each thread inside the shape (m).
    point_lvlh : (c, 3) float     Midpoint of each thread's inside part, LVLH (m).
    """

    threads: np.ndarray
    inside_length: np.ndarray
    point_lvlh: np.ndarray


def clip_segments_convex(start_body, end_body, triangles_body, normals_body):
    """Cyrus-Beck clip of segments against one convex shape given by its faces (body frame).

    Parameters
    ----------
    start_body, end_body : (s, 3) float
        Segment ends, body frame (m).
    triangles_body : (f, 3, 3) float
        The shape's triangles, body frame (m).
    normals_body : (f, 3) float
        Their outward unit normals.

    Returns
    -------
    t_enter, t_exit : (s,) float
        The part of each segment inside the shape, as fractions of its length (empty when
        ``t_exit <= t_enter``).
    face_enter, face_exit : (s,) int
        The faces the segment enters and leaves through (-1 where it starts or ends inside).
    """
    direction = end_body - start_body
    # inside the face's half-space: n.(p - v0) <= 0, i.e. t (n.d) <= n.(v0 - a)
    reach = np.einsum("fk,sfk->sf", normals_body, triangles_body[None, :, 0, :] - start_body[:, None, :])
    rate = direction @ normals_body.T
    with np.errstate(divide="ignore", invalid="ignore"):
        t_plane = reach / rate
    entering = rate < 0.0
    t_in = np.where(entering, t_plane, -np.inf)
    t_out = np.where(rate > 0.0, t_plane, np.inf)
    parallel_outside = np.any((rate == 0.0) & (reach < 0.0), axis=1)
    face_enter = np.argmax(t_in, axis=1)
    face_exit = np.argmin(t_out, axis=1)
    t_enter = np.take_along_axis(t_in, face_enter[:, None], 1)[:, 0]
    t_exit = np.take_along_axis(t_out, face_exit[:, None], 1)[:, 0]
    face_enter = np.where(t_enter > 0.0, face_enter, -1)
    face_exit = np.where(t_exit < 1.0, face_exit, -1)
    t_enter, t_exit = np.maximum(t_enter, 0.0), np.minimum(t_exit, 1.0)
    t_exit = np.where(parallel_outside, t_enter, t_exit)
    return t_enter, t_exit, face_enter, face_exit


def pass_throughs_shape(positions_lvlh, threads, com_lvlh, body_to_lvlh, triangles_body, normals_body,
                        box_min_body, box_max_body) -> PassThroughs:
    """The threads passing through one convex shape of one body at one instant (module docstring).

    Parameters
    ----------
    positions_lvlh : (n, 3) float
        Net node positions, LVLH (m).
    threads : (m, 2) int
        Node pairs joined by a thread.
    com_lvlh : (3,) float
        The body's CoM, LVLH (m).
    body_to_lvlh : (3, 3) float
        The body's attitude.
    triangles_body, normals_body : (f, 3, 3), (f, 3) float
        The shape's faces, body frame (m).
    box_min_body, box_max_body : (3,) float
        The shape's bounding box, body frame (m).

    Returns
    -------
    PassThroughs
    """
    x_body = (np.asarray(positions_lvlh, float) - com_lvlh) @ body_to_lvlh
    a, b = x_body[threads[:, 0]], x_body[threads[:, 1]]
    near = np.all(np.minimum(a, b) <= box_max_body, axis=1) & np.all(np.maximum(a, b) >= box_min_body, axis=1)
    candidates = np.flatnonzero(near)
    if not candidates.size:
        return PassThroughs(np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3)))
    a, b = a[candidates], b[candidates]
    t_enter, t_exit, face_enter, face_exit = clip_segments_convex(a, b, triangles_body, normals_body)
    both_ends_outside = (face_enter >= 0) & (face_exit >= 0) & (t_exit > t_enter)
    turned = np.einsum("sk,sk->s", normals_body[np.maximum(face_enter, 0)], normals_body[np.maximum(face_exit, 0)])
    through = both_ends_outside & (turned < OPPOSITE_FACES_COS)
    length = np.linalg.norm(b - a, axis=1)
    middle_body = a + 0.5 * (t_enter + t_exit)[:, None] * (b - a)
    return PassThroughs(candidates[through], ((t_exit - t_enter) * length)[through],
                        com_lvlh + middle_body[through] @ body_to_lvlh.T)


def missed_load_bounds(crossings: PassThroughs, tension, point_lvlh) -> tuple[float, float]:
    """Upper bounds of the force and of the moment about ``point_lvlh`` that the passing threads would
    have put on the part: twice each thread's tension, at its crossing point.

    Parameters
    ----------
    crossings : PassThroughs
        The threads passing through the part.
    tension : (m,) float
        Every thread's tension (N).
    point_lvlh : (3,) float
        The point the moment is taken about, LVLH (m).

    Returns
    -------
    force : float
        N.
    moment : float
        N m.
    """
    pull = 2.0 * np.asarray(tension)[crossings.threads]
    arm = np.linalg.norm(crossings.point_lvlh - np.asarray(point_lvlh), axis=1)
    return float(pull.sum()), float(pull @ arm)


@dataclass(frozen=True)
class PassThroughSnapshot:
    """Every pass-through of one net snapshot.

    Attributes
    ----------
    time : float                       s.
    by_body : dict of int to PassThroughs   Per body index (bodies with none are left out).
    tension : (m,) float               Every thread's tension at that instant (N).
    """

    time: float
    by_body: dict
    tension: np.ndarray


def pass_through_history(net_time, net_positions_lvlh, series_time, body_com_lvlh, body_to_lvlh, net,
                         meshes_per_body) -> list[PassThroughSnapshot]:
    """The pass-throughs of every recorded net snapshot (snapshots with none are left out).

    Parameters
    ----------
    net_time : (k,) float
        Snapshot times (s).
    net_positions_lvlh : (k, n, 3) float
        Node positions at the snapshots, LVLH (m).
    series_time : (r,) float
        Sample times of the body states (s); each snapshot takes the nearest sample.
    body_com_lvlh : (r, nb, 3) float
        Body CoMs, LVLH (m).
    body_to_lvlh : (r, nb, 3, 3) float
        Body attitudes.
    net : multibody.net.NetTopology
        The net (threads, rest lengths, stiffness).
    meshes_per_body : list of list of trimesh.Trimesh
        Each body's convex contact shapes, body frame with the origin at the CoM (m).

    Returns
    -------
    list of PassThroughSnapshot
    """
    shapes = contact_shapes_body_frame(meshes_per_body, np.zeros((len(meshes_per_body), 3)))
    series_time = np.asarray(series_time, float)
    history = []
    for t, positions in zip(net_time, net_positions_lvlh):
        k = int(np.argmin(np.abs(series_time - t)))
        by_body = {}
        for s, b in enumerate(shapes.shape_body):
            first, last = shapes.triangle_range[s]
            found = pass_throughs_shape(positions, net.threads, body_com_lvlh[k, b], body_to_lvlh[k, b],
                                        shapes.triangles_body[first:last], shapes.normals_body[first:last],
                                        shapes.box_min_body[s], shapes.box_max_body[s])
            if found.threads.size:
                by_body[b] = found if b not in by_body else _merged(by_body[b], found)
        if by_body:
            history.append(PassThroughSnapshot(float(t), by_body, elastic_tension(positions, net)))
    return history


def elastic_tension(positions_lvlh, net):
    """Every thread's tension (N) from its stretch alone: the net's own law
    (:func:`multibody.net.thread_tension_strain`) with the damper left out, as the bound states.

    Parameters
    ----------
    positions_lvlh : (n, 3) float
        Node positions, LVLH (m).
    net : multibody.net.NetTopology
        Threads, rest lengths, stiffness and damping.

    Returns
    -------
    tension : (m,) float
    """
    at_rest = np.zeros_like(positions_lvlh)
    return thread_tension_strain(positions_lvlh, at_rest, net.threads, net.rest_lengths, net.stiffness,
                                 net.damping)[0]


def _merged(first: PassThroughs, second: PassThroughs) -> PassThroughs:
    """Two shapes of one body: a thread through both counts once (its first crossing kept)."""
    new = ~np.isin(second.threads, first.threads)
    return PassThroughs(np.concatenate([first.threads, second.threads[new]]),
                        np.concatenate([first.inside_length, second.inside_length[new]]),
                        np.concatenate([first.point_lvlh, second.point_lvlh[new]]))
