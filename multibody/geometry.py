"""Debris geometry: triangle meshes of primitives and mesh files (built with trimesh).

Every shape is placed in the *target frame* (the debris reference frame of the case
file); :func:`contact_shapes_body_frame` moves the triangles into a body frame
(origin at the body CoM, axes parallel to the target frame).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation


def shape_mesh(kind: str, *, size=None, radius=None, length=None, axis=None, center=(0, 0, 0),
               rotation_vector=(0, 0, 0), file=None, scale=1.0, sections=32, semi_axes=None,
               subdivisions=3) -> trimesh.Trimesh:
    """Closed triangle mesh of one shape, target frame (m).

    Parameters
    ----------
    kind : {"box", "cylinder", "sphere", "ellipsoid", "mesh"}
    size : (3,) float       Box edge lengths (m), box frame.
    radius, length : float  Cylinder or sphere radius (m); cylinder length (m).
    axis : (3,) float       Cylinder axis, target frame.
    semi_axes : (3,) float  Ellipsoid semi-axes along its own x, y, z (m) before ``rotation_vector``.
    subdivisions : int      Icosphere refinement of the ellipsoid (3: 1280 triangles).
    center : (3,) float     Shape centre, target frame (m).
    rotation_vector : (3,) float  Shape->target rotation for boxes, ellipsoids and meshes (rad).
    file : path             Mesh file (any format trimesh reads), vertices in m before ``scale``.
    scale : float           Factor applied to the mesh file's vertices (-).
    sections : int          Facets around a cylinder's circumference.
    """
    if kind == "box":
        mesh = trimesh.creation.box(extents=size)
    elif kind == "cylinder":
        mesh = trimesh.creation.cylinder(radius=radius, height=length, sections=sections)
        mesh.apply_transform(_align_z_to(axis))
    elif kind == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=radius)
    elif kind == "ellipsoid":
        mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
        mesh.apply_scale(np.asarray(semi_axes, float))
    elif kind == "mesh":
        mesh = trimesh.load_mesh(Path(file), force="mesh")
        mesh.apply_scale(scale)
    else:
        raise ValueError(f"unknown shape kind {kind!r}")
    if kind in ("box", "ellipsoid", "mesh"):
        transform = np.eye(4)
        transform[:3, :3] = Rotation.from_rotvec(rotation_vector).as_matrix()
        mesh.apply_transform(transform)
    mesh.apply_translation(center)
    return mesh


def _align_z_to(axis) -> np.ndarray:
    """4x4 rotation taking the z axis onto ``axis``."""
    return trimesh.geometry.align_vectors([0, 0, 1], np.asarray(axis, float) / np.linalg.norm(axis))


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
