"""The target's geometry at t = 0, read from the ``target`` table of a net-impact case
(:class:`~riskassess.cases.impact.Case`): its shapes as meshes in the target frame and its pose in LVLH.

Shared by the case loader's reach check (:func:`riskassess.cases.impact.validate_case`) and the model
builder (:mod:`riskassess.models.impact`); it reads the case's fields only, so it sits below both.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.geometry import shape_mesh
from multibody.shapes import SHAPES


def body_meshes_target_frame(case, base: Path):
    """Per body, its shapes as trimesh meshes in the target frame (m).

    Parameters
    ----------
    case : Case
        A net-impact case (its ``target.bodies``).
    base : Path
        Folder of the case file; mesh files are relative to it.

    Returns
    -------
    list of list of trimesh.Trimesh
        One list per body, one mesh per shape, vertices in the target frame (m).
    """
    meshes = []
    for body in case.target.bodies:
        meshes.append([shape_mesh(**_shape_kwargs(s, base)) for s in body.shapes])
    return meshes


def _shape_kwargs(shape, base: Path) -> dict:
    """The keys of a case shape for :func:`multibody.geometry.shape_mesh`; files relative to ``base``."""
    kwargs = shape.model_dump()
    for key in SHAPES[shape.kind].KEYS:
        if key.value == "file":
            kwargs[key.name] = base / kwargs[key.name]
    return kwargs


def target_pose_lvlh(case):
    """Target-frame origin (m) and target->LVLH rotation matrix at t = 0.

    Parameters
    ----------
    case : Case
        A net-impact case (``target.position_lvlh`` in m, ``target.attitude_rotation_vector`` in rad).

    Returns
    -------
    origin_lvlh : (3,) float
        Target-frame origin, LVLH (m).
    target_to_lvlh : (3, 3) float
        Rotation matrix; its columns are the target axes in LVLH.
    """
    rot = Rotation.from_rotvec(case.target.attitude_rotation_vector).as_matrix()
    return np.asarray(case.target.position_lvlh, float), rot


def target_points_lvlh(case, points_target) -> np.ndarray:
    """Points given in the target frame ((3,) or (k, 3), m) at t = 0, in LVLH (m).

    Parameters
    ----------
    case : Case
        A net-impact case (the target's pose).
    points_target : (3,) or (k, 3) float
        Points, target frame (m).

    Returns
    -------
    (3,) or (k, 3) float
        The same points, LVLH (m).
    """
    origin, rot = target_pose_lvlh(case)
    return origin + np.asarray(points_target, float) @ rot.T


def target_vertices_lvlh(case, base: Path = Path(".")) -> np.ndarray:
    """Vertices of every target shape at t = 0, LVLH (m).

    Parameters
    ----------
    case : Case
        A net-impact case.
    base : Path
        Folder of the case file; mesh files are relative to it.

    Returns
    -------
    (k, 3) float
        All vertices of all shapes of all bodies, LVLH (m).
    """
    return target_points_lvlh(case, np.vstack([m.vertices for body in body_meshes_target_frame(case, base)
                                                for m in body]))
