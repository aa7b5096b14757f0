"""VTK export of a full-net tow folder (``riskassess export-vtk RUN_DIR`` on a ``riskassess tow`` run
with ``simulation.model = "full-net"``), in the layout of :mod:`riskassess.products.vtk_export`, written by :mod:`riskassess.products.vtk_frames`.

Written into ``RUN_DIR/vtk/``; all positions in the debris' LVLH frame at each frame's time (origin
at the debris CoM; axes radial, along-track, orbit normal of the debris' inertial position and
velocity), m:

==========================  ==================================================================
file                        content
==========================  ==================================================================
``net_NNNN.vtu``            net nodes (corner masses included) and threads (closing loop last)
                            as line cells; cell data ``strain`` (negative: slack),
                            ``elastic_tension_N`` (max(k (l - l_0), 0): net.npz holds positions
                            only, so the damping part is left out), ``closing_loop`` (0/1)
``bodies_NNNN.vtu``         chaser cube and debris cylinder at their poses; cell data ``body_index``
                            (0 chaser, 1 debris)
``tether_NNNN.vtu``         the main tether: one line from the central node to the chaser's
                            attachment point; cell data ``tension_N``
``towing.pvd``              the collection: open it in ParaView and press play
==========================  ==================================================================

One frame per net snapshot (``full_net.net_output_interval``); body poses and the tether tension
from the nearest sample of ``towing.npz``.
"""
from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import trimesh

from multibody.orbit import lvlh_to_eci
from multibody.net import thread_tension_strain
from riskassess.cases.impact import load_model
from riskassess.products.results import MissingData, RunFolder
from riskassess.models.towing_fullnet import debris_geometry
from riskassess.cases.towing import TowingCase
from riskassess.products.vtk_frames import VtkExport, export_frames, nearest_samples, surface_lvlh


def body_meshes(case) -> list[trimesh.Trimesh]:
    """Chaser cube (side L_C) and debris cylinder (d_D, L_D, axis z_body, centre at the
    :func:`riskassess.models.towing_fullnet.debris_geometry` offset) in their body frames (m).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The towing case (``chaser.side_length``, ``debris.diameter``, ``debris.length`` (m), the
        sub-tether attachment points).

    Returns
    -------
    list of trimesh.Trimesh
        [chaser, debris], vertices (m) in the body frames.
    """
    radius, half_length, z_centre = debris_geometry(case)
    cylinder = trimesh.creation.cylinder(radius=radius, height=2.0 * half_length, sections=48)
    cylinder.apply_translation([0.0, 0.0, z_centre])
    return [trimesh.creation.box(extents=[case.chaser.side_length] * 3), cylinder]


class _TowFrames:
    """The tow folder's data per frame, checked once up front."""

    def __init__(self, run: RunFolder):
        for name in ("net.npz", "towing.npz", "case.toml"):
            if not run.has(name):
                raise MissingData(f"{run.path / name}: missing; VTK export of a tow folder needs a full-net run")
        self.case = load_model(run.path / "case.toml", TowingCase)
        self.net, self.series = run.arrays("net.npz"), run.arrays("towing.npz")
        for key in ("rest_lengths", "stiffness", "closing_threads"):
            if key not in self.net:
                raise MissingData(f"{run.path / 'net.npz'}: no '{key}' (written by an older version; re-run the tow)")
        self.sample = nearest_samples(self.series["time"], self.net["time"])
        self.meshes = body_meshes(self.case)
        self.closing = np.zeros(len(self.net["threads"]), np.uint8)
        self.closing[len(self.net["threads"]) - int(self.net["closing_threads"]):] = 1

    def lvlh(self, f: int):
        """(inertial -> LVLH rotation (3, 3), debris CoM (3,) inertial) at frame ``f``."""
        i = self.sample[f]
        com = self.series["debris_com_inertial"][i]
        return lvlh_to_eci(com, self.series["debris_velocity_inertial"][i]).T, com

    def net_mesh(self, f: int) -> meshio.Mesh:
        to_lvlh, com = self.lvlh(f)
        x = self.net["nodes_inertial"][f]
        tension, strain = thread_tension_strain(x, np.zeros_like(x), self.net["threads"], self.net["rest_lengths"],
                                                self.net["stiffness"], np.zeros(len(self.net["threads"])))
        return meshio.Mesh((x - com) @ to_lvlh.T, [("line", self.net["threads"])],
                           cell_data={"strain": [strain], "elastic_tension_N": [tension], "closing_loop": [self.closing]})

    def bodies_mesh(self, f: int) -> meshio.Mesh:
        to_lvlh, com = self.lvlh(f)
        s, i = self.series, self.sample[f]
        points, triangles, index, offset = [], [], [], 0
        for k, (mesh, body) in enumerate(zip(self.meshes, ("chaser", "debris"))):
            points.append(surface_lvlh(mesh.vertices, to_lvlh @ s[f"{body}_to_inertial"][i],
                                       to_lvlh @ (s[f"{body}_com_inertial"][i] - com)))
            triangles.append(mesh.faces + offset)
            offset += len(mesh.vertices)
            index.append(np.full(len(mesh.faces), k, np.int32))
        return meshio.Mesh(np.vstack(points), [("triangle", np.vstack(triangles))],
                           cell_data={"body_index": [np.concatenate(index)]})

    def tether_mesh(self, f: int) -> meshio.Mesh:
        to_lvlh, com = self.lvlh(f)
        s, i = self.series, self.sample[f]
        attach = s["chaser_com_inertial"][i] + s["chaser_to_inertial"][i] @ np.asarray(
            self.case.chaser.tether_attachment_body, float)
        ends = np.array([s["connection_point_inertial"][i], attach])
        return meshio.Mesh((ends - com) @ to_lvlh.T, [("line", np.array([[0, 1]]))],
                           cell_data={"tension_N": [np.array([s["main_tether_tension"][i]])]})


def export_tow_vtk(run_dir: str | Path, out: str | Path | None = None, every: int | None = None, progress=None,
                   overwrite: bool = False, max_frames: int | None = None) -> VtkExport:
    """Write the VTK files of a full-net tow folder (module docstring); returns where and how many
    (``every``, ``max_frames``: :func:`riskassess.products.vtk_frames.frame_stride`).

    Parameters
    ----------
    run_dir : str or Path
        A full-net ``riskassess tow`` output folder (``net.npz``, ``towing.npz``, ``case.toml``).
    out : str or Path, optional
        The export folder; default ``RUN_DIR/vtk``.
    every : int, optional
        Net snapshots to step, >= 1.
    progress : callable, optional
        ``progress(frames written, frames to write)``.
    overwrite : bool
        Replace an earlier export of the same run.
    max_frames : int, optional
        Most frames to write.

    Returns
    -------
    VtkExport
        Export folder, ``.pvd`` path, number of frames and their times (s).
    """
    return export_frames(run_dir, out, every, progress, _TowFrames, ("net", "bodies", "tether"), "towing.pvd",
                         "positions in the debris' LVLH frame (m)", overwrite=overwrite, max_frames=max_frames)
