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
structures.json    the structural verdict (cases with weak locations)
structures.npz     demand time series per weak location, ``<location>/<demand>``
=================  ==============================================================

Products made later from the folder (``report.html``, ``report.pdf``, the ``vtk`` folder with
its own manifest) are listed under ``products`` in the manifest; deleting one does not spoil the
folder. Which folders the tool may write, and the manifest's states: :mod:`riskassess.products.outfolder`
and docs/outputs.md.

Every file is written to a temporary name and renamed, so a folder never holds a
half-written file; the manifest is written last and lists what is complete.
"""
from __future__ import annotations

import json
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

FORMAT = "riskassess-run"
VERSION = 1
#: zlib level of the ``.npz`` files (numpy's ``savez_compressed`` writes zlib's default, 6). A run's float series
#: compress little at any level: measured on a 30 s capture run (helper speed22, 2026-11-28, load 13; CPU time),
#: timeseries.npz 53.8 MB raw: level 6 1.42 s to 35.1 MB, level 1 0.78 s to 35.4 MB; net.npz 16.5 MB: 0.36 s to 11.4 MB
#: against 0.28 s to 11.3 MB. The arrays read back are the same either way; only the bytes of the archive differ.
NPZ_COMPRESS_LEVEL = 1


def _default_mode() -> int:
    """File mode of a normally created file (0o666 less the umask); mkstemp's 0o600 would hide
    results from the user's group."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder.

    Parameters
    ----------
    path : Path
        Destination file; its folder must exist (the temporary file is made there so the
        rename is atomic).
    data : bytes
        The whole content.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.chmod(tmp, _default_mode())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_json(path: Path, obj) -> None:
    """Write ``obj`` as indented JSON to ``path``, atomically (numpy arrays and scalars as lists and numbers).

    Parameters
    ----------
    path : Path
        Destination ``.json`` file; its folder must exist.
    obj : dict or list
        JSON-serialisable content; ``numpy.ndarray`` and numpy scalars are converted.
    """
    atomic_write_bytes(path, (json.dumps(obj, indent=2, default=_json_default) + "\n").encode())


