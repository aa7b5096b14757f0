"""VTK collections of a run folder's frames for ParaView, the writer shared by the impact export
(:mod:`riskassess.products.vtk_export`) and the full-net tow export (:mod:`riskassess.products.tow_vtk`): body
surfaces in LVLH, the sample nearest to a snapshot, the stride that keeps an export within its
budget, and :func:`export_frames`, which writes ``<part>_NNNN.vtu`` files, one ``frame_NNNN.vtm``
per frame and the ``.pvd`` collection through a staging folder, with the export's manifest.
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from riskassess.products import outfolder
from riskassess.products.results import RunFolder, atomic_write_bytes, write_manifest

#: Format of the manifest that marks a folder as a VTK export of one run.
VTK_FORMAT = "riskassess-vtk"
#: Size an export aims to stay within when neither ``every`` nor ``max_frames`` is given (bytes):
#: 20 MB keeps the reference run (1229 nodes, 376 snapshots) at every 3rd snapshot, 0.06 s apart.
VTK_BUDGET_BYTES = 20_000_000


@dataclass
class VtkExport:
    folder: Path
    pvd: Path
    n_frames: int
    times: np.ndarray


def surface_lvlh(vertices_body, body_to_lvlh, com_lvlh):
    """Vertices (m) of a body surface in LVLH: r = R r_body + c. (n, 3) in, (n, 3) out.

    Parameters
    ----------
    vertices_body : (n, 3) float
        Surface vertices r_body (m), body frame, relative to the body CoM.
    body_to_lvlh : (3, 3) float
        Rotation R from body frame to LVLH.
    com_lvlh : (3,) float
        Body CoM c (m), LVLH.

    Returns
    -------
    (n, 3) float
        The vertices (m), LVLH.
    """
    return np.asarray(vertices_body) @ np.asarray(body_to_lvlh).T + com_lvlh


def surface_velocity_lvlh(vertices_body, body_to_lvlh, velocity_lvlh, omega_body):
    """Velocity (m/s, LVLH) of body-fixed points: v = v_c + R (omega_body x r_body).

    Parameters
    ----------
    vertices_body : (n, 3) float
        Body-fixed points r_body (m), body frame, relative to the body CoM.
    body_to_lvlh : (3, 3) float
        Rotation R from body frame to LVLH.
    velocity_lvlh : (3,) float
        CoM velocity v_c (m/s), LVLH.
    omega_body : (3,) float
        Angular velocity (rad/s), body frame.

    Returns
    -------
    (n, 3) float
        Point velocities (m/s), LVLH.
    """
    return np.cross(omega_body, np.asarray(vertices_body)) @ np.asarray(body_to_lvlh).T + velocity_lvlh


def nearest_samples(sample_times, wanted_times) -> np.ndarray:
    """Index of the sample nearest to each wanted time.

    Parameters
    ----------
    sample_times : (k,) float
        Sample times (s), increasing, k >= 2.
    wanted_times : (m,) float
        Times (s) to match.

    Returns
    -------
    (m,) int
        Indices into ``sample_times``.
    """
    idx = np.clip(np.searchsorted(sample_times, wanted_times), 1, len(sample_times) - 1)
    earlier = np.abs(wanted_times - sample_times[idx - 1]) <= np.abs(sample_times[idx] - wanted_times)
    return np.where(earlier, idx - 1, idx)


def pvd_text(entries: list[tuple[float, int, str, str]], comment: str = "") -> str:
    """ParaView collection: (time s, part, name, file) per dataset.

    Parameters
    ----------
    entries : list of (float, int, str, str)
        Per dataset: time (s), part number, name, file path relative to the ``.pvd``.
    comment : str
        XML comment written at the top (e.g. the frame the positions are in).
    """
    lines = ['<?xml version="1.0"?>', f"<!-- {comment} -->" if comment else "",
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">', "  <Collection>"]
    lines += [f'    <DataSet timestep="{t:.9g}" part="{part}" name={quoteattr(name)} file={quoteattr(file)}/>'
              for t, part, name, file in entries]
    lines += ["  </Collection>", "</VTKFile>", ""]
    return "\n".join(line for line in lines if line)


def vtm_text(blocks: list[tuple[str, str]]) -> str:
    """A VTK multiblock file whose blocks are the given (name, file) pairs: ParaView shows the names.

    Parameters
    ----------
    blocks : list of (str, str)
        Per block: name shown in ParaView, file path relative to the ``.vtm``.
    """
    lines = ['<?xml version="1.0"?>', '<VTKFile type="vtkMultiBlockDataSet" version="1.0" byte_order="LittleEndian">',
             "  <vtkMultiBlockDataSet>"]
    lines += [f'    <DataSet index="{k}" name={quoteattr(name)} file={quoteattr(file)}/>'
              for k, (name, file) in enumerate(blocks)]
    lines += ["  </vtkMultiBlockDataSet>", "</VTKFile>", ""]
    return "\n".join(lines)


def write_collection(out: Path, frames, n_frames: int, pvd_name: str, comment: str, identity: dict,
                     progress=None, extra=None, overwrite: bool = False) -> None:
    """Write ``frames``, an iterable of (time (s), ((part name, meshio.Mesh), ...)) per frame, as
    ``<part>_NNNN.vtu`` files, one ``frame_NNNN.vtm`` per frame naming its parts, and the ParaView
    collection ``pvd_name`` of the frames into ``out``, with a manifest
    ``identity`` (format, case, command, run) plus the files. ``out`` is checked first
    (:func:`riskassess.products.outfolder.check`: new, empty, or this run's earlier export with ``overwrite``);
    the files are staged beside it and moved in at the end, so an interrupted export leaves the
    previous one intact; ``extra(staging)`` may add files before the collection is written.

    Parameters
    ----------
    out : Path
        The export folder (new, empty, or an earlier export of the same run).
    frames : iterable of (float, tuple of (str, meshio.Mesh))
        Per frame its time (s) and its parts; positions in the frame the caller states in ``comment``.
    n_frames : int
        Number of frames, for ``progress``.
    pvd_name : str
        File name of the collection (``impact.pvd``, ``towing.pvd``).
    comment : str
        Comment written into the collection.
    identity : dict
        ``format``, ``case``, ``command``, ``run`` of the export's manifest.
    progress : callable, optional
        ``progress(frames written, n_frames)``.
    extra : callable, optional
        ``extra(staging folder)`` writes more files into the export.
    overwrite : bool
        Replace an earlier export of the same run.
    """
    old = outfolder.check(out, identity, overwrite)
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.partial-"))
    try:
        entries = []
        for n, (t, parts) in enumerate(frames):
            blocks = []
            for name, mesh in parts:
                file = f"{name}_{n:04d}.vtu"
                meshio.write(staging / file, mesh, file_format="vtu", binary=True, compression="zlib")
                blocks.append((name, file))
            (staging / f"frame_{n:04d}.vtm").write_text(vtm_text(blocks))
            entries.append((t, 0, "frame", f"frame_{n:04d}.vtm"))
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


def frame_bytes(frames, parts: tuple, f: int) -> int:
    """Size (bytes) of snapshot ``f`` written as the export writes it (compressed VTU files).

    Parameters
    ----------
    frames : object
        Per-frame data with a method ``<part>_mesh(f) -> meshio.Mesh`` for each part.
    parts : tuple of str
        Part names.
    f : int
        Net snapshot index.
    """
    with tempfile.TemporaryDirectory() as tmp:
        for part in parts:
            meshio.write(Path(tmp) / f"{part}.vtu", getattr(frames, f"{part}_mesh")(f), file_format="vtu",
                         binary=True, compression="zlib")
        return sum(p.stat().st_size for p in Path(tmp).iterdir())


def frame_stride(n_snapshots: int, every: int | None, max_frames: int | None, bytes_per_frame=None,
                 budget: int = VTK_BUDGET_BYTES) -> int:
    """Snapshots to step: ``every`` when given; else the smallest stride that keeps at most
    ``max_frames`` frames; else at most ``budget // bytes_per_frame()`` frames (at least 2).

    Parameters
    ----------
    n_snapshots : int
        Net snapshots in the run folder.
    every : int, optional
        Snapshots to step, >= 1.
    max_frames : int, optional
        Most frames to write, >= 1 (not together with ``every``).
    bytes_per_frame : callable, optional
        ``bytes_per_frame() -> int`` size of one frame (bytes); called only when needed.
    budget : int
        Export size to stay within (bytes).
    """
    if every is not None:
        if every < 1:
            raise ValueError(f"every must be >= 1 (frames to step); got {every}")
        if max_frames is not None:
            raise ValueError("give 'every' or 'max_frames', not both")
        return every
    if max_frames is None:
        max_frames = max(2, budget // max(1, bytes_per_frame()))
    elif max_frames < 1:
        raise ValueError(f"max_frames must be >= 1; got {max_frames}")
    return max(1, -(-n_snapshots // max_frames))


def export_frames(run_dir: str | Path, out: str | Path | None, every: int | None, progress, frames_type, parts: tuple,
                  pvd_name: str, comment: str, extra=None, overwrite: bool = False,
                  max_frames: int | None = None) -> VtkExport:
    """The front shared by the impact and the tow export: checks ``every``, reads the run folder into
    ``frames_type(run)`` (which raises MissingData before anything is written), writes every stride-th
    net snapshot's ``parts`` (each the ``<part>_mesh(f)`` of the frames; stride: :func:`frame_stride`)
    with :func:`write_collection` into ``out`` (default ``RUN_DIR/vtk``; a folder directly inside the run
    folder is registered as a product of the run) and returns where and how many. ``extra(frames,
    staging)`` may add files.

    Parameters
    ----------
    run_dir : str or Path
        The run folder (a ``riskassess run`` or full-net ``riskassess tow`` output folder).
    out : str or Path, optional
        The export folder; default ``RUN_DIR/vtk``.
    every : int, optional
        Snapshots to step, >= 1.
    progress : callable, optional
        ``progress(frames written, frames to write)``.
    frames_type : callable
        ``frames_type(run: RunFolder)`` -> the per-frame data (a ``<part>_mesh(f)`` method per part and
        ``net["time"]`` (k,) s).
    parts : tuple of str
        Part names, one ``<part>_NNNN.vtu`` per frame each.
    pvd_name : str
        File name of the collection.
    comment : str
        What the collection's comment says (the frame of the positions, units).
    extra : callable, optional
        ``extra(frames, staging folder)`` writes more files.
    overwrite : bool
        Replace an earlier export of the same run.
    max_frames : int, optional
        Most frames to write.

    Returns
    -------
    VtkExport
        Export folder, ``.pvd`` path, number of frames and their times (s).
    """
    if every is not None and every < 1:
        raise ValueError(f"every must be >= 1 (frames to step); got {every}")
    run = RunFolder(run_dir)
    out = Path(out) if out else run.path / "vtk"
    identity = {"format": VTK_FORMAT, "case": run.manifest.get("case"), "command": "export-vtk",
                "run": str(run.path.resolve())}
    outfolder.check(out, identity, overwrite)   # refuse before reading the run's arrays
    frames = frames_type(run)
    n = len(frames.net["time"])
    # sized on a mid-run snapshot: the flat net at t = 0 compresses far better than the wrapped one
    stride = frame_stride(n, every, max_frames, lambda: frame_bytes(frames, parts, n // 2))
    picked = np.arange(0, n, stride)
    write_collection(out, ((float(frames.net["time"][f]), tuple((part, getattr(frames, f"{part}_mesh")(f)) for part in parts))
                           for f in picked), len(picked), pvd_name, f"case {run.manifest.get('case')}: {comment}", identity,
                     progress, None if extra is None else lambda staging: extra(frames, staging), overwrite)
    if out.resolve().parent == run.path.resolve():
        run.add_product(out.name)
    return VtkExport(out, out / pvd_name, len(picked), frames.net["time"][picked])
