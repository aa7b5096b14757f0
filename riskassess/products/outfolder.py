"""Output folders: how every command claims the folder it writes, and the state its manifest records.

The rules (docs/outputs.md, "Output folders"):

* the tool never deletes or overwrites a file it did not create;
* a missing ``--out`` is created, an empty one is used;
* a non-empty folder is used only when its ``manifest.json`` says it holds the output of the same
  command family for the same case, and only with ``--overwrite``; the old run's own files (those
  its manifest lists under ``files`` and ``products``, and the tool's temporary files) are removed
  first, after the manifest has been marked ``running``, and nothing else is ever removed: any
  other file in the folder refuses the overwrite;
* the default folder is ``runs/<safe name>``, the case name reduced to letters, digits, ``_`` and ``-``.

A refusal is an :class:`OutputRefused` (a ``ValueError``: exit code 2) naming the folder and what is
in the way. :class:`OutputFolder` then keeps the manifest: ``running`` until the command's last
product is written, then ``complete`` (or the outcome the stage reported, or ``products_failed``).
"""
from __future__ import annotations

import contextlib
import datetime
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path

from multibody.solver_output import SOLVER_LOG, solver_log
from riskassess.products.results import FORMAT, VERSION, write_manifest

MANIFEST = "manifest.json"
#: Commands that write the same kind of folder: re-running one into the other's folder is a re-run.
FAMILIES = {"assess": "run"}
#: Names of the tool's own temporary files: ``atomic_write_*`` (``.<name>.<8 random>.tmp`` and
#: ``.<stem>.<8 random>.npz``, tempfile.mkstemp) and the VTK export's staging folders.
TEMPORARY = re.compile(r"^\..+\.[a-z0-9_]{8}\.(tmp|npz)$|^\..+\.(partial|old)-[a-z0-9_]{8}$")
#: Longest folder name made from a case name (characters).
MAX_NAME = 80


class OutputRefused(ValueError):
    """The output folder holds something the tool must not touch; the message says what and where."""


def safe_name(name: str) -> str:
    """A folder name from user text: runs of anything but ASCII letters, digits, ``_`` and ``-``
    become one ``_`` (so no ``/``, ``..``, leading dot or absolute path survives); ``unnamed`` if empty.

    Parameters
    ----------
    name : str
        User text, typically a case name; cut to :data:`MAX_NAME` characters.
    """
    safe = re.sub(r"[^A-Za-z0-9_-]+", "_", str(name)).strip("_-")[:MAX_NAME]
    return safe or "unnamed"


def default_out(case_name: str, suffix: str = "", root: str | Path = "runs") -> Path:
    """``root/<safe name><suffix>``: the default ``--out`` of a command, always inside ``root``.

    Parameters
    ----------
    case_name : str
        The case's ``name``.
    suffix : str
        Appended to the name before cleaning (e.g. ``"_identify"``, ``"-diagnosis"``).
    root : str or Path
        Folder that holds the default output folders (``runs``).
    """
    return Path(root) / safe_name(f"{case_name}{suffix}")


def is_temporary(name: str) -> bool:
    """Whether a file or folder name is one of the tool's temporary names (:data:`TEMPORARY`).

    Parameters
    ----------
    name : str
        A bare file or folder name (no path).
    """
    return TEMPORARY.match(name) is not None


def read_own_manifest(folder: Path) -> dict | None:
    """The folder's manifest when it is one this tool wrote (any format ``riskassess-*``), else None.

    Parameters
    ----------
    folder : Path
        Folder that may hold a ``manifest.json`` (a symbolic link is never read).
    """
    path = Path(folder) / MANIFEST
    try:
        manifest = json.loads(path.read_text()) if path.is_file() and not path.is_symlink() else None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not isinstance(manifest, dict) or not str(manifest.get("format", "")).startswith("riskassess-"):
        return None
    return manifest


def command_of(manifest: dict) -> str:
    """The command family that wrote a manifest (older manifests carry no ``command``).

    Parameters
    ----------
    manifest : dict
        A manifest read by :func:`read_own_manifest`.

    Returns
    -------
    str
        ``run`` (``assess`` counts as ``run``), ``perceive``, ``identify``, or the stage name.
    """
    command = manifest.get("command")
    if command is None:
        if manifest.get("format") == "riskassess-identify":
            command = "identify"
        elif manifest.get("stage", "impact") == "impact":
            command = "perceive" if "perception.json" in manifest.get("files", []) else "run"
        else:
            command = manifest["stage"]
    return FAMILIES.get(command, command)


