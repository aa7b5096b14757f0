"""Run folders shared by the riskassess tests (simulated once per test session, not once per worker)."""
import contextlib
import fcntl
import io
import os
from pathlib import Path

import pytest

from riskassess.cli import main

CASES = Path(__file__).resolve().parents[2] / "cases"


def shortened_case(end_time: float) -> str:
    """cases/envisat_small.toml with a shorter simulated time (s)."""
    text = (CASES / "envisat_small.toml").read_text()
    assert "end_time = 7.5" in text
    return text.replace("end_time = 7.5", f"end_time = {end_time}", 1)


def once_per_session(tmp_path_factory, name: str, build) -> Path:
    """The folder ``build(folder)`` fills, made once for the whole test session.

    Under pytest-xdist every worker has its own session, so a session fixture used by files on both
    workers ran its simulation twice (``--dist loadfile`` spreads the files that use it). The first
    worker to ask builds the folder under the workers' common temporary root, holding an exclusive
    lock; the others wait on the lock and reuse it. The run is deterministic (one thread, same
    inputs), so which worker builds it changes no number. Tests only read the folder or copy it.
    Without xdist the folder is built in the session's own temporary directory.
    """
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        folder = tmp_path_factory.mktemp(name)
        build(folder)
        return folder
    root = tmp_path_factory.getbasetemp().parent / "shared"
    root.mkdir(exist_ok=True)
    folder, done = root / name, root / f"{name}.done"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)            # released when the file closes
        if not done.exists():
            folder.mkdir(exist_ok=False)
            build(folder)
            done.touch()
    return folder


def _assess(tmp: Path, end_time: float, stem: str, keep_stdout: bool) -> Path:
    case = tmp / f"{stem}.toml"
    case.write_text(shortened_case(end_time))
    out = tmp / "run"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["assess", str(case), "--out", str(out), "--json"]) == 0
    if keep_stdout:
        # what `assess --json` printed, kept beside the folder (not in it: the folder is the tool's)
        (tmp / "assess_stdout.json").write_text(printed.getvalue())
    return out


@pytest.fixture(scope="session")
def assessed(tmp_path_factory):
    """The reduced Envisat case (15 x 15 net, the reference weak locations), 2 s: a complete run folder."""
    tmp = once_per_session(tmp_path_factory, "assess", lambda folder: _assess(folder, 2.0, "small_assess", True))
    return tmp / "run"


@pytest.fixture(scope="session")
def envisat_small_first_0p3s(tmp_path_factory):
    """The reduced Envisat case shortened to 0.3 s (first contact at ~0.15 s, the solar-array hinge
    fails at ~0.27 s): (case file, run folder written by ``riskassess assess``)."""
    tmp = once_per_session(tmp_path_factory, "short", lambda folder: _assess(folder, 0.3, "small_0p3", False))
    return tmp / "small_0p3.toml", tmp / "run"
