"""VTK export of a run folder for ParaView: ``riskassess export-vtk RUN_DIR``.

Written into ``RUN_DIR/vtk/`` (all positions in the LVLH frame, m):

==========================  ==================================================================
file                        content
==========================  ==================================================================
``net_NNNN.vtu``            net nodes (bullets included, last) and threads as line cells;
                            point data ``velocity_lvlh_m_s``, ``speed_m_s``; cell data
                            ``tension_N``, ``strain`` (negative: slack), ``bullet_tether`` (0/1)
``bodies_NNNN.vtu``         every debris body's surface (triangles) at its pose; point data
                            ``velocity_lvlh_m_s``; cell data ``body_index`` (order of
                            ``bodies.json``), ``released`` (1 once the body's piece is released)
``bullets_NNNN.vtu``        the bullets as vertex cells; point data ``velocity_lvlh_m_s``,
                            ``radius_m`` (for sphere glyphs)
``body_frames_NNNN.vtu``    per body its CoM (vertex) and its body axes x, y, z (lines from the
                            CoM, half the body's size long); point data
                            ``contact_force_lvlh_N``, ``contact_moment_lvlh_Nm`` (about the
                            CoM; on the CoM point, zero on the axis ends), ``body_index``; cell
                            data ``axis`` (-1 CoM, 0/1/2 x/y/z)
``joints_NNNN.vtu``         every joint at its point (vertex), moving with its parent body;
                            point data ``axis_lvlh`` (h2), ``joint_index`` (order of
                            ``joints.json``), ``released`` (0/1), ``weak_location`` (0/1: a
                            weak location is declared there), ``fails`` (0/1: it fails)
``frame_NNNN.vtm``          the frame's parts as one multiblock with named blocks (net,
                            bodies, bullets, body_frames, joints)
``impact.pvd``              the collection of the frames: open it in ParaView and press play
``bodies.json``             body index -> name, mass, released piece
``joints.json``             joint index -> name, parent, weak locations there
==========================  ==================================================================

One frame per kept net snapshot (the case's ``net_output_rate``): every ``every``-th one, or, by
default, evenly strided so that the export stays within ``max_frames`` frames, or within
:data:`~riskassess.products.vtk_frames.VTK_BUDGET_BYTES` when neither is given (the size of the middle
snapshot sets the stride).
Body poses come from the time series sample nearest to the snapshot (at most half an output
interval away; the same time when the output rate is a multiple of the net output rate, as in
the shipped cases). Net point data ``contact_force_lvlh_N`` (N) is the contact force on each node,
averaged since the previous snapshot (run folders of older versions have none).

The export goes only into a new or empty folder, or, with ``overwrite``, into a VTK folder this
tool made earlier for the same run (its ``manifest.json``, format ``riskassess-vtk``, names the
run and lists the files); the run folder itself or any folder holding other files is refused
(:class:`riskassess.products.outfolder.OutputRefused`). It is written into a hidden staging folder beside
``out`` and moved in at the end, so an interrupted export leaves the previous export intact; of
a replaced export only the files its manifest lists are removed. The writer is
:mod:`riskassess.products.vtk_frames`; a full-net tow folder is exported by :mod:`riskassess.products.tow_vtk`.
"""
from __future__ import annotations

import json
from pathlib import Path

import meshio
import numpy as np

from multibody.net import thread_tension_strain
from riskassess.products.results import MissingData, RunFolder
from riskassess.products.vtk_frames import VtkExport, export_frames, nearest_samples, surface_lvlh, surface_velocity_lvlh
from riskassess.products.vtk_markers import joint_markers

def release_times_by_body(run: RunFolder, body_names) -> np.ndarray:
    """Per body the time (s) its piece is released; inf for bodies never released.

    Parameters
    ----------
    run : RunFolder
        The run folder (its ``structures.json``, when there, gives the released pieces).
    body_names : sequence of str
        Body names in the order of the series.

    Returns
    -------
    (nb,) float
        Release times (s).
    """
    times = np.full(len(body_names), np.inf)
    if run.has("structures.json"):
        index = {name: k for k, name in enumerate(body_names)}
        for piece in run.structures["released_pieces"]:
            for body in piece["bodies"]:
                times[index[body]] = min(times[index[body]], piece["release_time_s"])
    return times


