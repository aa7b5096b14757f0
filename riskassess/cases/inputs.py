"""The edge of every case file: what is read, how much of it, and the rules every value obeys.

Every case schema (impact, towing, diagnosis, approach) derives from :class:`Strict`: unknown
keys are refused, types are strict (a TOML string is never taken for a number, an integer never
for a boolean; a TOML integer is taken for a float), every float is finite, every number lies
within :data:`MAX_MAGNITUDE`. Names are safe tokens, lists looked up by name hold each name once,
and a file a case names is a regular file below the case file's folder, read only up to its
limit. docs/case-format.md ("What the checker refuses") states the same for users.
"""
from __future__ import annotations

import os
import re
import stat
import tomllib
from pathlib import Path, PurePosixPath
from typing import Annotated, Literal, get_args

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, field_validator

#: The optimizers a towing case or ``riskassess identify --optimizers`` may name (plug-ins of
#: :mod:`riskassess.stages.optimizers`; the tests check each is there). Here rather than in the
#: towing schema so the CLI's parser can list them without loading the towing models.
Search = Literal["pso", "pattern", "mads"]
SEARCHES = get_args(Search)

#: Largest case file read (bytes). The largest shipped case is about 9 kB; 1 MB leaves a hundred
#: times that for comments and long tables while ``riskassess validate /dev/zero`` stops at once.
CASE_FILE_LIMIT = 1_000_000
#: Largest mesh file (bytes): a binary STL of 200 MB holds about 4 million triangles, beyond what the
#: contact and LiDAR geometry of one debris object needs, and still fits in memory on a laptop.
MESH_FILE_LIMIT = 200_000_000
#: Largest perception.json read by ``mass_properties_from`` (bytes); 'riskassess perceive' writes a
#: few kB (estimates, their covariances and per-frame figures).
JSON_FILE_LIMIT = 10_000_000
#: Largest measured-data file read (bytes): 50 MB is about 250 000 rows of 20 channels at 10 significant
#: digits, ten times the longest record the fit handles in minutes (every sample is simulated each
#: evaluation); the shipped records are below 1 MB.
MEASURED_FILE_LIMIT = 50_000_000
#: Deepest nesting of tables and arrays in a case file: the shipped cases nest 5 deep
#: (target.bodies[].shapes[].center[]); 32 leaves room and keeps the parser far from Python's
#: recursion limit (tomllib recurses about three frames per level).
MAX_NESTING = 32
#: Largest magnitude of any number in a case. The largest physical input of the shipped cases is
#: the Earth's gravitational parameter, 3.986e14 m^3/s^2; 1e18 leaves a factor 2500 above it, stays
#: below 2**63 (integers reach NumPy as int64) and keeps cubes of any input (1e54) far from the
#: float limit 1.8e308, so the checks' arithmetic cannot overflow.
MAX_MAGNITUDE = 1e18
#: A case name: it becomes the default output folder ``runs/<name>``, so one safe path component
#: (no separator, not '.' or '..', no leading '-' or '.').
CASE_NAME_PATTERN = r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}"
#: A body, joint or weak-location name: a case name that starts with a letter, so a sweep key
#: ``target.joints[hinge]`` never reads a name as a list index.
ITEM_NAME_PATTERN = r"[A-Za-z][A-Za-z0-9._-]{0,63}"
#: Longest free text (description, source) (characters).
MAX_TEXT = 10_000


#: Description of every schema's top-level ``kind``.
KIND_NOTE = ("The case kind: impact, towing, approach or diagnosis (docs/case-format.md); files written before "
             "it was explicit may leave it out.")


class CaseError(ValueError):
    """A case file that cannot be used; the message names the file, the key and what is allowed."""


# ---------------------------------------------------------------------------- files
def _size_text(n: int) -> str:
    return f"{n:,} bytes"


