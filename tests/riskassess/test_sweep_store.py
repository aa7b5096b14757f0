"""The results store refuses what is not its own (issue 20, item 8): read-only status, format and
integrity checked on open, 0-byte and foreign files never reinitialised, one writer at a time."""
import json
import re
import sqlite3
import subprocess
import sys

import pytest

from riskassess.cli import main
from riskassess.sweep.spec import RunSpec, run_id
from riskassess.sweep.store import (APPLICATION_ID, SCHEMA_VERSION, ResultStore, StoreError, StoreLocked,
                                    check_store_file)
from tests.riskassess.conftest import CASES

CASE_TEXT = "name = 'hand_made'\n"


def _spec(v: float, sample: int = 0) -> RunSpec:
    overrides = {"launch.velocity": v}
    return RunSpec(run_id(overrides), overrides, int(v), sample)


@pytest.fixture
def store_path(tmp_path):
    """A store with two runs: one done without debris, one pending."""
    path = tmp_path / "results.sqlite"
    with ResultStore(path) as store:
        store.declare("case.toml", CASE_TEXT, {"arguments": []}, [_spec(10.0), _spec(20.0)])
        store.write_done(_spec(10.0).run_id, {"secondary_debris": False, "debris_state": "no_debris",
                                              "locations": {"hinge": {"utilization": 0.5}}, "breakup_likelihood": 0.0})
    return path


def _foreign_sqlite(path):
    """Another application's SQLite file, rollback journal (the default)."""
    db = sqlite3.connect(path)
    db.execute("CREATE TABLE notes (text TEXT)")
    db.execute("INSERT INTO notes VALUES ('thesis')")
    db.commit()
    db.close()


def test_new_store_is_stamped_with_format_and_schema(store_path):
    db = sqlite3.connect(store_path)
    assert db.execute("PRAGMA application_id").fetchone()[0] == APPLICATION_ID
    assert db.execute("PRAGMA user_version").fetchone()[0] == SCHEMA_VERSION
    db.close()
    assert check_store_file(store_path) == SCHEMA_VERSION


