"""Where the joints and weak locations of the target are, in the body frames and at every frame.

A joint is declared in the target frame (``target.joints[].position``, ``.axis``); the target
frame's pose in LVLH at t = 0 is ``target.position_lvlh`` and ``target.attitude_rotation_vector``.
The point is fixed in its parent body, so it is carried into the parent's body frame once, with
the parent's recorded pose at the first sample, and then moved with the parent's pose:

.. math:: r_{lvlh}(t) = R_{parent}(t)\\, R_{parent}(0)^T (T_0 r_{target} + c_0 - c_{parent}(0)) + c_{parent}(t)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation


@dataclass(frozen=True)
class JointMarkers:
    """Joints fixed in their parent bodies.

    Attributes
    ----------
    names : list of str
    parent : (nj,) int
        Index of the parent body (order of ``body_names``).
    point_parent : (nj, 3) float
        Joint point (m), parent body frame.
    axis_parent : (nj, 3) float
        Unit joint axis h2, parent body frame.
    """

    names: list
    parent: np.ndarray
    point_parent: np.ndarray
    axis_parent: np.ndarray

    def at(self, body_to_lvlh, body_com_lvlh):
        """Points (m) and axes (-) in LVLH for body poses (nb, 3, 3) and CoMs (nb, 3) of one sample.

        Parameters
        ----------
        body_to_lvlh : (nb, 3, 3) float
            Rotations body frame -> LVLH of every body at the sample.
        body_com_lvlh : (nb, 3) float
            Body CoMs (m), LVLH.

        Returns
        -------
        points : (nj, 3) float
            Joint points (m), LVLH.
        axes : (nj, 3) float
            Unit joint axes h2, LVLH.
        """
        rot = np.asarray(body_to_lvlh)[self.parent]
        points = np.einsum("jab,jb->ja", rot, self.point_parent) + np.asarray(body_com_lvlh)[self.parent]
        return points, np.einsum("jab,jb->ja", rot, self.axis_parent)


def joint_markers(case: dict, body_names, body_to_lvlh_0, body_com_lvlh_0) -> JointMarkers:
    """The case's joints in their parent body frames, from the poses (nb, 3, 3), (nb, 3) of the first sample.

    Parameters
    ----------
    case : dict
        The validated case (``case.json``): ``target.joints`` (``name``, ``parent``, ``position`` (m)
        and ``axis`` in the target frame), ``target.position_lvlh`` (m) and
        ``target.attitude_rotation_vector`` (rad, target frame -> LVLH at t = 0).
    body_names : sequence of str
        Body names in the order of the series; joints whose parent is not among them are left out.
    body_to_lvlh_0 : (nb, 3, 3) float
        Rotations body frame -> LVLH at the first sample.
    body_com_lvlh_0 : (nb, 3) float
        Body CoMs (m), LVLH, at the first sample.
    """
    target = case["target"]
    target_to_lvlh = Rotation.from_rotvec(target["attitude_rotation_vector"]).as_matrix()
    origin = np.asarray(target["position_lvlh"], float)
    index = {name: k for k, name in enumerate(body_names)}
    joints = [j for j in target.get("joints", []) if j["parent"] in index]
    parent = np.array([index[j["parent"]] for j in joints], np.int64)
    if not joints:
        return JointMarkers([], parent, np.zeros((0, 3)), np.zeros((0, 3)))
    rot0 = np.asarray(body_to_lvlh_0)[parent]
    points_lvlh = np.array([j["position"] for j in joints], float) @ target_to_lvlh.T + origin
    point_parent = np.einsum("jba,jb->ja", rot0, points_lvlh - np.asarray(body_com_lvlh_0)[parent])
    axes = np.array([j["axis"] for j in joints], float)
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    axis_parent = np.einsum("jba,jb->ja", rot0, axes @ target_to_lvlh.T)
    return JointMarkers([j["name"] for j in joints], parent, point_parent, axis_parent)
