"""Is a numba kernel already compiled in its on-disk cache (``@njit(cache=True)``)?

The first run after an install (or after a kernel's source changed) compiles the force kernels,
about 30 s on one core, before the first step; later runs load them from ``__pycache__`` in well
under a second. The application layer asks :func:`compiled_on_disk` before a run to announce the
wait instead of sitting silent at t = 0.
"""
from __future__ import annotations


def compiled_on_disk(dispatcher) -> bool:
    """``dispatcher`` (an ``@njit(cache=True)`` function) has a cached compilation for its current
    source on this CPU: the same index key numba looks up before compiling (signature, CPU name and
    features, hash of the bytecode and closure). False for a function without a disk cache.

    Notes
    -----
    Reads numba's cache index only (``FunctionCache._cache_file._load_index``, numba 0.60 to 0.68);
    an internal API, so any error reads as "not compiled": at worst the announcement is shown once
    too often.
    """
    cache = getattr(dispatcher, "_cache", None)
    cache_file = getattr(cache, "_cache_file", None)
    if cache_file is None:
        return False
    try:
        index = cache_file._load_index()
        codegen = dispatcher.targetctx.codegen()
        return any(cache._index_key(key[0], codegen) in index for key in index)
    except Exception:  # noqa: BLE001 -- numba internals changed: say "not compiled"
        return False


def all_compiled_on_disk(dispatchers) -> bool:
    """Every one of ``dispatchers`` is :func:`compiled_on_disk`."""
    return all(compiled_on_disk(d) for d in dispatchers)
