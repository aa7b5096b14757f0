"""The real target of a perception case when it differs from its drawings (``[perception.truth_damage]``).

The case's ``[target]`` is the model the tracker is given (``perception.model = 'known'``). A real
derelict never matches its drawings: an array may be bent, an antenna lost, the CoM moved. This
module makes the *real* target from the model and the stated damage; the LiDAR scans it and the
collision run simulates it, while the tracker keeps the model.

Mass properties of the real body (the model's stated mass, CoM and inertia are the start):

- the stated mass is spread at one uniform density over the shapes' volumes (shapes of one body
  disjoint, as :func:`multibody.geometry.uniform_density_inertia` assumes);
- a missing shape takes its mass, first moment and inertia away;
- a bent shape keeps its mass; its first moment and inertia move with it;
- ``center_of_mass_shift`` then moves the CoM (mass moved inside the body, e.g. propellant), the
  inertia about the CoM kept.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.geometry import geometric_center_of_mass, uniform_density_inertia
from riskassess.cases.target_geometry import body_meshes_target_frame


def hinge_turn(shape, hinge_point, hinge_axis, angle):
    """A case shape turned by ``angle`` (rad) about the line through ``hinge_point`` (m, target
    frame) along ``hinge_axis`` (target frame): its centre moved, its own rotation (or axis) turned.

    Parameters
    ----------
    shape : pydantic model
        One entry of ``target.bodies[].shapes`` (keys ``center`` and ``rotation_vector`` or ``axis``).
    hinge_point : (3,) float
        A point of the hinge line, target frame (m).
    hinge_axis : (3,) float
        Hinge direction, target frame (-); any non-zero length.
    angle : float
        Right-handed turn about ``hinge_axis`` (rad).

    Returns
    -------
    pydantic model
        A copy of ``shape`` in its bent place.
    """
    axis = np.asarray(hinge_axis, float) / np.linalg.norm(hinge_axis)
    turn = Rotation.from_rotvec(angle * axis)
    point = np.asarray(hinge_point, float)
    update = {"center": (point + turn.apply(np.asarray(shape.center, float) - point)).tolist()}
    if "rotation_vector" in type(shape).model_fields:
        update["rotation_vector"] = (turn * Rotation.from_rotvec(shape.rotation_vector)).as_rotvec().tolist()
    if "axis" in type(shape).model_fields:
        update["axis"] = turn.apply(np.asarray(shape.axis, float)).tolist()
    return shape.model_copy(update=update)


def _parallel_axis_term(mass, com):
    """m (|c|^2 E - c c^T) (kg m^2): what a body of ``mass`` (kg) with its CoM at ``com`` (m, target
    frame) adds to its inertia about its CoM to give the inertia about the target origin."""
    com = np.asarray(com, float)
    return mass * (com @ com * np.eye(3) - np.outer(com, com))


def _shape_part(mesh, density):
    """Mass (kg), first moment (kg m) and inertia about the target origin (kg m^2) of one shape."""
    mass = density * mesh.volume
    own = uniform_density_inertia([mesh], mass, mesh.center_mass)
    return mass, mass * np.asarray(mesh.center_mass), own + _parallel_axis_term(mass, mesh.center_mass)


def damaged_case(case, base: Path):
    """The real target's case: ``case`` with ``perception.truth_damage`` applied to target body 0
    (shapes and mass properties, module docstring); ``case`` itself when it states no damage.

    Parameters
    ----------
    case : Case
        A perception case (one target body; its shape indices checked by the case loader).
    base : Path
        Folder of the case file (mesh files are relative to it).

    Returns
    -------
    Case
        The case of the real target (mass in kg, CoM in m and inertia in kg m^2, target frame); its
        ``truth_damage`` is kept, so the stage can say what was changed.
    """
    damage = case.perception.truth_damage if case.perception is not None else None
    if damage is None:
        return case
    body = case.target.bodies[0]
    meshes = body_meshes_target_frame(case, base)[0]
    com = np.asarray(body.center_of_mass if body.center_of_mass is not None else geometric_center_of_mass(meshes))
    inertia = np.asarray(body.inertia) if body.inertia is not None else uniform_density_inertia(meshes, body.mass, com)
    density = body.mass / sum(m.volume for m in meshes)
    mass, first, about_origin = body.mass, body.mass * com, inertia + _parallel_axis_term(body.mass, com)
    shapes = list(body.shapes)
    bent = {}
    for bend in damage.bends:
        bent[bend.shape] = hinge_turn(shapes[bend.shape], bend.hinge_point, bend.hinge_axis, bend.angle)
    new_meshes = body_meshes_target_frame(case.model_copy(update={"target": case.target.model_copy(update={
        "bodies": [body.model_copy(update={"shapes": [bent.get(k, s) for k, s in enumerate(shapes)]})]})}), base)[0]
    for index in [*damage.missing_shapes, *bent]:
        part_mass, part_first, part_inertia = _shape_part(meshes[index], density)
        mass, first, about_origin = mass - part_mass, first - part_first, about_origin - part_inertia
    for index in bent:
        part_mass, part_first, part_inertia = _shape_part(new_meshes[index], density)
        mass, first, about_origin = mass + part_mass, first + part_first, about_origin + part_inertia
    com = first / mass
    inertia = about_origin - _parallel_axis_term(mass, com)
    inertia = 0.5 * (inertia + inertia.T)
    com = com + np.asarray(damage.center_of_mass_shift, float)
    kept = [bent.get(k, s) for k, s in enumerate(shapes) if k not in damage.missing_shapes]
    real = body.model_copy(update={"mass": float(mass), "center_of_mass": com.tolist(),
                                   "inertia": inertia.tolist(), "shapes": kept, "mass_properties_from": None})
    return case.model_copy(update={"target": case.target.model_copy(update={"bodies": [real]})})
