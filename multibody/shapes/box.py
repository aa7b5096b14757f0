"""Contact shape ``box``: a rectangular box, edges along its own axes, turned into the target frame."""
from __future__ import annotations

import trimesh

from multibody.shapes.base import Key, rotated_and_moved

#: The name a case gives (``kind = "box"``).
NAME = "box"
#: Its keys in a case's ``shapes`` table.
KEYS = (
    Key("size", "positive_vector3", "Edge lengths (m)."),
    Key("center", "vector3", "Centre, target frame (m)."),
    Key("rotation_vector", "vector3", "Box->target rotation (rad).", default=(0.0, 0.0, 0.0)),
)


def mesh_target_frame(size, center=(0, 0, 0), rotation_vector=(0, 0, 0)) -> trimesh.Trimesh:
    """The box's 12-triangle mesh, target frame (m).

    Parameters
    ----------
    size : (3,) float             Edge lengths along the box's own x, y, z (m).
    center : (3,) float           Box centre, target frame (m).
    rotation_vector : (3,) float  Box->target rotation (rad).
    """
    return rotated_and_moved(trimesh.creation.box(extents=size), center, rotation_vector)
