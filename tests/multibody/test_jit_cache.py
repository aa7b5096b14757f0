"""multibody.jit_cache: numba's disk cache is keyed by the compiled packages' sources, so an edit in a
callee's file can never load a caller's stale machine code (numba keys a kernel on its own bytecode)."""
import os
import time

import numba

from multibody import jit_cache
from multibody.jit_cache import source_key, use_source_keyed_cache


def _package(root, body):
    (root / "pkg").mkdir(exist_ok=True)
    (root / "pkg" / "kernel.py").write_text("def caller():\n    return callee()\n")
    (root / "pkg" / "law.py").write_text(body)
    return root / "pkg"


def test_an_edit_in_any_source_file_changes_the_key(tmp_path):
    package = _package(tmp_path, "def callee():\n    return 1.0\n")
    before = source_key([package])
    assert source_key([package]) == before                       # deterministic
    _package(tmp_path, "def callee():\n    return 2.0\n")         # only the callee's file changes
    assert source_key([package]) != before
    (package / "extra.py").write_text("")                         # a new file counts too
    assert len({before, source_key([package])}) == 2


def test_the_cache_folder_is_numbas_and_named_for_the_key():
    folder = use_source_keyed_cache()
    assert numba.config.CACHE_DIR == str(folder)
    assert folder.name == source_key(jit_cache.Path(jit_cache.__file__).resolve().parents[1] / p
                                     for p in jit_cache.COMPILED_PACKAGES)
    assert use_source_keyed_cache() == folder                      # idempotent: set once per process


def test_only_keyed_folders_unused_for_two_weeks_are_removed(tmp_path):
    current, recent, old = (tmp_path / name for name in ("current", "recent", "old"))
    for folder in (current, recent, old):
        folder.mkdir()
    two_weeks_ago = time.time() - jit_cache.STALE_CACHE_AGE_S - 60.0
    os.utime(old, (two_weeks_ago, two_weeks_ago))
    os.utime(current, (two_weeks_ago, two_weeks_ago))      # in use now, whatever its age
    jit_cache._remove_old_folders(tmp_path, current)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["current", "recent"]