def owned_paths(folder: Path, manifest: dict) -> set[str]:
    """Relative paths (``/``-separated) of the files a manifest makes the tool's own: the manifest,
    its ``files`` and ``products``; a listed folder that holds its own manifest (a VTK export)
    contributes that manifest's files.

    Parameters
    ----------
    folder : Path
        The output folder the manifest belongs to.
    manifest : dict
        Its manifest; entries outside the folder (absolute, ``..``) are ignored.

    Returns
    -------
    set of str
        Paths relative to ``folder``.
    """
    owned = {MANIFEST}
    for name in [*manifest.get("files", []), *manifest.get("products", [])]:
        name = str(name).strip("/")
        if not _inside(folder, name):
            continue
        sub = read_own_manifest(folder / name) if (folder / name).is_dir() else None
        if sub is not None:
            owned |= {f"{name}/{p}" for p in owned_paths(folder / name, sub)}
        else:
            owned.add(name)
    return owned


def _inside(folder: Path, name: str) -> bool:
    """A manifest entry names a path inside the folder (no absolute path, no ``..``)."""
    parts = Path(name).parts
    return bool(parts) and not Path(name).is_absolute() and ".." not in parts


def foreign_entries(folder: Path, owned: set[str]) -> list[str]:
    """Everything in ``folder`` the tool did not make: neither owned, nor a temporary file, nor a
    folder holding only those (symbolic links are never the tool's).

    Parameters
    ----------
    folder : Path
        The output folder to walk.
    owned : set of str
        Relative paths the tool owns, from :func:`owned_paths`.

    Returns
    -------
    list of str
        Sorted relative paths; folders end with ``/``.
    """
    foreign = []
    parents = {str(Path(p).parent) for p in owned} | {str(q) for p in owned for q in Path(p).parents}
    for root, dirs, files in os.walk(folder):
        rel_root = Path(root).relative_to(folder)
        for d in list(dirs):
            rel = rel_root / d
            if (Path(root) / d).is_symlink() or (str(rel) not in parents and not is_temporary(d)):
                foreign.append(f"{rel}/")
                dirs.remove(d)
        for f in files:
            rel = rel_root / f
            if (Path(root) / f).is_symlink() or (rel.as_posix() not in owned and not is_temporary(f)
                                                 and not is_temporary(rel_root.name)):
                foreign.append(str(rel))
    return sorted(foreign)


def _listing(names: list[str], limit: int = 6) -> str:
    more = f" and {len(names) - limit} more" if len(names) > limit else ""
    return ", ".join(names[:limit]) + more


def check(out: Path, identity: dict, overwrite: bool) -> dict | None:
    """Raise :class:`OutputRefused` unless ``out`` may receive this output (module rules); return
    the existing manifest to replace (with ``overwrite``), or None for a new or empty folder.
    ``identity``: ``format``, ``case``, ``command`` and any further keys that must match
    (a VTK export's ``run``).

    Parameters
    ----------
    out : Path
        The requested output folder (``--out``).
    identity : dict
        ``format``, ``case``, ``command`` (and e.g. ``run``) of the output about to be written.
    overwrite : bool
        The user passed ``--overwrite``.

    Returns
    -------
    dict or None
        The manifest of the output to replace, or None.
    """
    out = Path(out)
    if out.is_symlink():
        raise OutputRefused(f"{out}: is a symbolic link; give the folder it points to ({out.resolve()}) as --out")
    if out.exists() and not out.is_dir():
        raise OutputRefused(f"{out}: is not a folder; choose a new or empty output folder")
    if not out.exists() or not any(out.iterdir()):
        return None
    existing = read_own_manifest(out)
    if existing is None:
        raise OutputRefused(f"{out}: refusing to write into a folder that is not empty and was not written by "
                            f"riskassess; in the way: {_listing(sorted(p.name for p in out.iterdir()))}. "
                            f"Choose a new or empty output folder (--out); nothing was changed")
    theirs = {"format": existing.get("format"), "case": existing.get("case"), "command": command_of(existing),
              **{k: existing.get(k) for k in identity if k not in ("format", "case", "command")}}
    ours = {**identity, "command": FAMILIES.get(identity["command"], identity["command"])}
    if theirs != ours:
        raise OutputRefused(f"{out}: holds the output of 'riskassess {theirs['command']}' for case "
                            f"{theirs['case']!r}{_differing(theirs, ours)}; this is 'riskassess {ours['command']}' "
                            f"for case {ours['case']!r}. Choose another output folder (--out); nothing was changed")
    if not overwrite:
        raise OutputRefused(f"{out}: already holds a '{existing.get('status')}' output of case {ours['case']!r}; "
                            f"pass --overwrite to replace it (only the files its manifest lists are removed), "
                            f"or choose another output folder (--out)")
    foreign = foreign_entries(out, owned_paths(out, existing))
    if foreign:
        raise OutputRefused(f"{out}: --overwrite would leave files riskassess did not write beside the new "
                            f"output: {_listing(foreign)}; move them away or choose another folder; nothing "
                            f"was changed")
    return existing


