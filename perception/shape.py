"""Rotational symmetries of a debris shape: the poses a surface-only measurement cannot tell
apart. The tracker uses them to stay on one branch of its attitude (a frame searched without a
motion prediction takes the variant nearest the last pose); the scoring against the truth counts
every variant as right."""
from __future__ import annotations

import numpy as np
import open3d as o3d
import trimesh


def half_turn_symmetries(mesh: trimesh.Trimesh, tolerance: float, samples: int = 4000) -> list[np.ndarray]:
    """Rotations S (3, 3), mesh frame, that map the surface onto itself: the identity and those
    half turns about the principal axes (through the centroid) after which every sampled surface
    point lies within ``tolerance`` (m) of the surface. A uniform ellipsoid has all three; a
    generic body only the identity.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The surface (m, mesh frame).
    tolerance : float
        Largest distance (m) of a turned sample from the surface for a symmetry.
    samples : int
        Surface points tested (fixed seed).

    Returns
    -------
    list of (3, 3) float
        Rotations of the mesh frame, the identity first.
    """
    return [transform[:3, :3] for transform in half_turn_symmetry_transforms(mesh, tolerance, samples)]


def half_turn_symmetry_transforms(mesh: trimesh.Trimesh, tolerance: float, samples: int = 4000) -> list[np.ndarray]:
    """The same symmetries as homogeneous transforms (4, 4) of the mesh frame, turning about the
    centroid: x -> S (x - c) + c.

    Parameters
    ----------
    mesh, tolerance, samples :
        As in :func:`half_turn_symmetries`.

    Returns
    -------
    list of (4, 4) float
        Homogeneous transforms of the mesh frame (m), the identity first; c is the centre of
        mass of a watertight mesh, else the surface centroid.
    """
    points = trimesh.sample.sample_surface(mesh, samples, seed=1)[0]
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(np.asarray(mesh.vertices, np.float32)),
                        o3d.core.Tensor(np.asarray(mesh.faces, np.uint32)))
    center = mesh.center_mass if mesh.is_watertight else mesh.centroid
    axes = mesh.principal_inertia_vectors.T if mesh.is_watertight else np.linalg.eigh(np.cov((points - center).T))[1]
    found = [np.eye(3)]
    for k in range(3):
        flip = -np.ones(3)
        flip[k] = 1.0
        turn = axes @ np.diag(flip) @ axes.T
        moved = (points - center) @ turn.T + center
        if scene.compute_distance(o3d.core.Tensor(moved.astype(np.float32))).numpy().max() < tolerance:
            found.append(turn)
    transforms = []
    for turn in found:
        transform = np.eye(4)
        transform[:3, :3], transform[:3, 3] = turn, center - turn @ center
        transforms.append(transform)
    return transforms


def rotation_error(estimated_body_to_world, true_body_to_world, symmetries) -> float:
    """Smallest rotation angle (rad) between an estimated attitude and the true one or any of its
    indistinguishable variants ``R_true S``.

    Parameters
    ----------
    estimated_body_to_world : (3, 3) float
        Estimated attitude, model frame B -> world (B the mesh frame of a known shape).
    true_body_to_world : (3, 3) float
        True attitude, mesh frame -> world.
    symmetries : list of (3, 3) float
        Rotations S of the mesh frame (:func:`half_turn_symmetries`), the identity included.

    Returns
    -------
    float
        Angle (rad), in [0, pi].
    """
    angles = []
    for s in symmetries:
        relative = np.asarray(estimated_body_to_world) @ (np.asarray(true_body_to_world) @ s).T
        angles.append(np.arccos(np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0)))
    return float(min(angles))
