"""Where the Dask cluster's own messages go during a sweep: to a log file beside the sweep's
products (``dask.log``), not across the progress bar.

* In this (client) process, the ``distributed`` loggers (scheduler, nannies, client) write
  WARNING and above to the file; their terminal handlers keep only ERROR and above.
* In every worker process of a local cluster, standard error (file descriptor 2) is the file:
  Python warnings, logging and whatever a library prints there. What a run raises still comes
  back to the client with its future and is recorded in the store and counted on the terminal;
  what the solver prints goes to the run's own ``solver.log`` (:mod:`multibody.solver_output`).

A remote scheduler's workers (``--scheduler``) keep their own logging: the file is a path on
this machine.
"""
from __future__ import annotations

import contextlib
import logging
import os
from pathlib import Path

from distributed.diagnostics.plugin import WorkerPlugin

#: Name of the cluster's log file in the sweep's products folder.
CLUSTER_LOG = "dask.log"
_FORMAT = "%(asctime)s %(name)s %(levelname)s %(message)s"


class StderrToFile(WorkerPlugin):
    """Worker plugin: the worker process's standard error appended to ``path``."""

    name = "riskassess-stderr-to-file"

    def __init__(self, path: str | Path):
        self.path = str(path)

    def setup(self, worker) -> None:
        """Point the worker process's file descriptor 2 at the log file (called by Dask on each worker).

        Parameters
        ----------
        worker : distributed.Worker
            The worker the plugin is registered on (not used).
        """
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        os.dup2(fd, 2)
        os.close(fd)


@contextlib.contextmanager
def distributed_logging_to(path: str | Path, terminal_level: int = logging.ERROR):
    """Within the block, the ``distributed`` loggers of this process write WARNING and above to
    ``path`` (appended; its folder created) and their terminal handlers only ``terminal_level``
    and above; everything restored after.

    Parameters
    ----------
    path : str or Path
        The log file, usually :data:`CLUSTER_LOG` in the sweep's products folder.
    terminal_level : int
        ``logging`` level below which the terminal handlers stay silent.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    logger = logging.getLogger("distributed")
    handler = logging.FileHandler(path, encoding="utf-8")
    handler.setLevel(logging.WARNING)
    handler.setFormatter(logging.Formatter(_FORMAT))
    streams = [h for h in logger.handlers if isinstance(h, logging.StreamHandler)
               and not isinstance(h, logging.FileHandler)]
    saved_levels, saved_level = [h.level for h in streams], logger.level
    for h in streams:
        h.setLevel(max(h.level, terminal_level))
    logger.addHandler(handler)
    logger.setLevel(min(logger.getEffectiveLevel(), logging.WARNING))
    try:
        yield path
    finally:
        logger.removeHandler(handler)
        handler.close()
        logger.setLevel(saved_level)
        for h, level in zip(streams, saved_levels):
            h.setLevel(level)
