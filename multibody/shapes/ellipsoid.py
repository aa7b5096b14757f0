"""Contact shape ``ellipsoid``: a unit icosphere scaled along its own axes, turned into the target frame."""
from __future__ import annotations

import numpy as np
import trimesh

from multibody.shapes.base import Key, rotated_and_moved

#: The name a case gives (``kind = "ellipsoid"``).
NAME = "ellipsoid"
#: Its keys in a case's ``shapes`` table.
KEYS = (
    Key("semi_axes", "positive_vector3", "Semi-axes along the ellipsoid's own x, y, z (m)."),
    Key("center", "vector3", "Centre, target frame (m)."),
    Key("rotation_vector", "vector3", "Ellipsoid->target rotation (rad).", default=(0.0, 0.0, 0.0)),
)


def mesh_target_frame(semi_axes, center=(0, 0, 0), rotation_vector=(0, 0, 0), subdivisions=3) -> trimesh.Trimesh:
    """The ellipsoid's mesh, vertices on the ellipsoid, target frame (m).

    Parameters
    ----------
    semi_axes : (3,) float        Semi-axes along the ellipsoid's own x, y, z (m).
    center : (3,) float           Centre, target frame (m).
    rotation_vector : (3,) float  Ellipsoid->target rotation (rad).
    subdivisions : int            Icosphere refinement (3: 1280 triangles; not a case key).
    """
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    mesh.apply_scale(np.asarray(semi_axes, float))
    return rotated_and_moved(mesh, center, rotation_vector)