def _differing(theirs: dict, ours: dict) -> str:
    """The further keys that differ (a VTK export of another run), when command and case agree."""
    if (theirs["command"], theirs["case"]) != (ours["command"], ours["case"]):
        return ""
    extra = [f"{k} {theirs[k]!r}" for k in theirs if k not in ("format", "case", "command") and theirs[k] != ours[k]]
    return f" ({', '.join(extra)})" if extra else ""


def remove_own(out: Path, manifest: dict, keep=lambda name: False) -> None:
    """Remove the files ``manifest`` lists (see :func:`owned_paths`) and the tool's temporary files,
    except those ``keep(relative path)`` holds on to; then the folders this emptied. Only after
    :func:`check` found nothing else in ``out``.

    Parameters
    ----------
    out : Path
        The output folder.
    manifest : dict
        Its existing manifest (the files to remove).
    keep : callable
        ``keep(relative_path) -> bool``: True keeps that file.
    """
    owned = owned_paths(out, manifest)
    for rel in sorted(owned - {MANIFEST}, key=lambda p: -p.count("/")):
        if not keep(rel):
            (out / rel).unlink(missing_ok=True)
    for root, dirs, files in os.walk(out, topdown=False):
        for f in files:
            if is_temporary(f) or is_temporary(Path(root).name):
                (Path(root) / f).unlink(missing_ok=True)
        for d in dirs:
            with contextlib.suppress(OSError):   # a folder still holding a kept file stays
                (Path(root) / d).rmdir()


@dataclass
class OutputFolder:
    """A claimed output folder and its manifest; every manifest change goes through here."""

    path: Path
    manifest: dict

    def write(self) -> None:
        write_manifest(self.path, self.manifest)

    def add_files(self, *names: str) -> None:
        """Record finished files of the stage (relative paths) in ``files``.

        Parameters
        ----------
        *names : str
            Paths relative to the output folder.
        """
        files = self.manifest.setdefault("files", [])
        files += [n for n in names if n not in files]
        self.write()

    def finish(self, outcome: str = "complete", pending=(), **fields) -> None:
        """The stage's results are written with ``outcome`` (``complete``, ``not_observable``, ...);
        the status says so at once, or stays ``running`` while ``pending`` products are to come.

        Parameters
        ----------
        outcome : str
            The stage's outcome, stored under ``outcome`` (and ``status`` unless products are pending).
        pending : sequence of str
            Product steps still to come (``"report"``, ``"vtk"``); each ends with :func:`step_done`.
        **fields
            More manifest keys to store.
        """
        self.manifest.update(fields, outcome=outcome, status="running" if pending else outcome)
        if pending:
            self.manifest["products_pending"] = list(pending)
        self.write()

    def fail(self, status: str, exc: BaseException) -> None:
        """Record that the command stopped (``failed``, ``structures_failed``) and why.

        Parameters
        ----------
        status : str
            The manifest status to record (``failed``, ``structures_failed``, ...).
        exc : BaseException
            The cause, recorded under ``error`` as ``"Type: message"``.
        """
        self.manifest.update(status=status, error=f"{type(exc).__name__}: {exc}")
        self.write()

    @contextlib.contextmanager
    def recording(self):
        """Any exception (Ctrl-C included) while the folder is ``running`` is recorded as ``failed``.
        What the solver prints meanwhile goes to :data:`~multibody.solver_output.SOLVER_LOG` here
        (listed in the manifest; lines that are not routine notices also reach standard error)."""
        try:
            with solver_log(self.path / SOLVER_LOG):
                yield self
        except BaseException as exc:
            if self.manifest.get("status") == "running" and "outcome" not in self.manifest:
                self.fail("failed", exc)
            raise
        finally:
            if (self.path / SOLVER_LOG).is_file() and SOLVER_LOG not in self.manifest.get("files", []):
                self.add_files(SOLVER_LOG)


