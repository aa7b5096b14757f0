"""Measured data: reading and checking a CSV file, quaternion sign continuity, noise per channel.

Format: CSV with a header row; the first column is ``time`` (s, increasing), then named channels
in SI units (see :mod:`riskassess.diagnosis.observation`); any subset of the known channels may be present,
empty cells are missing samples. Columns with other names are reported as unknown and not used.
"""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from math import comb
from pathlib import Path

import numpy as np

from riskassess.diagnosis.plants.channels import CHANNELS, QUATERNION
from riskassess.cases.inputs import MEASURED_FILE_LIMIT, read_text

#: Fewest samples a record must have: the noise estimate and a held-out part need a few dozen.
MIN_SAMPLES = 30
#: Difference orders tried by the noise estimate (white noise gives the same sigma at every order,
#: a smooth signal less the higher the order).
DIFFERENCE_ORDERS = range(1, 9)
#: Two successive orders within 5 % mean the signal no longer shows: a pure-noise estimate from
#: 600 samples scatters by ~3 % (1 / sqrt(2 n)).
PLATEAU = 1.05


class MeasuredDataError(ValueError):
    """A measured-data file that cannot be used; the message names the file, row or column."""


@dataclass
class MeasuredData:
    """A measured record.

    Attributes
    ----------
    path : Path
    time : (k,) float                     Sample times (s).
    values : dict[str, (k,) float]        Known channels (SI), NaN where a sample is missing.
    unknown : list[str]                   Columns that are not known channels (not used).
    noise : dict[str, float]              1-sigma noise per channel (channel units).
    noise_source : dict[str, str]         "given" or "estimated from successive differences".
    """

    path: Path
    time: np.ndarray
    values: dict
    unknown: list = field(default_factory=list)
    noise: dict = field(default_factory=dict)
    noise_source: dict = field(default_factory=dict)

    @property
    def channels(self) -> list[str]:
        return list(self.values)


def read_measured(path, noise: dict | None = None) -> MeasuredData:
    """Read and check ``path``; ``noise`` gives 1-sigma values (channel -> sigma) that override the
    estimate. Raises :class:`MeasuredDataError` naming the file and what is wrong.

    Parameters
    ----------
    path : str or Path
        Measured-data CSV file (format in the module doc).
    noise : dict of str to float, optional
        1-sigma noise per channel (channel units, :data:`riskassess.diagnosis.plants.channels.UNITS`).

    Returns
    -------
    measured : MeasuredData
        Times (s), known channels (SI; quaternion signs made continuous) and their noise.
    """
    path = Path(path)
    header, rows = _read_rows(path)
    data = _numeric(path, header, rows)
    time = data[:, 0]
    if not np.all(np.isfinite(time)) or np.any(np.diff(time) <= 0):
        raise MeasuredDataError(f"{path}: column 'time' must be finite and strictly increasing (s)")
    if time[0] < 0:
        raise MeasuredDataError(f"{path}: time starts at {time[0]:g} s; times are counted from the case's initial "
                                f"state (t = 0) and cannot be negative")
    known = [c for c in header[1:] if c in CHANNELS]
    values = {c: data[:, header.index(c)] for c in known}
    _check_channels(path, values)
    if any(c in values for c in QUATERNION):
        _continuous_quaternion(values)
    measured = MeasuredData(path, time, values, [c for c in header[1:] if c not in CHANNELS])
    _set_noise(measured, noise or {})
    return measured


