"""Debris geometry: triangle meshes of primitives and mesh files (built with trimesh).

Every shape is placed in the *target frame* (the debris reference frame of the case
file); :func:`contact_shapes_body_frame` moves the triangles into a body frame
(origin at the body CoM, axes parallel to the target frame).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from multibody.shapes import SHAPES


def shape_mesh(kind: str, **keys) -> trimesh.Trimesh:
    """Closed triangle mesh of one shape, target frame (m): the plug-in of :mod:`multibody.shapes`
    named ``kind`` (one file each); an unknown kind is a ValueError listing the known ones.

    Parameters
    ----------
    kind : str   The shape's ``NAME`` ("box", "cylinder", "ellipsoid", "mesh", "sphere", ...).
    **keys       Its keys (SI, target frame), as its ``KEYS`` name them, e.g. ``size`` (3,) (m) and
                 ``center`` (3,) (m) of a box; see the shape file's ``mesh_target_frame``.
    """
    return SHAPES[kind].mesh_target_frame(**keys)


def uniform_density_inertia(meshes, mass, com_target):
    """Inertia tensor (kg m^2) about ``com_target`` of ``mass`` spread evenly over the meshes' volume.

    Overlapping shapes count twice; keep the shapes of one body disjoint when the
    inertia is to come from geometry.

    Parameters
    ----------
    meshes : list of trimesh.Trimesh
        Closed shapes of one body, vertices in the target frame (m).
    mass : float
        The body's mass (kg).
    com_target : (3,) float
        Reference point of the tensor (the body's CoM), target frame (m).

    Returns
    -------
    (3, 3) float
        Inertia tensor about ``com_target``, axes of the target frame (kg m^2).
    """
    volume = sum(m.volume for m in meshes)
    inertia_target = np.zeros((3, 3))
    for m in meshes:
        share = mass * m.volume / volume
        j_own_target = m.moment_inertia * share / m.volume  # trimesh uses unit density
        offset_target = np.asarray(m.center_mass) - np.asarray(com_target)
        inertia_target += j_own_target + share * (offset_target @ offset_target * np.eye(3)
                                                  - np.outer(offset_target, offset_target))
    return inertia_target


def geometric_center_of_mass(meshes):
    """Volume-weighted centroid of the meshes, target frame (m).

    Parameters
    ----------
    meshes : list of trimesh.Trimesh
        Closed shapes of one body, vertices in the target frame (m).

    Returns
    -------
    (3,) float
        Centroid of the shapes' joint volume, target frame (m).
    """
    volumes = np.array([m.volume for m in meshes])
    centers_target = np.array([m.center_mass for m in meshes])
    return volumes @ centers_target / volumes.sum()


@dataclass(frozen=True)
class ContactShapes:
    """Triangle soup of all contact shapes of all bodies, in body frames (see kernel)."""

    triangles_body: np.ndarray       # (T, 3, 3) m
    normals_body: np.ndarray         # (T, 3)
    shape_body: np.ndarray      # (ns,) int
    triangle_range: np.ndarray  # (ns, 2) int
    box_min_body: np.ndarray         # (ns, 3) m
    box_max_body: np.ndarray         # (ns, 3) m


def contact_shapes_body_frame(meshes_per_body, com_per_body) -> ContactShapes:
    """Collect the shapes of every body into kernel arrays, each moved into its body frame.

    Parameters
    ----------
    meshes_per_body : list of list of trimesh.Trimesh
        Shapes of each body, target frame.
    com_per_body : (nb, 3) float
        Body CoM, target frame (m). Body axes are parallel to the target frame.
    """
    triangles_body, normals_body, owner, ranges, lo_body, hi_body = [], [], [], [], [], []
    start = 0
    for b, meshes in enumerate(meshes_per_body):
        for mesh in meshes:
            tri_body = np.asarray(mesh.triangles) - np.asarray(com_per_body[b])
            triangles_body.append(tri_body)
            normals_body.append(np.asarray(mesh.face_normals))
            owner.append(b)
            ranges.append((start, start + len(tri_body)))
            lo_body.append(tri_body.reshape(-1, 3).min(axis=0))
            hi_body.append(tri_body.reshape(-1, 3).max(axis=0))
            start += len(tri_body)
    if not triangles_body:  # bodies without contact shapes
        return ContactShapes(np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros(0, np.int64),
                             np.zeros((0, 2), np.int64), np.zeros((0, 3)), np.zeros((0, 3)))
    return ContactShapes(
        triangles_body=np.ascontiguousarray(np.concatenate(triangles_body)),
        normals_body=np.ascontiguousarray(np.concatenate(normals_body)),
        shape_body=np.asarray(owner, np.int64),
        triangle_range=np.asarray(ranges, np.int64),
        box_min_body=np.asarray(lo_body), box_max_body=np.asarray(hi_body),
    )
