"""Contact shape ``mesh``: a closed triangle mesh read from a file, scaled to metres and placed."""
from __future__ import annotations

from pathlib import Path

import trimesh

from multibody.shapes.base import Key, rotated_and_moved

#: The name a case gives (``kind = "mesh"``).
NAME = "mesh"
#: Its keys in a case's ``shapes`` table.
KEYS = (
    Key("file", "file", "Closed triangle mesh (STL, OBJ, PLY...), path relative to the case file, "
                        "in its folder or below."),
    Key("scale", "positive", "Factor taking file units to metres (-).", default=1.0),
    Key("center", "vector3", "Translation of the mesh, target frame (m).", default=(0.0, 0.0, 0.0)),
    Key("rotation_vector", "vector3", "Mesh->target rotation (rad).", default=(0.0, 0.0, 0.0)),
)


def mesh_target_frame(file, scale=1.0, center=(0, 0, 0), rotation_vector=(0, 0, 0)) -> trimesh.Trimesh:
    """The file's mesh, target frame (m).

    Parameters
    ----------
    file : path                   Mesh file (any format trimesh reads), vertices in file units.
    scale : float                 Factor taking file units to metres (-), applied before the rotation.
    center : (3,) float           Translation of the mesh, target frame (m).
    rotation_vector : (3,) float  Mesh->target rotation (rad).
    """
    mesh = trimesh.load_mesh(Path(file), force="mesh")
    mesh.apply_scale(scale)
    return rotated_and_moved(mesh, center, rotation_vector)
