"""Where Exudyn's console output goes while it solves.

Exudyn's C++ core prints routine notices on every solve ("WARNING: VelocityVerlet: still under
development", "large amount (137523) of memory allocations ..."). Standard output must carry only
the tool's own results (``riskassess run --json``), and the user's terminal only what needs their
attention. So, within :func:`solver_log`, everything the solver prints is appended to a log file
(the run folder's ``solver.log``); lines that are not one of :data:`ROUTINE_NOTICES` (a real error
or an unknown warning) are also copied to standard error. Outside :func:`solver_log` the output
goes to standard error, as before.

No Exudyn import here: the application layer sets the destination before it builds a model.
"""
from __future__ import annotations

import contextlib
import contextvars
import ctypes
import os
import re
import sys
from pathlib import Path

#: Name of the solver log in an output folder.
SOLVER_LOG = "solver.log"

#: What Exudyn prints on every solve of ours, harmless by design (one table: add a notice here).
ROUTINE_NOTICES = (
    re.compile(r"VelocityVerlet: still under development"),   # exudyn 1.13, every explicit solve
    # exudyn/solver.py CheckSolverInfoStatistics: our coupled force is a Python user function
    re.compile(r"detected large amount \(\d+\) of memory allocations"),
    re.compile(r"^\s*$"),                                      # blank lines
)

_DESTINATION: contextvars.ContextVar[Path | None] = contextvars.ContextVar("solver_log", default=None)


def is_routine(line: str) -> bool:
    """The solver's ``line`` is one of :data:`ROUTINE_NOTICES` (kept in the log only).

    Parameters
    ----------
    line : str
        One line the solver printed.
    """
    return any(p.search(line) for p in ROUTINE_NOTICES)


@contextlib.contextmanager
def solver_log(path: str | Path):
    """Within the block, what the solver prints is appended to ``path`` (created if needed).

    Parameters
    ----------
    path : str or Path
        The log file.
    """
    token = _DESTINATION.set(Path(path))
    try:
        yield Path(path)
    finally:
        _DESTINATION.reset(token)


def _flush_c_stdout() -> None:
    """Flush C stdio (``std::cout`` shares its buffer), so nothing printed inside lands outside."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library to reach (not on the platforms we ship for)
        pass


@contextlib.contextmanager
def _fd1_to(fd: int, stream):
    """File descriptor 1 and ``sys.stdout`` to ``fd`` / ``stream`` (pybind's print goes through
    ``sys.stdout``, which need not be file descriptor 1), restored after the block."""
    sys.stdout.flush()
    _flush_c_stdout()
    saved = os.dup(1)
    try:
        os.dup2(fd, 1)
        with contextlib.redirect_stdout(stream):
            yield
    finally:
        sys.stdout.flush()
        _flush_c_stdout()
        os.dup2(saved, 1)
        os.close(saved)


@contextlib.contextmanager
def solver_chatter_captured():
    """Around a solve: its console output to the current :func:`solver_log` (then the lines that
    are not routine also to standard error), or to standard error when no log is set."""
    path = _DESTINATION.get()
    if path is None:
        with _fd1_to(2, sys.stderr):
            yield
        return
    with open(path, "a+", encoding="utf-8", errors="replace") as log:
        start = log.tell()
        try:
            with _fd1_to(log.fileno(), log):
                yield
        finally:
            log.flush()
            log.seek(start)
            unusual = [line for line in log.read().splitlines() if not is_routine(line)]
            if unusual:
                print("\n".join(unusual), file=sys.stderr, flush=True)
