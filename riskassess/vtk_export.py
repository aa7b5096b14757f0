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
``impact.pvd``              the collection: open it in ParaView and press play
``bodies.json``             body index -> name, mass, released piece
==========================  ==================================================================

One frame per net snapshot (the case's ``net_output_rate``). Body poses come from the time
series sample nearest to the snapshot (at most half an output interval away; the same time
when the output rate is a multiple of the net output rate, as in the shipped cases).

The export goes only into a new or empty folder, or, with ``overwrite``, into a VTK folder this
tool made earlier for the same run (its ``manifest.json``, format ``riskassess-vtk``, names the
run and lists the files); the run folder itself or any folder holding other files is refused
(:class:`riskassess.outfolder.OutputRefused`). It is written into a hidden staging folder beside
``out`` and moved in at the end, so an interrupted export leaves the previous export intact; of
a replaced export only the files its manifest lists are removed.
"""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from multibody.net import thread_tension_strain
from riskassess import outfolder
from riskassess.results import MissingData, RunFolder, atomic_write_bytes, write_manifest

#: Format of the manifest that marks a folder as a VTK export of one run.
VTK_FORMAT = "riskassess-vtk"


@dataclass
class VtkExport:
    folder: Path
    pvd: Path
    n_frames: int
    times: np.ndarray


def surface_lvlh(vertices_body, body_to_lvlh, com_lvlh):
    """Vertices (m) of a body surface in LVLH: r = R r_body + c. (n, 3) in, (n, 3) out."""
    return np.asarray(vertices_body) @ np.asarray(body_to_lvlh).T + com_lvlh


def surface_velocity_lvlh(vertices_body, body_to_lvlh, velocity_lvlh, omega_body):
    """Velocity (m/s, LVLH) of body-fixed points: v = v_c + R (omega_body x r_body)."""
    return np.cross(omega_body, np.asarray(vertices_body)) @ np.asarray(body_to_lvlh).T + velocity_lvlh


def nearest_samples(sample_times, wanted_times) -> np.ndarray:
    """Index of the sample nearest to each wanted time."""
    idx = np.clip(np.searchsorted(sample_times, wanted_times), 1, len(sample_times) - 1)
    earlier = np.abs(wanted_times - sample_times[idx - 1]) <= np.abs(sample_times[idx] - wanted_times)
    return np.where(earlier, idx - 1, idx)


def release_times_by_body(run: RunFolder, body_names) -> np.ndarray:
    """Per body the time (s) its piece is released; inf for bodies never released."""
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

    def net_mesh(self, f: int) -> meshio.Mesh:
        x, v = self.net["positions_lvlh"][f], self.net["velocities_lvlh"][f]
        tension, strain = thread_tension_strain(x, v, self.net["threads"], self.net["rest_lengths"],
                                                self.net["stiffness"], self.net["damping"])
        return meshio.Mesh(x, [("line", self.net["threads"])],
                           point_data={"velocity_lvlh_m_s": v, "speed_m_s": np.linalg.norm(v, axis=1)},
                           cell_data={"tension_N": [tension], "strain": [strain],
                                      "bullet_tether": [self.bullet_tether]})

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


def pvd_text(entries: list[tuple[float, int, str, str]], comment: str = "") -> str:
    """ParaView collection: (time s, part, name, file) per dataset."""
    lines = ['<?xml version="1.0"?>', f"<!-- {comment} -->" if comment else "",
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">', "  <Collection>"]
    lines += [f'    <DataSet timestep="{t:.9g}" part="{part}" name={quoteattr(name)} file={quoteattr(file)}/>'
              for t, part, name, file in entries]
    lines += ["  </Collection>", "</VTKFile>", ""]
    return "\n".join(line for line in lines if line)


def write_collection(out: Path, frames, n_frames: int, pvd_name: str, comment: str, identity: dict,
                     progress=None, extra=None, overwrite: bool = False) -> None:
    """Write ``frames``, an iterable of (time (s), ((part name, meshio.Mesh), ...)) per frame, as
    ``<part>_NNNN.vtu`` files and the ParaView collection ``pvd_name`` into ``out``, with a manifest
    ``identity`` (format, case, command, run) plus the files. ``out`` is checked first
    (:func:`riskassess.outfolder.check`: new, empty, or this run's earlier export with ``overwrite``);
    the files are staged beside it and moved in at the end, so an interrupted export leaves the
    previous one intact; ``extra(staging)`` may add files before the collection is written."""
    old = outfolder.check(out, identity, overwrite)
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.partial-"))
    try:
        entries = []
        for n, (t, parts) in enumerate(frames):
            for part, (name, mesh) in enumerate(parts):
                file = f"{name}_{n:04d}.vtu"
                meshio.write(staging / file, mesh, file_format="vtu", binary=True, compression="zlib")
                entries.append((t, part, name, file))
            if progress:
                progress(n + 1, n_frames)
        if extra:
            extra(staging)
        atomic_write_bytes(staging / pvd_name, pvd_text(entries, comment).encode())
        write_manifest(staging, {**identity, "version": 1, "status": "complete",
                                 "files": sorted(p.name for p in staging.iterdir())})
        _move_in(staging, out, old)
    except BaseException:
        _remove_staging(staging)
        raise


def _move_in(staging: Path, out: Path, old: dict | None) -> None:
    """Put the staged export at ``out``: renamed there when ``out`` does not exist; file by file
    into an empty ``out`` (the user's folder stays); swapped with this run's earlier export
    (``old``, its manifest), of which only the listed files are then removed."""
    staging.chmod(0o755)
    if not out.exists():
        staging.rename(out)
    elif old is None:                      # an empty folder, checked just before
        names = sorted(p.name for p in staging.iterdir())
        for name in sorted(names, key=lambda n: n == outfolder.MANIFEST):   # the manifest last
            os.replace(staging / name, out / name)
        staging.rmdir()
    else:
        previous = out.with_name(f".{out.name}.old-{staging.name.rsplit('-', 1)[-1]}")
        out.rename(previous)
        staging.rename(out)
        outfolder.remove_own(previous, old)
        with contextlib.suppress(OSError):   # something else appeared in it meanwhile: it stays
            previous.rmdir()


def _remove_staging(staging: Path) -> None:
    """Remove the staging folder this export made (its files only, never a tree walk)."""
    for path in staging.iterdir():
        path.unlink(missing_ok=True)
    staging.rmdir()


def export_frames(run_dir: str | Path, out: str | Path | None, every: int, progress, frames_type, parts: tuple,
                  pvd_name: str, comment: str, extra=None, overwrite: bool = False) -> VtkExport:
    """The front shared by the impact and the tow export: checks ``every``, reads the run folder into
    ``frames_type(run)`` (which raises MissingData before anything is written), writes every ``every``-th
    net snapshot's ``parts`` (each the ``<part>_mesh(f)`` of the frames) with :func:`write_collection`
    into ``out`` (default ``RUN_DIR/vtk``; a folder directly inside the run folder is registered as a
    product of the run) and returns where and how many. ``extra(frames, staging)`` may add files."""
    if every < 1:
        raise ValueError(f"every must be >= 1 (frames to step); got {every}")
    run = RunFolder(run_dir)
    out = Path(out) if out else run.path / "vtk"
    identity = {"format": VTK_FORMAT, "case": run.manifest.get("case"), "command": "export-vtk",
                "run": str(run.path.resolve())}
    outfolder.check(out, identity, overwrite)   # refuse before reading the run's arrays
    frames = frames_type(run)
    picked = np.arange(0, len(frames.net["time"]), every)
    write_collection(out, ((float(frames.net["time"][f]), tuple((part, getattr(frames, f"{part}_mesh")(f)) for part in parts))
                           for f in picked), len(picked), pvd_name, f"case {run.manifest.get('case')}: {comment}", identity,
                     progress, None if extra is None else lambda staging: extra(frames, staging), overwrite)
    if out.resolve().parent == run.path.resolve():
        run.add_product(out.name)
    return VtkExport(out, out / pvd_name, len(picked), frames.net["time"][picked])


def _write_bodies_json(frames: _Frames, staging: Path) -> None:
    """``bodies.json``: body index -> name, mass (kg), release time of its piece (s, null if never)."""
    bodies = [{"index": k, "name": name, "mass_kg": float(m), "released_at_s": None if np.isinf(r) else float(r)}
              for k, (name, m, r) in enumerate(zip(frames.body_names, frames.series["body_masses"],
                                                   frames.released_from))]
    (staging / "bodies.json").write_text(json.dumps(bodies, indent=2) + "\n")


def export_vtk(run_dir: str | Path, out: str | Path | None = None, every: int = 1, progress=None,
               overwrite: bool = False) -> VtkExport:
    """Write the VTK files of a run folder (see the module docstring); returns where and how many."""
    if RunFolder(run_dir).stage == "tow":  # a full-net tow folder: its own layout
        from riskassess.tow_vtk import export_tow_vtk

        return export_tow_vtk(run_dir, out, every, progress, overwrite)
    return export_frames(run_dir, out, every, progress, _Frames, ("net", "bodies", "bullets"), "impact.pvd",
                         "positions LVLH (m); body_index -> bodies.json", _write_bodies_json, overwrite)
