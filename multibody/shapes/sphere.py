"""Contact shape ``sphere``: an icosphere of two subdivisions (320 triangles)."""
from __future__ import annotations

import trimesh

from multibody.shapes.base import Key

#: The name a case gives (``kind = "sphere"``).
NAME = "sphere"
#: Its keys in a case's ``shapes`` table.
KEYS = (
    Key("radius", "positive", "(m)"),
    Key("center", "vector3", "Centre, target frame (m)."),
)


def mesh_target_frame(radius, center=(0, 0, 0)) -> trimesh.Trimesh:
    """The sphere's mesh, vertices on the sphere, target frame (m).

    Parameters
    ----------
    radius : float        (m)
    center : (3,) float   Centre, target frame (m).
    """
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=radius)
    mesh.apply_translation(center)
    return mesh
