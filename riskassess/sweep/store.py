"""The results store of a sweep: one SQLite file, one row per run, written as each run ends.

Each write is one committed transaction (SQLite journals it), so killing the sweep at any
moment keeps every finished run; a re-run with the same store skips them. The store also
holds the sweep's definition (the case file's content and the arguments) and refuses to
mix runs of a different case into it.

Run states: ``pending`` (declared, not finished), ``done`` (``result`` holds the run's
record, ``debris_state`` its verdict: ``debris``, ``no_debris``, ``indeterminate``, or NULL
for a case without weak locations), ``failed`` (``error`` says why; ``error_kind`` is
``diverged`` for a simulation stopped by the numerical health checks, ``simulation`` for
another error of the run itself, ``infrastructure`` for a lost worker or connection, which a
resume retries).

Opening is guarded, because a store path is user input:

* the file is recognised by its SQLite header: ``application_id`` :data:`APPLICATION_ID` and
  ``user_version`` the schema version (:data:`SCHEMA_VERSION`); a store of schema 1 (no id,
  written before the version existed) is recognised by its tables, read as it is, and
  migrated when a sweep writes to it; any other file, a 0-byte file or one of a newer schema
  is refused, never reinitialised (only a path that does not exist yet is created);
* ``PRAGMA quick_check`` must pass, else a :class:`StoreError` names the file;
* readers (:meth:`ResultStore.open_readonly`, ``sweep-status``) open with SQLite's
  ``mode=ro``: they never create tables or change the journal mode;
* a writer holds an exclusive ``flock`` on ``<store>.lock`` (pid, host and start time inside)
  for as long as it is open; a second writer is refused with a message naming the holder.
  The kernel drops the lock when the process ends, however it ends.
"""
from __future__ import annotations

import datetime
import fcntl
import hashlib
import json
import os
import socket
import sqlite3
import urllib.parse
from pathlib import Path

from riskassess.products.sweep_records import debris_state_of

#: SQLite header ``application_id`` of a results store: "RSKA" in ASCII.
APPLICATION_ID = 0x52534B41
#: Schema of the runs table. 1: before the format was stamped (no debris_state);
#: 2: ``debris_state`` per run, error kind ``diverged``.
SCHEMA_VERSION = 2
#: First line of the lock file; a lock file without it is not ours and is not touched.
LOCK_MARK = "riskassess-sweep-lock"
#: SQLite file header (https://www.sqlite.org/fileformat.html, section 1.3).
_HEADER = b"SQLite format 3\x00"
_HEADER_SIZE = 100
_USER_VERSION_OFFSET, _APPLICATION_ID_OFFSET = 60, 68

SCHEMA = """
CREATE TABLE sweep (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE runs (
    run_id TEXT PRIMARY KEY,
    grid_index INTEGER NOT NULL,
    sample INTEGER NOT NULL,
    overrides TEXT NOT NULL,
    state TEXT NOT NULL CHECK (state IN ('pending', 'done', 'failed')),
    result TEXT,
    error TEXT,
    error_kind TEXT,
    wall_s REAL,
    finished TEXT,
    attempts INTEGER NOT NULL DEFAULT 0,
    debris_state TEXT CHECK (debris_state IN ('debris', 'no_debris', 'indeterminate'))
);
"""
#: Columns of a schema-1 store's runs table (how it is recognised without an application id).
_V1_COLUMNS = ["run_id", "grid_index", "sample", "overrides", "state", "result", "error", "error_kind", "wall_s",
               "finished", "attempts"]


class StoreError(ValueError):
    """A path that is not a usable results store; the message names the file and why."""


class StoreLocked(StoreError):
    """Another sweep is writing to the store; the message names the holder."""


class StoreMismatch(StoreError):
    """The store belongs to another sweep (another case file content)."""


def case_fingerprint(case_text: str) -> str:
    """The first 16 hex digits of the SHA-1 of a case file's content: which case a store belongs to.

    Parameters
    ----------
    case_text : str
        The case file's content.
    """
    return hashlib.sha1(case_text.encode()).hexdigest()[:16]