def _read_rows(path: Path):
    """Header and data rows of a regular UTF-8 file (a byte-order mark is allowed) of at most
    MEASURED_FILE_LIMIT bytes."""
    try:
        text = read_text(path, MEASURED_FILE_LIMIT, "measured-data file", bom=True)
        rows = [r for r in csv.reader(io.StringIO(text, newline="")) if r and any(cell.strip() for cell in r)]
    except ValueError as exc:
        raise MeasuredDataError(str(exc)) from None
    except csv.Error as exc:   # a NUL byte, a cell beyond the csv module's field limit
        raise MeasuredDataError(f"{path}: not a CSV file ({exc})") from None
    if not rows:
        raise MeasuredDataError(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    if header[0] != "time":
        raise MeasuredDataError(f"{path}: the first column must be 'time' (s). Got '{header[0]}' instead")
    duplicates = sorted({h for h in header if header.count(h) > 1})
    if duplicates:
        raise MeasuredDataError(f"{path}: duplicate columns {duplicates}")
    if len(rows) - 1 < MIN_SAMPLES:
        raise MeasuredDataError(f"{path}: {len(rows) - 1} samples; at least {MIN_SAMPLES} are needed")
    return header, rows[1:]


def _numeric(path: Path, header, rows) -> np.ndarray:
    data = np.full((len(rows), len(header)), np.nan)
    for i, row in enumerate(rows):
        if len(row) != len(header):
            raise MeasuredDataError(f"{path}: row {i + 2} has {len(row)} cells, the header {len(header)}")
        for j, cell in enumerate(row):
            cell = cell.strip()
            if cell == "" or cell.lower() == "nan":
                continue
            try:
                data[i, j] = float(cell)
            except ValueError:
                raise MeasuredDataError(f"{path}: row {i + 2}, column '{header[j]}': '{cell[:40]}' is not a number") from None
            if not np.isfinite(data[i, j]):
                raise MeasuredDataError(f"{path}: row {i + 2}, column '{header[j]}': '{cell}' is not a finite number "
                                        f"(leave the cell empty, or write nan, for a missing sample)")
    return data


def _check_channels(path: Path, values: dict) -> None:
    if not values:
        raise MeasuredDataError(f"{path}: no known channel; known channels are {', '.join(CHANNELS)}")
    present = [c for c in QUATERNION if c in values]
    if present and len(present) != 4:
        raise MeasuredDataError(f"{path}: an attitude needs all of {', '.join(QUATERNION)}; got only {present}")
    for name, column in values.items():
        if np.isfinite(column).sum() < MIN_SAMPLES:
            raise MeasuredDataError(f"{path}: column '{name}' has {np.isfinite(column).sum()} samples; "
                                    f"at least {MIN_SAMPLES} are needed")
    if present:
        q = np.column_stack([values[c] for c in QUATERNION])
        norm = np.linalg.norm(q, axis=1)
        bad = np.isfinite(norm) & (np.abs(norm - 1.0) > 0.1)
        if bad.any():
            raise MeasuredDataError(f"{path}: the quaternion at row {int(np.flatnonzero(bad)[0]) + 2} has norm "
                                    f"{norm[bad][0]:.3g}; q_w..q_z must be a unit quaternion (scalar first)")


def _continuous_quaternion(values: dict) -> None:
    """Flip quaternion signs (q and -q are one attitude) so that successive samples stay close."""
    q = np.column_stack([values[c] for c in QUATERNION])
    last = None
    for i in range(len(q)):
        if not np.all(np.isfinite(q[i])):
            continue
        if last is not None and q[i] @ last < 0:
            q[i] = -q[i]
        last = q[i]
    for k, c in enumerate(QUATERNION):
        values[c] = q[:, k]


def difference_noise(column) -> float:
    """1-sigma white noise of a sampled channel (its units) from m-th successive differences.

    .. math:: \\sigma_m^2 = \\overline{(\\Delta^m y)^2} / \\binom{2m}{m}

    For white noise of variance sigma^2, Delta^m y has variance C(2m, m) sigma^2, at every order;
    a smooth signal's m-th difference shrinks like (omega dt)^m. The estimate is taken where it
    stops falling with the order (the signal is gone): the first m with sigma_m <= 1.05
    sigma_(m+1), averaged with sigma_(m+1); differences beyond 6 robust sigmas (outliers) are
    dropped. Missing samples are skipped.

    Parameters
    ----------
    column : (k,) float
        Uniformly sampled channel (its unit), NaN where missing.

    Returns
    -------
    sigma : float
        1-sigma noise (the channel's unit).
    """
    y = np.asarray(column, float)
    y = y[np.isfinite(y)]
    estimates = []
    for m in DIFFERENCE_ORDERS:
        if len(y) <= m + 10:
            break
        d = np.diff(y, n=m)
        robust = 1.4826 * np.median(np.abs(d - np.median(d)))
        d = d[np.abs(d) <= 6.0 * robust] if robust > 0 else d
        estimates.append(np.sqrt(np.mean(d * d) / comb(2 * m, m)))
    sigma = estimates[-1]
    for k in range(len(estimates) - 1):
        if estimates[k] <= PLATEAU * estimates[k + 1]:
            sigma = 0.5 * (estimates[k] + estimates[k + 1])
            break
    scale = max(np.ptp(y), np.abs(y).max(), 1e-300)
    # a noise-free record: floor at the double-precision resolution of the channel's values
    return float(max(sigma, 1e-12 * scale))


def _set_noise(measured: MeasuredData, given: dict) -> None:
    unknown = sorted(set(given) - set(CHANNELS))
    if unknown:
        raise MeasuredDataError(f"--noise: unknown channels {unknown}; known channels are {', '.join(CHANNELS)}")
    for name, column in measured.values.items():
        if name in given:
            if not (np.isfinite(given[name]) and given[name] > 0):
                raise MeasuredDataError(f"--noise {name}: sigma must be finite and > 0. Got {given[name]} instead")
            measured.noise[name], measured.noise_source[name] = float(given[name]), "given"
        else:
            measured.noise[name] = difference_noise(column)
            measured.noise_source[name] = "estimated from successive differences"
