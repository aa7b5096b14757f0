"""Contact shape ``cylinder``: a closed circular cylinder along a given axis."""
from __future__ import annotations

import numpy as np
import trimesh

from multibody.shapes.base import Key

#: The name a case gives (``kind = "cylinder"``).
NAME = "cylinder"
#: Its keys in a case's ``shapes`` table.
KEYS = (
    Key("radius", "positive", "(m)"),
    Key("length", "positive", "(m)"),
    Key("axis", "vector3", "Axis direction, target frame (-)."),
    Key("center", "vector3", "Centre, target frame (m)."),
)


def mesh_target_frame(radius, length, axis, center=(0, 0, 0), sections=32) -> trimesh.Trimesh:
    """The cylinder's mesh (flat end caps), target frame (m).

    Parameters
    ----------
    radius, length : float   Radius and length along the axis (m).
    axis : (3,) float        Axis direction, target frame (-); any non-zero length.
    center : (3,) float      Centre (mid-length on the axis), target frame (m).
    sections : int           Facets around the circumference (not a case key).
    """
    mesh = trimesh.creation.cylinder(radius=radius, height=length, sections=sections)
    mesh.apply_transform(_align_z_to(axis))
    mesh.apply_translation(center)
    return mesh


def _align_z_to(axis) -> np.ndarray:
    """4x4 rotation taking the z axis onto ``axis``."""
    return trimesh.geometry.align_vectors([0, 0, 1], np.asarray(axis, float) / np.linalg.norm(axis))
