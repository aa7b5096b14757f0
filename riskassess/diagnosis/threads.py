"""One BLAS thread per process during the fits.

The candidates are fitted in parallel worker processes, one per core; OpenBLAS threads on top of
them oversubscribe the cores, and its spinning threads then make the optimizer's small dense
algebra crawl: the SVD of a 5000 x 17 Jacobian took 0.65 s with 2 OpenBLAS threads on a busy
2-core machine against 0.018 s with one. There is no threadpoolctl here, so the OpenBLAS copies
loaded by numpy and scipy are found in the process's memory map (Linux) and told to use one thread;
elsewhere nothing changes.
"""
from __future__ import annotations

import ctypes
from pathlib import Path

_SETTERS = ("scipy_openblas_set_num_threads64_", "scipy_openblas_set_num_threads", "openblas_set_num_threads64_",
            "openblas_set_num_threads")


def single_threaded_blas() -> int:
    """Set every loaded OpenBLAS to one thread; returns how many libraries were set."""
    import scipy.linalg  # noqa: F401  (load scipy's own OpenBLAS too)

    maps = Path("/proc/self/maps")
    if not maps.is_file():
        return 0
    paths = {line.split()[-1] for line in maps.read_text().splitlines() if "openblas" in line.lower()}
    count = 0
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for name in _SETTERS:
            if hasattr(lib, name):
                getattr(lib, name)(1)
                count += 1
                break
    return count