def _header_fields(path: Path) -> tuple[int, int]:
    """(user_version, application_id) from the file header; StoreError when it is no SQLite file."""
    if not path.is_file():
        raise StoreError(f"{path}: not a regular file, so not a results store")
    with open(path, "rb") as f:
        header = f.read(_HEADER_SIZE)
    if not header:
        raise StoreError(f"{path}: empty file (0 bytes), not a results store; it is left as it is "
                         f"(delete it, or give another --store)")
    if len(header) < _HEADER_SIZE or not header.startswith(_HEADER):
        raise StoreError(f"{path}: not an SQLite file, so not a results store of 'riskassess sweep'")

    def field(offset):
        return int.from_bytes(header[offset:offset + 4], "big")
    return field(_USER_VERSION_OFFSET), field(_APPLICATION_ID_OFFSET)


def _connect_readonly(path: Path) -> sqlite3.Connection:
    uri = f"file:{urllib.parse.quote(str(path.resolve()))}?mode=ro"
    return sqlite3.connect(uri, uri=True, isolation_level=None, timeout=30.0)


def check_store_file(path: Path) -> int:
    """The schema version of the store at ``path``, after checking it is ours and intact.

    Parameters
    ----------
    path : Path
        An existing file given as a results store (``--store``).

    Returns
    -------
    int
        Schema version, 1 to :data:`SCHEMA_VERSION`.
    """
    user_version, application_id = _header_fields(path)
    if application_id not in (APPLICATION_ID, 0):
        raise StoreError(f"{path}: an SQLite file of another application (application_id {application_id:#x}), "
                         f"not a results store of 'riskassess sweep'; it is left as it is")
    if application_id == APPLICATION_ID and not 2 <= user_version <= SCHEMA_VERSION:
        raise StoreError(f"{path}: results store of schema version {user_version}; this riskassess reads versions "
                         f"1 to {SCHEMA_VERSION} (a newer riskassess wrote it?)")
    try:
        db = _connect_readonly(path)
        try:
            problems = [row[0] for row in db.execute("PRAGMA quick_check")]
            columns = [row[1] for row in db.execute("PRAGMA table_info(runs)")]
            tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        finally:
            db.close()
    except sqlite3.DatabaseError as exc:
        raise StoreError(f"{path}: damaged or unreadable SQLite file ({exc}); not used") from None
    if problems != ["ok"]:
        raise StoreError(f"{path}: damaged results store (PRAGMA quick_check: {'; '.join(problems[:3])}); not used")
    if application_id == 0:
        if tables != {"sweep", "runs"} or columns != _V1_COLUMNS:
            raise StoreError(f"{path}: an SQLite file that is not a results store of 'riskassess sweep' "
                             f"(tables {sorted(tables)}); it is left as it is")
        return 1
    return user_version


