"""Measured-data CSV files as :func:`riskassess.diagnosis.measured.read_measured` reads them
(``time`` then one column per channel), written atomically: synthetic records for tests,
benchmarks and users' trials."""
from __future__ import annotations

from pathlib import Path

from riskassess.products.results import atomic_write_bytes


def write_measured(path, time, values: dict) -> None:
    """Write a measured-data CSV (``time`` then the channels), atomically.

    Parameters
    ----------
    path : Path or str
        Destination ``.csv`` file; its folder must exist.
    time : (k,) float
        Sample times (s), written with 6 decimals.
    values : dict of str to (k,) float
        Channel name -> samples, in the channel's SI unit (as the diagnosis case names it),
        written with 9 significant digits.
    """
    names = list(values)
    lines = [",".join(["time"] + names)]
    for k, t in enumerate(time):
        lines.append(",".join([f"{t:.6f}"] + [f"{values[c][k]:.9g}" for c in names]))
    atomic_write_bytes(Path(path), ("\n".join(lines) + "\n").encode())