class _Frames:
    """The run's data needed per frame, checked once up front."""

    def __init__(self, run: RunFolder):
        self.net, self.series, meshes = run.net, run.timeseries, run.bodies
        self.body_names = [str(n) for n in self.series["body_names"]]
        self.meshes = []
        for k in range(len(self.body_names)):
            if f"vertices_{k}" not in meshes:
                raise MissingData(f"{run.path / 'bodies.npz'}: no mesh of body {k} ({self.body_names[k]})")
            self.meshes.append((meshes[f"vertices_{k}"], meshes[f"faces_{k}"]))
        self.sample = nearest_samples(self.series["time"], self.net["time"])
        self.released_from = release_times_by_body(run, self.body_names)
        n_nodes = len(self.net["masses"])
        self.n_bullets = int(self.net["n_bullets"])
        self.bullet_tether = (self.net["threads"] >= n_nodes - self.n_bullets).any(axis=1).astype(np.uint8)
        self.joints = joint_markers(run.case, self.body_names, self.series["body_to_lvlh"][0],
                                    self.series["body_com_lvlh"][0])
        self.axis_length = np.array([0.5 * np.ptp(v, axis=0).max() for v, _ in self.meshes])
        self.joint_released = np.full(len(self.joints.names), np.inf)
        self.weak = {}   # joint name -> [(location name, fails)]
        if run.has("structures.json"):
            for loc in run.structures["locations"]:
                self.weak.setdefault(loc["joint"], []).append((loc["name"], bool(loc["fails"])))
            for piece in run.structures["released_pieces"]:
                if piece["joint"] in self.joints.names:
                    k = self.joints.names.index(piece["joint"])
                    self.joint_released[k] = min(self.joint_released[k], piece["release_time_s"])

    def net_mesh(self, f: int) -> meshio.Mesh:
        x, v = self.net["positions_lvlh"][f], self.net["velocities_lvlh"][f]
        tension, strain = thread_tension_strain(x, v, self.net["threads"], self.net["rest_lengths"],
                                                self.net["stiffness"], self.net["damping"])
        return meshio.Mesh(x, [("line", self.net["threads"])],
                           point_data={"velocity_lvlh_m_s": v, "speed_m_s": np.linalg.norm(v, axis=1),
                                       **self._node_contact_force(f)},
                           cell_data={"tension_N": [tension], "strain": [strain],
                                      "bullet_tether": [self.bullet_tether]})

    def _node_contact_force(self, f: int) -> dict:
        if "contact_force_lvlh" not in self.net:   # a run folder of an older version
            return {}
        return {"contact_force_lvlh_N": np.asarray(self.net["contact_force_lvlh"][f], float)}

    def body_frames_mesh(self, f: int) -> meshio.Mesh:
        """Per body 4 points (CoM, then the ends of its x, y, z axes) with the contact loads on the CoM."""
        s, i = self.series, self.sample[f]
        nb = len(self.body_names)
        rot, com = s["body_to_lvlh"][i], s["body_com_lvlh"][i]
        ends = com[:, None, :] + self.axis_length[:, None, None] * np.swapaxes(rot, 1, 2)   # (nb, 3, 3): rows = axes
        points = np.concatenate([com[:, None, :], ends], axis=1).reshape(-1, 3)
        first = 4 * np.arange(nb)
        lines = np.stack([np.repeat(first, 3), (first[:, None] + np.arange(1, 4)).ravel()], axis=1)
        loads = {}
        for key, name in (("contact_force_lvlh", "contact_force_lvlh_N"),
                          ("contact_moment_lvlh", "contact_moment_lvlh_Nm")):
            values = np.zeros((nb, 4, 3))
            values[:, 0] = s[key][i]
            loads[name] = values.reshape(-1, 3)
        return meshio.Mesh(points, [("vertex", first[:, None]), ("line", lines)],
                           point_data={**loads, "body_index": np.repeat(np.arange(nb, dtype=np.int32), 4)},
                           cell_data={"axis": [np.full(nb, -1, np.int8), np.tile(np.arange(3, dtype=np.int8), nb)]})

    def joints_mesh(self, f: int) -> meshio.Mesh:
        """Every joint at its point in LVLH, with its axis, release and weak-location flags."""
        i = self.sample[f]
        points, axes = self.joints.at(self.series["body_to_lvlh"][i], self.series["body_com_lvlh"][i])
        names = self.joints.names
        return meshio.Mesh(points.reshape(-1, 3), [("vertex", np.arange(len(names))[:, None])], point_data={
            "axis_lvlh": axes.reshape(-1, 3), "joint_index": np.arange(len(names), dtype=np.int32),
            "released": (self.net["time"][f] >= self.joint_released).astype(np.uint8),
            "weak_location": np.array([name in self.weak for name in names], np.uint8),
            "fails": np.array([any(fails for _, fails in self.weak.get(name, [])) for name in names], np.uint8)})

    def bullets_mesh(self, f: int) -> meshio.Mesh:
        first = len(self.net["masses"]) - self.n_bullets
        return meshio.Mesh(self.net["positions_lvlh"][f, first:], [("vertex", np.arange(self.n_bullets)[:, None])],
                           point_data={"velocity_lvlh_m_s": self.net["velocities_lvlh"][f, first:],
                                       "radius_m": self.net["radii"][first:]})

    def bodies_mesh(self, f: int) -> meshio.Mesh:
        s, i = self.series, self.sample[f]
        points, velocities, triangles, body_index, released = [], [], [], [], []
        offset = 0
        for k, (vertices, faces) in enumerate(self.meshes):
            rot = s["body_to_lvlh"][i, k]
            points.append(surface_lvlh(vertices, rot, s["body_com_lvlh"][i, k]))
            velocities.append(surface_velocity_lvlh(vertices, rot, s["body_velocity_lvlh"][i, k],
                                                    s["body_omega_body"][i, k]))
            triangles.append(faces + offset)
            offset += len(vertices)
            body_index.append(np.full(len(faces), k, np.int32))
            released.append(np.full(len(faces), int(self.net["time"][f] >= self.released_from[k]), np.uint8))
        return meshio.Mesh(np.vstack(points), [("triangle", np.vstack(triangles))],
                           point_data={"velocity_lvlh_m_s": np.vstack(velocities)},
                           cell_data={"body_index": [np.concatenate(body_index)],
                                      "released": [np.concatenate(released)]})