def check_regular_file(path: Path, limit: int) -> int:
    """The size (bytes) of ``path``, or ValueError (message without the path) when it is missing,
    not a regular file (a directory, a device such as /dev/zero, a pipe) or larger than ``limit``.

    Parameters
    ----------
    path : Path
        The file to check (a symbolic link is followed).
    limit : int
        Largest accepted size (bytes).

    Returns
    -------
    int
        The file's size (bytes).
    """
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise ValueError("no such file") from None
    except OSError as exc:
        raise ValueError(f"cannot be read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise ValueError("is a directory; a file is expected")
    if not stat.S_ISREG(info.st_mode):
        raise ValueError("is not a regular file (a device, pipe or socket); a file is expected")
    if info.st_size > limit:
        raise ValueError(f"is {_size_text(info.st_size)}; at most {_size_text(limit)} are read")
    return info.st_size


def read_limited(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them; ValueError otherwise (a file
    that grows while read, or a /proc file of size 0 that is not, is cut at the limit and refused).

    Parameters
    ----------
    path : Path
        The file to read.
    limit : int
        Largest accepted size (bytes).

    Returns
    -------
    bytes
    """
    check_regular_file(path, limit)
    try:
        with open(path, "rb") as f:
            data = f.read(limit + 1)
    except OSError as exc:
        raise ValueError(f"cannot be read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise ValueError(f"is larger than {_size_text(limit)}, the most that is read")
    return data


def decode_utf8(data: bytes, path: Path, what: str, bom: bool = False) -> str:
    """``data`` as text; ValueError naming ``path`` and the first bad byte when it is not UTF-8.

    Parameters
    ----------
    data : bytes
        The file's content.
    path : Path
        The file, named in the error.
    what : str
        What the file is ("case file", "measured-data file"), named in the error.
    bom : bool
        True to drop a leading byte-order mark.

    Returns
    -------
    str
    """
    try:
        return data.decode("utf-8-sig" if bom else "utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not UTF-8 text: byte {exc.start} is 0x{data[exc.start]:02x} "
                         f"(save the {what} as UTF-8)") from None


def read_text(path: Path, limit: int, what: str, bom: bool = False) -> str:
    """The text of the regular UTF-8 file ``path`` (a ``what`` such as "case file") of at most
    ``limit`` bytes, a byte-order mark dropped if ``bom``; ValueError starting with the path otherwise.

    Parameters
    ----------
    path : Path
        The file to read.
    limit : int
        Largest accepted size (bytes).
    what : str
        What the file is, named in errors.
    bom : bool
        True to drop a leading byte-order mark.

    Returns
    -------
    str
    """
    try:
        data = read_limited(path, limit)
    except ValueError as exc:
        raise ValueError(f"{path}: " + (f"no such {what}" if str(exc) == "no such file" else f"the {what} {exc}")) \
            from None
    return decode_utf8(data, path, what, bom)


def reference_problem(name: str) -> str | None:
    """Why the file name ``name`` written in a case is refused, or None: it must be a relative path
    below the case file's folder (no absolute path, drive or '..' component).

    Parameters
    ----------
    name : str
        A file name as written in a case file.

    Returns
    -------
    str or None
        The reason, phrased to follow the key ("must be relative to the case file; ...").
    """
    if not name or not name.strip():
        return "must name a file; it is empty"
    if "\x00" in name:
        return "must name a file; a NUL character is not allowed"
    posix = name.replace("\\", "/")
    if posix.startswith("/") or re.match(r"[A-Za-z]:", posix):
        return "must be relative to the case file; an absolute path is not allowed"
    if ".." in PurePosixPath(posix).parts:
        return "must be in the case file's folder or below it; a '..' component is not allowed"
    return None


def _relative_file(name: str) -> str:
    problem = reference_problem(name)
    if problem:
        raise ValueError(problem)
    return name


def resolve_reference(base: Path, name: str, limit: int) -> Path:
    """The file ``name`` named by a case in folder ``base``: a regular file of at most ``limit`` bytes
    below ``base``; ValueError (message without the key) otherwise.

    Parameters
    ----------
    base : Path
        Folder of the case file.
    name : str
        The file name written in the case (relative to ``base``).
    limit : int
        Largest accepted size (bytes).

    Returns
    -------
    Path
        ``base / name``.
    """
    problem = reference_problem(name)
    if problem:
        raise ValueError(f"'{name}' {problem}")
    path = Path(base) / name
    try:
        check_regular_file(path, limit)
    except ValueError as exc:
        where = " (paths are relative to the case file)" if str(exc) == "no such file" else ""
        raise ValueError(f"'{name}' {'not found' if str(exc) == 'no such file' else exc}{where}") from None
    return path


# ---------------------------------------------------------------------------- TOML
def nesting_depth(value) -> int:
    """How deep tables and arrays nest in parsed TOML (a scalar is 0, ``{"a": [1]}`` is 2).

    Parameters
    ----------
    value : dict, list or scalar
        Parsed TOML content.

    Returns
    -------
    int
    """
    deepest, stack = 0, [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            stack += [(v, depth + 1) for v in item.values()]
        elif isinstance(item, list):
            stack += [(v, depth + 1) for v in item]
        else:
            continue
        deepest = max(deepest, depth + 1)
    return deepest


def read_toml(path: str | Path) -> dict:
    """The parsed TOML of a case file; :class:`CaseError` naming the file when it is missing, not a
    regular file, larger than :data:`CASE_FILE_LIMIT`, not UTF-8, not TOML or nested deeper than
    :data:`MAX_NESTING`.

    Parameters
    ----------
    path : str or Path
        The case file.

    Returns
    -------
    dict
    """
    path = Path(path)
    try:
        text = read_text(path, CASE_FILE_LIMIT, "case file")
    except ValueError as exc:
        raise CaseError(str(exc)) from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:
        raise CaseError(f"{path}: tables or arrays nested too deeply; at most {MAX_NESTING} levels") from None
    depth = nesting_depth(raw)
    if depth > MAX_NESTING:
        raise CaseError(f"{path}: tables or arrays nested {depth} levels deep; at most {MAX_NESTING} are allowed")
    return raw


# ---------------------------------------------------------------------------- values
def _bounded(value, where: str = ""):
    """ValueError when a number in ``value`` (a number or nested lists/dicts of them) exceeds
    :data:`MAX_MAGNITUDE`."""
    if isinstance(value, bool) or value is None or isinstance(value, (str, BaseModel)):
        return
    if isinstance(value, (int, float)):
        if not abs(value) <= MAX_MAGNITUDE:
            raise ValueError(f"{where}must be within +-{MAX_MAGNITUDE:g} (no physical input comes near it; "
                             f"larger values overflow the arithmetic). Got {value:g} instead")
    elif isinstance(value, (list, tuple)):
        for k, item in enumerate(value):
            _bounded(item, f"{where}[{k}] " if not where else f"{where.rstrip()}[{k}] ")
    elif isinstance(value, dict):
        for key, item in value.items():
            _bounded(item, f"{where}{key} ")


class Strict(BaseModel):
    """Base of every case schema: unknown keys forbidden, strict types, finite and bounded numbers."""
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)

    @field_validator("*", mode="after")
    @classmethod
    def _magnitude(cls, value):
        _bounded(value)
        return value


def _case_name(name: str) -> str:
    if not re.fullmatch(CASE_NAME_PATTERN, name):
        raise ValueError("a case name is 1 to 64 letters, digits, '.', '_' or '-', starting with a letter or "
                         "digit (it names the output folder runs/<name>)")
    return name


def _item_name(name: str) -> str:
    if not re.fullmatch(ITEM_NAME_PATTERN, name):
        raise ValueError("a name is 1 to 64 letters, digits, '.', '_' or '-', starting with a letter")
    return name


def _plain_text(text: str) -> str:
    bad = [c for c in text if (ord(c) < 32 and c not in "\n\t") or 0x7f <= ord(c) < 0xa0]
    if bad:
        raise ValueError(f"control character {bad[0]!r} in text; only printable text, newlines and tabs")
    return text


CaseName = Annotated[str, AfterValidator(_case_name)]
ItemName = Annotated[str, AfterValidator(_item_name)]
Text = Annotated[str, Field(max_length=MAX_TEXT), AfterValidator(_plain_text)]
RelativeFile = Annotated[str, AfterValidator(_relative_file)]


def unique_names(items: list, what: str, attribute: str = "name") -> list:
    """``items`` if no two share ``attribute``; ValueError listing the repeated names and where.

    Parameters
    ----------
    items : list
        Validated items (bodies, joints, weak locations, effects).
    what : str
        What an item is ("body", "joint"), named in the error.
    attribute : str
        The attribute that must be unique.

    Returns
    -------
    list
        ``items`` unchanged (usable as a validator).
    """
    names = [getattr(item, attribute) for item in items]
    repeated = {n: [k for k, m in enumerate(names) if m == n] for n in names if names.count(n) > 1}
    if repeated:
        where = "; ".join(f"'{n}' (items {', '.join(map(str, ks[:-1]))} and {ks[-1]})" for n, ks in repeated.items())
        raise ValueError(f"each {what} needs its own {attribute}; repeated: {where}")
    return items