def test_status_of_a_foreign_sqlite_file_is_refused_and_leaves_it_untouched(tmp_path, capsys):
    path = tmp_path / "thesis.sqlite"
    _foreign_sqlite(path)
    before = path.read_bytes()
    assert main(["sweep-status", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "not a results store" in err
    assert path.read_bytes() == before                       # no table added, journal mode unchanged
    assert sorted(p.name for p in tmp_path.iterdir()) == ["thesis.sqlite"]   # no -wal, -shm or lock file
    db = sqlite3.connect(path)
    assert db.execute("PRAGMA journal_mode").fetchone()[0] == "delete"
    db.close()


def test_status_opens_read_only(store_path, capsys):
    before = store_path.read_bytes()
    lock = store_path.parent / "results.sqlite.lock"
    lock_stat = lock.stat()
    assert main(["sweep-status", str(store_path)]) == 0
    assert store_path.read_bytes() == before
    assert lock.stat().st_mtime_ns == lock_stat.st_mtime_ns and lock.read_text() == ""   # no lock taken by a reader
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[1] for line in lines] == ["done", "pending"]
    assert "secondary_debris=no" in lines[0]
    with pytest.raises(sqlite3.OperationalError, match="readonly"):
        ResultStore.open_readonly(store_path).db.execute("CREATE TABLE x (y)")


@pytest.mark.parametrize("content, message", [
    (b"", "empty file (0 bytes)"),
    (b"hello, this is not a database\n" * 10, "not an SQLite file"),
])
def test_empty_or_garbage_store_is_refused_never_reinitialised(tmp_path, content, message, capsys):
    path = tmp_path / "results.sqlite"
    path.write_bytes(content)
    assert main(["sweep-status", str(path)]) == 2
    assert message in capsys.readouterr().err
    with pytest.raises(StoreError, match=re.escape(message)):
        ResultStore(path)                                       # a writer refuses it too
    assert path.read_bytes() == content
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.sqlite"]


def test_truncated_store_gives_a_clear_error_naming_the_file(tmp_path):
    path = tmp_path / "results.sqlite"
    with ResultStore(path) as store:
        many = [_spec(float(v)) for v in range(3000)]
        store.declare("case.toml", CASE_TEXT * 50, {"arguments": ["x" * 1000]}, many)
        store.db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    data = path.read_bytes()
    assert len(data) > 100_000
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(StoreError, match=f"{path}: damaged"):
        ResultStore.open_readonly(path)
    with pytest.raises(StoreError, match="damaged"):
        ResultStore(path)


def test_foreign_sqlite_file_is_refused_as_a_sweep_store(tmp_path):
    path = tmp_path / "results.sqlite"
    _foreign_sqlite(path)
    with pytest.raises(StoreError, match="not a results store"):
        ResultStore(path)
    db = sqlite3.connect(path)
    db.execute("PRAGMA application_id = 1234")
    db.commit()
    db.close()
    with pytest.raises(StoreError, match="another application"):
        ResultStore(path)


def test_store_of_a_newer_schema_is_refused(store_path):
    db = sqlite3.connect(store_path)
    db.execute(f"PRAGMA user_version = {SCHEMA_VERSION + 1}")
    db.commit()
    db.close()
    with pytest.raises(StoreError, match=f"schema version {SCHEMA_VERSION + 1}"):
        ResultStore.open_readonly(store_path)


def test_schema_1_store_is_read_and_migrated(tmp_path):
    """A store written before the format stamp: read as it is, migrated when a sweep writes."""
    path = tmp_path / "results.sqlite"
    db = sqlite3.connect(path)
    db.executescript("""
        CREATE TABLE sweep (key TEXT PRIMARY KEY, value TEXT NOT NULL);
        CREATE TABLE runs (run_id TEXT PRIMARY KEY, grid_index INTEGER NOT NULL, sample INTEGER NOT NULL,
            overrides TEXT NOT NULL, state TEXT NOT NULL CHECK (state IN ('pending', 'done', 'failed')),
            result TEXT, error TEXT, error_kind TEXT, wall_s REAL, finished TEXT, attempts INTEGER NOT NULL DEFAULT 0);
    """)
    nan_record = {"secondary_debris": False, "peak_contact_force_N": float("nan"), "locations": {}}
    good_record = {"secondary_debris": True, "peak_contact_force_N": 3.0, "locations": {}}
    db.executemany("INSERT INTO runs VALUES (?, 0, 0, ?, 'done', ?, NULL, NULL, 1.0, 'x', 1)",
                   [("a", json.dumps({"launch.velocity": 1.0}), json.dumps(nan_record)),
                    ("b", json.dumps({"launch.velocity": 2.0}), json.dumps(good_record))])
    db.commit()
    db.close()
    assert check_store_file(path) == 1
    with ResultStore.open_readonly(path) as store:
        # the NaN "no debris" of a store written before the health checks is indeterminate
        assert [r["debris_state"] for r in store.rows()] == ["indeterminate", "debris"]
    with ResultStore(path) as store:
        assert store.version == SCHEMA_VERSION
        assert dict(store.db.execute("SELECT run_id, debris_state FROM runs")) == {"a": "indeterminate",
                                                                                   "b": "debris"}
    assert check_store_file(path) == SCHEMA_VERSION


def test_second_writer_is_refused_naming_the_holder(store_path, capsys):
    """Another process holds the store: the message names its pid; after it ends, the lock is free."""
    holder = subprocess.Popen(
        [sys.executable, "-c", ("import sys, time; from riskassess.sweep.store import ResultStore; "
                                f"s = ResultStore({str(store_path)!r}); print('ready', flush=True); time.sleep(60)")],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "ready"
        with pytest.raises(StoreLocked, match=f"another sweep is writing to this store.*pid {holder.pid}"):
            ResultStore(store_path)
        argv = ["sweep", str(CASES / "envisat_small.toml"), "--vary", "launch.velocity=12:20:2", "--store",
                str(store_path)]
        assert main(argv) == 2                                  # the second sweep of the reproducer
        assert f"another sweep is writing to this store (pid {holder.pid}, host " in capsys.readouterr().err
        with ResultStore.open_readonly(store_path) as store:   # readers are not locked out
            assert len(store.rows()) == 2
    finally:
        holder.kill()
        holder.wait()
    with ResultStore(store_path) as store:                      # the kernel dropped the dead holder's lock
        assert len(store.rows()) == 2


def test_lock_file_that_is_not_ours_is_left_alone(tmp_path):
    path = tmp_path / "results.sqlite"
    (tmp_path / "results.sqlite.lock").write_text("my notes\n")
    with pytest.raises(StoreError, match="not a lock file"):
        ResultStore(path)
    assert (tmp_path / "results.sqlite.lock").read_text() == "my notes\n"


def test_the_store_keeps_why_a_run_is_indeterminate():
    """run_record keeps each location's state, reason and rule; an indeterminate run's record lists them per
    (location, rule), and a set of rows counts runs per (location, rule) (bench/bench_safe_velocity.py prints it)."""
    from riskassess.products.sweep_records import indeterminate_rule_counts
    from riskassess.sweep.runner import run_record

    summary = {"peak_contact_force_N": {"value": 10.0}, "peak_contact_moment_about_debris_com_Nm": {"value": 1.0},
               "joints": {}, "checks": {"energy_balance_relative_drift": 1e-6}, "wall_time_s": 1.0,
               "steps_per_second": 1e3}
    threads = ("net threads passed through solar_array (node-only contact; ...): the load they would have put on it, "
               "at most 80 N and 355 N m about the joint, could take moment past the allowable (1.20 of it)")

    def location(name, state, reason=None, peak=88.0):
        # the verdict gives each reason with its rule (structures.indeterminacy)
        return {"name": name, "fails": state == "fails", "likelihood": 0.0, "released_at_s": None, "state": state,
                "indeterminate_reason": reason, "indeterminate_rules": ["thread_pass_through"] if reason else [],
                "criteria": {"moment": {"peak": peak, "decisive_allowable": 200.0, "margin_of_safety": 200 / peak - 1,
                                        "unit": "N m"}}}

    def verdict(state, *locations):
        return {"locations": list(locations), "released_pieces": [], "debris_state": state,
                "secondary_debris": {"debris": True, "no_debris": False}.get(state)}

    unknown = run_record(summary, verdict("indeterminate", location("array", "indeterminate", threads),
                                          location("asar", "holds")), {"launch.velocity": 2.0})
    assert unknown["locations"]["array"]["indeterminate_rules"] == ["thread_pass_through"]
    assert unknown["locations"]["asar"]["state"] == "holds" and unknown["locations"]["asar"]["indeterminate_rules"] == []
    assert unknown["indeterminate_reasons"] == [{"location": "array", "rule": "thread_pass_through", "reason": threads}]
    safe = run_record(summary, verdict("no_debris", location("array", "holds")), {"launch.velocity": 2.0})
    assert safe["indeterminate_reasons"] == []
    # "no debris" on a NaN peak is indeterminate run-wide (debris_state_of), with its own rule
    nan = run_record(summary, verdict("no_debris", location("array", "holds", peak=float("nan"))), {})
    assert nan["indeterminate_reasons"][0]["rule"] == "non_finite_evidence"
    old = {"secondary_debris": None, "locations": {"array": {"utilization": 0.4}}}      # stored before the reasons
    rows = [{"state": "done", "result": r} for r in (unknown, unknown, safe, nan, old)] + [{"state": "failed",
                                                                                            "result": None}]
    assert indeterminate_rule_counts(rows) == {("array", "thread_pass_through"): 2, (None, "non_finite_evidence"): 1,
                                               (None, "not_recorded"): 1}
