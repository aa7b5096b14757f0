"""The results store of a sweep: one SQLite file, one row per run, written as each run ends.

Each write is one committed transaction (SQLite journals it), so killing the sweep at any
moment keeps every finished run; a re-run with the same store skips them. The store also
holds the sweep's definition (the case file's content and the arguments) and refuses to
mix runs of a different case into it.

Run states: ``pending`` (declared, not finished), ``done`` (``result`` holds the run's
record), ``failed`` (``error`` says why; ``error_kind`` is ``simulation`` for an error of
the run itself, ``infrastructure`` for a lost worker or connection, which a resume retries).
"""
from __future__ import annotations

import datetime
import hashlib
import json
import sqlite3
from pathlib import Path

SCHEMA = """
CREATE TABLE IF NOT EXISTS sweep (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
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
    attempts INTEGER NOT NULL DEFAULT 0
);
"""


class StoreMismatch(ValueError):
    """The store belongs to another sweep (another case file content)."""


def case_fingerprint(case_text: str) -> str:
    return hashlib.sha1(case_text.encode()).hexdigest()[:16]


class ResultStore:
    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # isolation_level=None: autocommit; each write below is its own transaction.
        self.db = sqlite3.connect(self.path, isolation_level=None, timeout=30.0)
        self.db.execute("PRAGMA journal_mode=WAL")
        self.db.execute("PRAGMA synchronous=NORMAL")
        self.db.executescript(SCHEMA)

    @classmethod
    def open_existing(cls, path: str | Path) -> ResultStore:
        if not Path(path).is_file():
            raise ValueError(f"{path}: no such results store")
        return cls(path)

    def close(self) -> None:
        self.db.close()

    def info(self) -> dict:
        return {k: json.loads(v) for k, v in self.db.execute("SELECT key, value FROM sweep")}

    def declare(self, case_path: str, case_text: str, definition: dict, specs) -> None:
        """Record the sweep definition and its runs (``pending`` unless already there)."""
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
        """Of ``run_ids``, those still to run: pending, infrastructure failures, and (if asked) all failures."""
        rows = {rid: (state, kind) for rid, state, kind in self.db.execute("SELECT run_id, state, error_kind FROM runs")}
        keep = []
        for rid in run_ids:
            state, kind = rows.get(rid, ("pending", None))
            if state == "pending" or (state == "failed" and (retry_failed or kind == "infrastructure")):
                keep.append(rid)
        return keep

    def _now(self) -> str:
        return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")

    def write_done(self, run_id: str, record: dict) -> None:
        self.db.execute("UPDATE runs SET state='done', result=?, error=NULL, error_kind=NULL, wall_s=?, finished=?, "
                        "attempts=attempts+1 WHERE run_id=?",
                        (json.dumps(record), record.get("wall_time_s"), self._now(), run_id))

    def write_failed(self, run_id: str, error: str, kind: str) -> None:
        self.db.execute("UPDATE runs SET state='failed', error=?, error_kind=?, finished=?, attempts=attempts+1 "
                        "WHERE run_id=?", (error, kind, self._now(), run_id))

    def rows(self) -> list[dict]:
        """Every run in grid order, with parsed overrides and result."""
        out = []
        cursor = self.db.execute("SELECT run_id, grid_index, sample, overrides, state, result, error, error_kind, "
                                 "wall_s, finished, attempts FROM runs ORDER BY grid_index, sample")
        for rid, g, m, overrides, state, result, error, kind, wall, finished, attempts in cursor:
            out.append({"run_id": rid, "grid_index": g, "sample": m, "overrides": json.loads(overrides),
                        "state": state, "result": json.loads(result) if result else None, "error": error,
                        "error_kind": kind, "wall_s": wall, "finished": finished, "attempts": attempts})
        return out