def claim(out: str | Path, case_name: str, command: str, overwrite: bool = False, stage: str | None = None,
          keep=None, **fields) -> OutputFolder:
    """Claim ``out`` for ``command`` on case ``case_name`` (module rules) and write its manifest
    with status ``running``. ``keep(relative path)``: old files to carry over on ``--overwrite``
    (a cache still valid for the new run); ``fields``: more manifest keys (``software``).

    Parameters
    ----------
    out : str or Path
        The output folder (``--out``); created when missing.
    case_name : str
        The case's ``name``, recorded under ``case``.
    command : str
        The CLI command (``run``, ``assess``, ``tow``, ...).
    overwrite : bool
        The user passed ``--overwrite``.
    stage : str, optional
        Recorded under ``stage`` (``tow``, ``approach``, ``diagnose``; omitted for impact runs).
    keep : callable, optional
        ``keep(relative_path) -> bool`` for old files to carry over.
    **fields
        More manifest keys.

    Returns
    -------
    OutputFolder
        The claimed folder, its manifest written with status ``running``.
    """
    out = Path(out)
    identity = {"format": FORMAT, "case": case_name, "command": command}
    existing = check(out, identity, overwrite)
    kept = []
    if existing is not None:
        # the old results stop being trusted before the first of them goes
        write_manifest(out, {**existing, "status": "running", "error": "being replaced by a new run"})
        keep = keep or (lambda name: False)
        remove_own(out, existing, keep)
        kept = [f for f in existing.get("files", []) if keep(f) and (out / f).is_file()]
    out.mkdir(parents=True, exist_ok=True)
    manifest = {"format": FORMAT, "version": VERSION, "case": case_name, "command": command,
                **({"stage": stage} if stage else {}), "status": "running",
                "created": datetime.datetime.now(datetime.timezone.utc).isoformat(), "files": kept, **fields}
    folder = OutputFolder(out, manifest)
    folder.write()
    return folder


def open_existing(run_dir: str | Path) -> OutputFolder:
    """An output folder written earlier (by this tool), to record products made from it.

    Parameters
    ----------
    run_dir : str or Path
        An output folder holding this tool's ``manifest.json``.
    """
    manifest = read_own_manifest(Path(run_dir))
    if manifest is None:
        raise OutputRefused(f"{run_dir}: no riskassess manifest.json; not an output folder of this tool")
    return OutputFolder(Path(run_dir), manifest)


def claim_product(run_dir: Path, manifest: dict, name: str) -> None:
    """Refuse to write product ``name`` (relative path) into ``run_dir`` over a file the tool did not
    make (one its ``manifest`` does not list).

    Parameters
    ----------
    run_dir : Path
        The output folder the product goes into.
    manifest : dict
        Its manifest.
    name : str
        The product's path relative to ``run_dir`` (``report.html``, ``vtk``).
    """
    target = Path(run_dir) / name
    if (target.exists() or target.is_symlink()) and name not in manifest.get("products", []) \
            and name not in manifest.get("files", []):
        raise OutputRefused(f"{target}: exists and was not written by riskassess for this run; "
                            f"move it away to write the {name} here")


def step_done(run_dir: str | Path, step: str, error: BaseException | None = None) -> None:
    """A product step (``report``, ``vtk``) ended, with ``error`` if it failed (kept under
    ``product_errors``; a later successful retry clears it). Once no step is pending the status
    becomes the stage's outcome, or ``products_failed`` when a step failed after complete results.
    Reads the manifest afresh: the step itself recorded its files under ``products``. A step the
    folder's command did not ask for (``riskassess report RUN`` on its own) changes nothing unless
    it retries one that failed.

    Parameters
    ----------
    run_dir : str or Path
        The output folder the product was made from.
    step : str
        The product step, ``"report"`` or ``"vtk"``.
    error : BaseException, optional
        Why the step failed; None when it succeeded.
    """
    folder = open_existing(run_dir)
    m = folder.manifest
    errors = m.get("product_errors", {})
    if step not in m.get("products_pending", []) and step not in errors:
        return
    if error is None:
        errors.pop(step, None)
    else:
        errors[step] = f"{type(error).__name__}: {error}"
    m["product_errors"] = errors
    if step in m.get("products_pending", []):
        m["products_pending"].remove(step)
    if not m.get("products_pending"):
        m.pop("products_pending", None)
        outcome = m.get("outcome", m.get("status"))
        m["status"] = "products_failed" if errors and outcome == "complete" else outcome
    if not errors:
        del m["product_errors"]
    folder.write()
