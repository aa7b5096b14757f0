"""The run folder: what ``riskassess run`` writes and later stages read without re-running.

Layout (format ``riskassess-run``, version 1):

=================  ==============================================================
file               content
=================  ==============================================================
manifest.json      format, version, case name, status, files, software versions
case.toml          the case file as given
case.json          the validated case (every default filled in)
summary.json       peaks, debris velocity change, hinge extremes, checks, wall time
timeseries.npz     every time series of :mod:`multibody.recorder` plus ``body_names``,
                   ``joint_names``, ``joint_kinds``, ``body_masses``
net.npz            net snapshots (``time``, ``positions_lvlh``, ``velocities_lvlh``) and
                   topology (``threads``, ``rest_lengths``, ``stiffness``, ``damping``,
                   ``masses``, ``radii``, ``n_bullets``)
bodies.npz         per body ``k``: ``vertices_k`` (m, body frame) and ``faces_k``
=================  ==============================================================

Every file is written to a temporary name and renamed, so a folder never holds a
half-written file; the manifest is written last and lists what is complete.
"""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import numpy as np

FORMAT = "riskassess-run"
VERSION = 1


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_json(path: Path, obj) -> None:
    atomic_write_bytes(path, (json.dumps(obj, indent=2, default=_json_default) + "\n").encode())


def atomic_write_npz(path: Path, arrays: dict) -> None:
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".npz")
    os.close(fd)
    try:
        np.savez_compressed(tmp, **arrays)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _json_default(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    raise TypeError(f"cannot write {type(obj).__name__} to JSON")


def read_manifest(run_dir: Path) -> dict:
    """The run's manifest; ``ValueError`` saying what is missing for an incomplete or foreign folder."""
    path = Path(run_dir) / "manifest.json"
    if not path.is_file():
        raise ValueError(f"{run_dir}: no manifest.json; not a riskassess run folder, or the run did not finish")
    manifest = json.loads(path.read_text())
    if manifest.get("format") != FORMAT:
        raise ValueError(f"{path}: format {manifest.get('format')!r} is not {FORMAT!r}")
    if manifest.get("version", 0) > VERSION:
        raise ValueError(f"{path}: version {manifest['version']} is newer than this tool reads ({VERSION})")
    missing = [f for f in manifest.get("files", []) if not (Path(run_dir) / f).is_file()]
    if missing:
        raise ValueError(f"{run_dir}: files listed in the manifest are missing: {missing}")
    return manifest


def load_timeseries(run_dir: Path) -> dict[str, np.ndarray]:
    read_manifest(run_dir)
    with np.load(Path(run_dir) / "timeseries.npz") as data:
        return {k: data[k] for k in data.files}


def load_summary(run_dir: Path) -> dict:
    read_manifest(run_dir)
    return json.loads((Path(run_dir) / "summary.json").read_text())