def atomic_write_npz(path: Path, arrays: dict) -> None:
    """Write ``arrays`` to the compressed ``.npz`` file ``path``, atomically.

    Parameters
    ----------
    path : Path
        Destination ``.npz`` file; its folder must exist.
    arrays : dict of str to numpy.ndarray
        Array name -> array, stored under that name.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".npz")
    os.close(fd)
    try:
        _savez_deflated(tmp, arrays)
        os.chmod(tmp, _default_mode())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _savez_deflated(path, arrays: dict) -> None:
    """``numpy.savez_compressed(path, **arrays)`` at :data:`NPZ_COMPRESS_LEVEL` (numpy's own writer, one ``.npy``
    member per array; object arrays pickled, as numpy does)."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=NPZ_COMPRESS_LEVEL) as archive:
        for name, value in arrays.items():
            with archive.open(name + ".npy", "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.asanyarray(value), allow_pickle=True)


def write_manifest(folder: Path, manifest: dict) -> None:
    """The one writer of ``manifest.json`` (atomically); :mod:`riskassess.products.outfolder` keeps its content.

    Parameters
    ----------
    folder : Path
        The output folder; ``manifest.json`` is (re)written in it.
    manifest : dict
        The manifest's whole content (format, version, case, status, files, ...).
    """
    atomic_write_json(Path(folder) / "manifest.json", manifest)


def _json_default(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    raise TypeError(f"cannot write {type(obj).__name__} to JSON")


def read_manifest(run_dir: Path, strict: bool = True) -> dict:
    """The run's manifest; ``ValueError`` saying what is missing for an incomplete or foreign folder.

    ``strict=False`` accepts a folder whose listed files are not all there (readers that
    say per item what is missing, like the report).

    Parameters
    ----------
    run_dir : Path
        A run folder written by ``riskassess run`` (holding ``manifest.json``).
    strict : bool
        Raise when a file the manifest lists is missing (default); False accepts it.

    Returns
    -------
    dict
        The parsed ``manifest.json``.
    """
    path = Path(run_dir) / "manifest.json"
    if not path.is_file():
        raise ValueError(f"{run_dir}: no manifest.json; not a riskassess run folder, or the run did not finish")
    manifest = json.loads(path.read_text())
    if manifest.get("format") != FORMAT:
        raise ValueError(f"{path}: format {manifest.get('format')!r} is not {FORMAT!r}")
    if manifest.get("version", 0) > VERSION:
        raise ValueError(f"{path}: version {manifest['version']} is newer than this tool reads ({VERSION})")
    missing = [f for f in manifest.get("files", []) if not (Path(run_dir) / f).is_file()]
    if missing and strict:
        raise ValueError(f"{run_dir}: files listed in the manifest are missing: {missing}")
    return manifest


#: Files every complete version-1 run folder holds; structures.* only for cases with weak locations.
CORE_FILES = ("case.toml", "case.json", "summary.json", "timeseries.npz", "net.npz", "bodies.npz")


class MissingData(LookupError):
    """A run folder lacks a file or key a later stage needs; the message says which and why."""


class RunFolder:
    """Read access to a run folder for the stages after the simulation (report, VTK export).

    Opening checks only the manifest; each accessor raises :class:`MissingData` naming the
    missing file (or key) so a report of an incomplete or older folder can say what is
    missing section by section instead of failing as a whole.
    """

    def __init__(self, run_dir: str | Path):
        self.path = Path(run_dir)
        self.manifest = read_manifest(self.path, strict=False)
        self._cache: dict = {}

    @property
    def complete(self) -> bool:
        """The stage's results are all written (``outcome``; older folders: ``status``), even while
        products of the same command (report, VTK) are still to come or one of them failed."""
        return self.manifest.get("outcome", self.manifest.get("status")) == "complete"

    @property
    def stage(self) -> str:
        """The stage that wrote the folder: 'impact' (run, assess, perceive: the files of
        :data:`CORE_FILES`) or the manifest's ``stage`` (approach, tow, diagnose), whose folders hold
        no impact results."""
        return self.manifest.get("stage", "impact")

    def missing_core_files(self) -> list[str]:
        if self.stage != "impact":
            return []
        return [f for f in CORE_FILES if not (self.path / f).is_file()]

    def has(self, name: str) -> bool:
        """The run wrote ``name`` completely (listed in the manifest) and it is still there.

        Parameters
        ----------
        name : str
            File name relative to the run folder, e.g. ``"summary.json"``.
        """
        return (self.path / name).is_file() and name in self.manifest.get("files", [])

    def _require(self, name: str) -> Path:
        if not self.has(name):
            if name in self.manifest.get("files", []):
                why = "listed in the manifest, but deleted or moved since"
            elif not self.complete:
                why = f"the run stopped with status '{self.manifest.get('status')}'"
            else:
                why = "not written by this run"
            raise MissingData(f"{self.path / name} is missing ({why})")
        return self.path / name

    def json(self, name: str) -> dict:
        """A JSON file of the folder, parsed once and cached.

        Parameters
        ----------
        name : str
            File name relative to the run folder, e.g. ``"summary.json"``; :class:`MissingData`
            when the run did not write it completely.
        """
        if name not in self._cache:
            self._cache[name] = json.loads(self._require(name).read_text())
        return self._cache[name]

    def arrays(self, name: str) -> dict[str, np.ndarray]:
        """The arrays of an ``.npz`` file of the folder, loaded once and cached.

        Parameters
        ----------
        name : str
            File name relative to the run folder, e.g. ``"timeseries.npz"``; :class:`MissingData`
            when the run did not write it completely.

        Returns
        -------
        dict of str to numpy.ndarray
            Array name -> array, shapes and units as the module doc lists them.
        """
        if name not in self._cache:
            with np.load(self._require(name)) as data:
                self._cache[name] = {k: data[k] for k in data.files}
        return self._cache[name]

    def cached(self, name: str, build):
        """``build(self)`` once per folder object (a derived product several readers share).

        Parameters
        ----------
        name : str
            Cache key (not a file name).
        build : callable
            ``build(run_folder) -> object``, called on the first request only.
        """
        if name not in self._cache:
            self._cache[name] = build(self)
        return self._cache[name]

    @property
    def summary(self) -> dict:
        return self.json("summary.json")

    @property
    def case(self) -> dict:
        return self.json("case.json")

    @property
    def timeseries(self) -> dict[str, np.ndarray]:
        return self.arrays("timeseries.npz")

    @property
    def net(self) -> dict[str, np.ndarray]:
        return self.arrays("net.npz")

    @property
    def bodies(self) -> dict[str, np.ndarray]:
        return self.arrays("bodies.npz")

    @property
    def structures(self) -> dict:
        return self.json("structures.json")

    @property
    def structures_series(self) -> dict[str, np.ndarray]:
        return self.arrays("structures.npz")

    def key(self, data: dict, *path):
        """``data[path[0]][path[1]]...``; :class:`MissingData` naming the key for older folders.

        Parameters
        ----------
        data : dict
            Nested content, e.g. :attr:`summary`.
        *path : str or int
            The keys (or list indices) to follow, outermost first.
        """
        value = data
        for k in path:
            try:
                value = value[k]
            except (KeyError, IndexError, TypeError):
                raise MissingData(f"{self.path}: key {'/'.join(map(str, path))} is missing "
                                  f"(a run folder from an older version of the tool?)") from None
        return value

    def add_product(self, relative_path: str) -> None:
        """Record a file made from this folder (report, export) in the manifest's ``products``.

        Parameters
        ----------
        relative_path : str
            The product's path relative to the run folder, e.g. ``"report.html"`` or ``"vtk"``.
        """
        products = self.manifest.setdefault("products", [])
        if relative_path not in products:
            products.append(relative_path)
            write_manifest(self.path, self.manifest)


def load_timeseries(run_dir: Path) -> dict[str, np.ndarray]:
    """Every time series of a run (``timeseries.npz``) after checking the manifest (strict).

    Parameters
    ----------
    run_dir : Path
        A complete run folder of ``riskassess run``.

    Returns
    -------
    dict of str to numpy.ndarray
        The recorder's series: ``time`` (k,) s and the keys of :mod:`multibody.recorder`
        (shapes, units and frames there), plus ``body_names``, ``joint_names``, ``joint_kinds``,
        ``body_masses``.
    """
    read_manifest(run_dir)
    with np.load(Path(run_dir) / "timeseries.npz") as data:
        return {k: data[k] for k in data.files}


def load_summary(run_dir: Path) -> dict:
    """The run summary (``summary.json``) after checking the manifest (strict).

    Parameters
    ----------
    run_dir : Path
        A complete run folder of ``riskassess run``.

    Returns
    -------
    dict
        As :func:`riskassess.products.summary.run_summary` wrote it.
    """
    read_manifest(run_dir)
    return json.loads((Path(run_dir) / "summary.json").read_text())