def _write_bodies_json(frames: _Frames, staging: Path) -> None:
    """``bodies.json``: body index -> name, mass (kg), release time of its piece (s, null if never)."""
    bodies = [{"index": k, "name": name, "mass_kg": float(m), "released_at_s": None if np.isinf(r) else float(r)}
              for k, (name, m, r) in enumerate(zip(frames.body_names, frames.series["body_masses"],
                                                   frames.released_from))]
    (staging / "bodies.json").write_text(json.dumps(bodies, indent=2) + "\n")
    joints = [{"index": k, "name": name, "parent": frames.body_names[frames.joints.parent[k]],
               "weak_locations": [{"name": loc, "fails": fails} for loc, fails in frames.weak.get(name, [])],
               "released_at_s": None if np.isinf(frames.joint_released[k]) else float(frames.joint_released[k])}
              for k, name in enumerate(frames.joints.names)]
    (staging / "joints.json").write_text(json.dumps(joints, indent=2) + "\n")


def export_vtk(run_dir: str | Path, out: str | Path | None = None, every: int | None = None, progress=None,
               overwrite: bool = False, max_frames: int | None = None) -> VtkExport:
    """Write the VTK files of a run folder (see the module docstring); returns where and how many.
    ``every``: export every N-th snapshot; ``max_frames``: at most that many, evenly strided; neither:
    within :data:`~riskassess.products.vtk_frames.VTK_BUDGET_BYTES`.

    Parameters
    ----------
    run_dir : str or Path
        The run folder of ``riskassess run`` / ``assess`` (or a full-net ``riskassess tow`` folder).
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
    if RunFolder(run_dir).stage == "tow":  # a full-net tow folder: its own layout
        # imported here: it loads the towing models (and their compiled kernels), which an impact export never needs
        from riskassess.products.tow_vtk import export_tow_vtk
        return export_tow_vtk(run_dir, out, every, progress, overwrite, max_frames)
    return export_frames(run_dir, out, every, progress, _Frames, ("net", "bodies", "bullets", "body_frames", "joints"),
                         "impact.pvd", "positions LVLH (m); body_index -> bodies.json, joint_index -> joints.json",
                         _write_bodies_json, overwrite, max_frames)
