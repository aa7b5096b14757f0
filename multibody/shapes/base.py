"""What every contact shape declares (:mod:`multibody.shapes`): its keys, each with the kind of value
it takes, and the placement shared by the shapes given a pose in the target frame (the debris frame
of a case, in which every shape is placed)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

#: The kinds of value a shape key takes, with what is allowed; the case schema
#: (:mod:`riskassess.cases.impact`) checks each kind.
VALUES = {
    "positive": "a number > 0",
    "positive_vector3": "three numbers > 0",
    "vector3": "three numbers",
    "file": "a mesh file trimesh reads, path relative to the case file",
}


@dataclass(frozen=True)
class Key:
    """One key of a shape's table in a case file.

    Attributes
    ----------
    name : str          The key, also the keyword of the shape's ``mesh_target_frame``.
    value : str         Kind of value, one of :data:`VALUES`.
    description : str   Meaning, with the unit in parentheses, e.g. ``"Edge lengths (m)."``.
    default : tuple, float or None  Value when the key is left out; None: the key is required.
    """

    name: str
    value: str
    description: str
    default: object = None

    def __post_init__(self):
        if self.value not in VALUES:
            raise ValueError(f"shape key {self.name!r}: value kind must be one of {sorted(VALUES)}. "
                             f"Got {self.value!r} instead")


class ContactShape(Protocol):
    """The interface of a contact shape: a module of :mod:`multibody.shapes` (one file each) defines

    Attributes
    ----------
    NAME : str                  The ``kind`` a case's ``shapes`` table gives.
    KEYS : tuple of Key         Its keys, in file order; the case schema (:mod:`riskassess.cases.impact`)
                                is built from them.
    """

    NAME: str
    KEYS: tuple[Key, ...]

    def mesh_target_frame(self, **keys) -> trimesh.Trimesh:
        """The closed triangle mesh of the shape in the target frame (m), taking its ``KEYS`` as keywords.

        Parameters
        ----------
        **keys
            The shape's keys (:attr:`KEYS`), in the units their descriptions give.

        Returns
        -------
        trimesh.Trimesh
            Vertices in the target frame (m).
        """


def rotated_and_moved(mesh: trimesh.Trimesh, center, rotation_vector) -> trimesh.Trimesh:
    """``mesh`` (given in its own frame) turned by the shape->target rotation vector, then its origin
    moved to ``center``: the mesh in the target frame (m). Modifies and returns ``mesh``.

    Parameters
    ----------
    mesh : trimesh.Trimesh       Shape in its own frame (m).
    center : (3,) float          Shape origin, target frame (m).
    rotation_vector : (3,) float Shape->target rotation (rad).
    """
    transform = np.eye(4)
    transform[:3, :3] = Rotation.from_rotvec(rotation_vector).as_matrix()
    mesh.apply_transform(transform)
    mesh.apply_translation(center)
    return mesh
