"""Is a numba kernel already compiled in its on-disk cache (``@njit(cache=True)``)?

The first run after an install (or after a kernel's source changed) compiles the force kernels,
about 30 s on one core, before the first step; later runs load them from ``__pycache__`` in well
under a second. The application layer asks :func:`compiled_on_disk` before a run to announce the
wait instead of sitting silent at t = 0.

numba keys a cached kernel on its own bytecode only: a kernel whose callee, in another file, changed
keeps loading its old machine code from ``__pycache__`` (an edited friction law ran the old law, twice
as fast, in every benchmark until the cache was cleared). :func:`use_source_keyed_cache` therefore
points numba's cache at a folder named for a hash of every source file of the compiled packages, so
an edit anywhere in them compiles afresh, once, and nothing stale can load. The packages call it in
their ``__init__`` before any kernel is defined.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
import time
from pathlib import Path

import numba
from numba import types

#: The packages that define ``@njit(cache=True)`` kernels, relative to the folder holding ``multibody``.
COMPILED_PACKAGES = ("multibody", "perception", "riskassess/diagnosis")
#: Keyed cache folders nothing was compiled into for this long (s) are removed (they are ours, and
#: one per edit of the sources piles up); several checkouts in use at once keep theirs.
STALE_CACHE_AGE_S = 14 * 86400.0

_cache_folder: Path | None = None

#: numba options of a per-step kernel that allocates nothing and returns no array: no reference counting in its
#: body (numba's ``_nrt`` option). numba compiles a callee that states no setting with its caller's, so a callee
#: that allocates states :data:`WITH_REFCOUNTS`; one that does not runs without counts too, which is safe as long as
#: it returns no array (each function's counts balance on their own).
#: numba otherwise takes and drops a reference to every array of every named tuple a function is handed or reads
#: from a structref, at its entry and exits: some 500 atomic counts a step of the reference case, 6.4 % of its solve
#: (perf, docs/model.md, Speed, helper "speed10"). Safe only where every array the function touches is held by its
#: caller for the whole call, nothing is allocated (numba then refuses to compile it) and no array is returned to
#: a caller that would drop a reference it was never given.
NO_REFCOUNTS = {"_nrt": False}
#: numba options of a kernel that a :data:`NO_REFCOUNTS` kernel calls and that allocates (or calls what does): numba
#: compiles a callee with its caller's runtime setting unless the callee states its own, and allocating needs it.
WITH_REFCOUNTS = {"_nrt": True}


def source_key(roots) -> str:
    """Hex SHA-256 (first 16 digits) of the relative path and bytes of every ``.py`` file under ``roots``.

    Parameters
    ----------
    roots : iterable of path
        Package folders; a missing one is skipped.
    """
    digest = hashlib.sha256()
    for root in roots:
        root = Path(root)
        if not root.is_dir():
            continue
        for path in sorted(root.rglob("*.py")):
            digest.update(str(path.relative_to(root.parent)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _cache_root() -> Path:
    """Where the keyed folders live: ``NUMBA_CACHE_DIR`` if the user set it, else the user's cache
    folder (``XDG_CACHE_HOME`` or ``~/.cache``)/adr-riskassess/numba."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"]) / "adr-riskassess"
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "adr-riskassess" / "numba"


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder):
            pass
        return True
    except OSError:
        return False


def _remove_old_folders(root: Path, current: Path) -> None:
    """Remove keyed folders other than ``current`` unchanged for :data:`STALE_CACHE_AGE_S`; errors are
    ignored (another process may be removing one too)."""
    now = time.time()
    for folder in root.iterdir():
        try:
            if folder.is_dir() and folder != current and now - folder.stat().st_mtime > STALE_CACHE_AGE_S:
                shutil.rmtree(folder, ignore_errors=True)
        except OSError:
            pass


def use_source_keyed_cache() -> Path:
    """Point numba's disk cache (``numba.config.CACHE_DIR``) at a folder keyed by :func:`source_key` of
    :data:`COMPILED_PACKAGES` (module doc); idempotent. Falls back to the system's temporary folder when
    the user's cache folder is not writable. Returns the folder."""
    global _cache_folder
    if _cache_folder is None:
        project = Path(__file__).resolve().parents[1]
        key = source_key(project / package for package in COMPILED_PACKAGES)
        root = _cache_root()
        if not _writable(root / key):
            root = Path(tempfile.gettempdir()) / f"adr-riskassess-numba-{os.getuid()}"
        folder = root / key
        folder.mkdir(parents=True, exist_ok=True)
        _remove_old_folders(root, folder)
        numba.config.CACHE_DIR = str(folder)
        _cache_folder = folder
    return _cache_folder


def compiled_on_disk(dispatcher) -> bool:
    """``dispatcher`` (an ``@njit(cache=True)`` function) has a cached compilation for its current
    source on this CPU: the same index key numba looks up before compiling (signature, CPU name and
    features, hash of the bytecode and closure). False for a function without a disk cache.

    Parameters
    ----------
    dispatcher : numba.core.registry.CPUDispatcher
        A compiled function.

    Notes
    -----
    Reads numba's cache index only (``FunctionCache._cache_file._load_index``, numba 0.60 to 0.68);
    an internal API, so any error reads as "not compiled": at worst the announcement is shown once
    too often.
    """
    cache = getattr(dispatcher, "_cache", None)
    cache_file = getattr(cache, "_cache_file", None)
    if cache_file is None:
        return False
    try:
        index = cache_file._load_index()
        codegen = dispatcher.targetctx.codegen()
        return any(cache._index_key(key[0], codegen) in index for key in index)
    except Exception:  # noqa: BLE001 -- numba internals changed: say "not compiled"
        return False


def all_compiled_on_disk(dispatchers) -> bool:
    """Every one of ``dispatchers`` is :func:`compiled_on_disk`.

    Parameters
    ----------
    dispatchers : iterable of numba.core.registry.CPUDispatcher
        Compiled functions.
    """
    return all(compiled_on_disk(d) for d in dispatchers)


class UnliteralStructRef(types.StructRef):
    """Base of the project's numba structref types: field types without literal values, so one
    compilation serves every case and run (a structref built from a case's constants would otherwise
    be typed with those values and compile afresh for each). Subclass and register with
    ``numba.experimental.structref.register``."""

    def preprocess_fields(self, fields):
        """Field types without literal values (numba's structref hook).

        Parameters
        ----------
        fields : tuple of (str, numba type)

        Returns
        -------
        tuple of (str, numba type)
        """
        return tuple((name, types.unliteral(typ)) for name, typ in fields)