class _WriterLock:
    """Exclusive ``flock`` on ``<store>.lock``; the file holds pid, host and start time of the holder."""

    def __init__(self, store_path: Path):
        self.path = store_path.with_name(store_path.name + ".lock")
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        self.file = os.fdopen(fd, "r+")
        try:
            fcntl.flock(self.file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lines = [line for line in self.file.read().splitlines() if line and line != LOCK_MARK]
            holder = ", ".join(lines) or "holder not written yet"
            self.file.close()
            raise StoreLocked(f"{store_path}: another sweep is writing to this store ({holder}); wait for it to "
                              f"end, or give another --store") from None
        text = self.file.read()
        if text and not text.startswith(LOCK_MARK):
            self.file.close()
            raise StoreError(f"{self.path}: exists and is not a lock file of 'riskassess sweep'; it is left as it "
                             f"is (move it, or give another --store)")
        self.file.seek(0)
        self.file.truncate()
        started = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
        self.file.write(f"{LOCK_MARK}\npid {os.getpid()}\nhost {socket.gethostname()}\nstarted {started}\n")
        self.file.flush()

    def close(self) -> None:
        if not self.file.closed:
            self.file.seek(0)
            self.file.truncate()    # no stale holder named after a clean end
            self.file.close()       # closing the descriptor releases the flock


class ResultStore:
    """A results store open for writing (exclusive) or, from :meth:`open_readonly`, for reading."""

    def __init__(self, path: str | Path, readonly: bool = False):
        self.path = Path(path)
        self.readonly = readonly
        self.lock = None
        if readonly:
            self.version = check_store_file(self.path)
            self.db = _connect_readonly(self.path)
            return
        existed = self.path.exists()
        if existed:
            check_store_file(self.path)          # before any lock file is made beside a foreign file
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        self.lock = _WriterLock(self.path)
        try:
            self._open_for_writing()
        except BaseException:
            self.lock.close()
            raise

    def _open_for_writing(self) -> None:
        if self.path.exists():
            self.version = check_store_file(self.path)  # again, now under the lock
        else:
            self.version = None
        # isolation_level=None: autocommit; each write below is its own transaction.
        self.db = sqlite3.connect(self.path, isolation_level=None, timeout=30.0)
        if self.version is None:
            self.db.executescript(f"BEGIN; {SCHEMA} PRAGMA application_id = {APPLICATION_ID}; "
                                  f"PRAGMA user_version = {SCHEMA_VERSION}; COMMIT;")
        elif self.version == 1:
            self._migrate_v1()
        self.version = SCHEMA_VERSION
        self.db.execute("PRAGMA journal_mode=WAL")   # readers (sweep-status) read while the sweep writes
        self.db.execute("PRAGMA synchronous=NORMAL")

    def _migrate_v1(self) -> None:
        """Schema 1 -> 2 in one transaction: the debris_state column, filled from each done run's record."""
        rows = list(self.db.execute("SELECT run_id, result FROM runs WHERE state = 'done'"))
        self.db.execute("BEGIN")
        try:
            self.db.execute("ALTER TABLE runs ADD COLUMN debris_state TEXT "
                            "CHECK (debris_state IN ('debris', 'no_debris', 'indeterminate'))")
            self.db.executemany("UPDATE runs SET debris_state = ? WHERE run_id = ?",
                                [(debris_state_of(json.loads(result)) if result else None, rid)
                                 for rid, result in rows])
            self.db.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            self.db.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
            self.db.execute("COMMIT")
        except BaseException:
            self.db.execute("ROLLBACK")
            raise

    @classmethod
    def open_readonly(cls, path: str | Path) -> ResultStore:
        """An existing store for reading only (SQLite ``mode=ro``; no lock, no change to the file).

        Parameters
        ----------
        path : str or Path
            The results store (``.sqlite`` file).
        """
        if not Path(path).exists():
            raise StoreError(f"{path}: no such results store")
        return cls(path, readonly=True)

    #: Former name of :meth:`open_readonly`.
    open_existing = open_readonly

    def close(self) -> None:
        self.db.close()
        if self.lock is not None:
            self.lock.close()

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def info(self) -> dict:
        return {k: json.loads(v) for k, v in self.db.execute("SELECT key, value FROM sweep")}

    def set_info(self, key: str, value) -> None:
        """Store one entry of the sweep's definition (``sweep`` table), as JSON.

        Parameters
        ----------
        key : str
            Entry name (``arguments``, ``created``, ``products``, ...).
        value : object
            JSON-serialisable value.
        """
        self.db.execute("INSERT OR REPLACE INTO sweep VALUES (?, ?)", (key, json.dumps(value)))

    def declare(self, case_path: str, case_text: str, definition: dict, specs) -> None:
        """Record the sweep definition and its runs (``pending`` unless already there).

        Parameters
        ----------
        case_path : str
            The case file.
        case_text : str
            Its content; the store refuses another content (:class:`StoreMismatch`).
        definition : dict
            More sweep entries (``arguments``, ``created``).
        specs : list of riskassess.sweep.spec.RunSpec
            Every run of the sweep.
        """
        fingerprint = case_fingerprint(case_text)
        info = self.info()
        if info and info.get("case_fingerprint") != fingerprint:
            raise StoreMismatch(f"{self.path}: holds a sweep of another case content ({info.get('case_path')}, "
                                f"fingerprint {info.get('case_fingerprint')}, now {fingerprint}); use another --store")
        with self.db:
            self.db.execute("BEGIN")
            for key, value in {"case_path": case_path, "case_fingerprint": fingerprint, "case_text": case_text,
                               **definition}.items():
                self.db.execute("INSERT OR REPLACE INTO sweep VALUES (?, ?)", (key, json.dumps(value)))
            self.db.executemany(
                "INSERT OR IGNORE INTO runs (run_id, grid_index, sample, overrides, state) VALUES (?, ?, ?, ?, 'pending')",
                [(s.run_id, s.grid_index, s.sample, json.dumps(s.overrides)) for s in specs])

    def states(self) -> dict[str, str]:
        return dict(self.db.execute("SELECT run_id, state FROM runs"))

    def to_run(self, run_ids, retry_failed: bool = False) -> list[str]:
        """Of ``run_ids``, those still to run: pending, infrastructure failures, and (if asked) all failures.

        Parameters
        ----------
        run_ids : iterable of str
            Run ids of the sweep (:func:`riskassess.sweep.spec.run_id`).
        retry_failed : bool
            Include every failed run.

        Returns
        -------
        list of str
            The ids, in the order given, without repeats.
        """
        rows = {rid: (state, kind) for rid, state, kind in self.db.execute("SELECT run_id, state, error_kind FROM runs")}
        keep = []
        for rid in dict.fromkeys(run_ids):
            state, kind = rows.get(rid, ("pending", None))
            if state == "pending" or (state == "failed" and (retry_failed or kind == "infrastructure")):
                keep.append(rid)
        return keep

    def _now(self) -> str:
        return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")

    def write_done(self, run_id: str, record: dict) -> None:
        """Record a finished run (``done``) with its record and debris state, in one transaction.

        Parameters
        ----------
        run_id : str
            The run's id.
        record : dict
            Its record (:func:`riskassess.sweep.runner.run_record`).
        """
        self.db.execute("UPDATE runs SET state='done', result=?, debris_state=?, error=NULL, error_kind=NULL, "
                        "wall_s=?, finished=?, attempts=attempts+1 WHERE run_id=?",
                        (json.dumps(record), debris_state_of(record), record.get("wall_time_s"), self._now(), run_id))

    def write_failed(self, run_id: str, error: str, kind: str) -> None:
        """Record a failed run (``failed``) with its error, in one transaction.

        Parameters
        ----------
        run_id : str
            The run's id.
        error : str
            What went wrong.
        kind : str
            ``diverged``, ``simulation`` or ``infrastructure`` (:func:`riskassess.sweep.runner.failure_kind`).
        """
        self.db.execute("UPDATE runs SET state='failed', result=NULL, debris_state=NULL, error=?, error_kind=?, "
                        "finished=?, attempts=attempts+1 WHERE run_id=?", (error, kind, self._now(), run_id))

    def rows(self) -> list[dict]:
        """Every run in grid order, with parsed overrides and result, and the run's debris state."""
        out = []
        cursor = self.db.execute("SELECT run_id, grid_index, sample, overrides, state, result, error, error_kind, "
                                 "wall_s, finished, attempts FROM runs ORDER BY grid_index, sample")
        for rid, g, m, overrides, state, result, error, kind, wall, finished, attempts in cursor:
            result = json.loads(result) if result else None
            out.append({"run_id": rid, "grid_index": g, "sample": m, "overrides": json.loads(overrides),
                        "state": state, "result": result, "error": error, "error_kind": kind, "wall_s": wall,
                        "finished": finished, "attempts": attempts,
                        # from the record, so a schema-1 store read as it is gets the same answer
                        "debris_state": debris_state_of(result) if state == "done" and result else None})
        return out


def default_store_path(case_name: str) -> Path:
    """``sweeps/<case name>/results.sqlite``, the name reduced to one safe path component.

    Parameters
    ----------
    case_name : str
        The case's ``name``.
    """
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in case_name).strip("._") or "sweep"
    return Path("sweeps") / safe / "results.sqlite"
