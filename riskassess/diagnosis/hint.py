"""A hint at the form of an unexplained residual: sparse regression over a generic term library.

Sequentially thresholded least squares (Brunton, Proctor & Kutz 2016, "SINDy", Algorithm 1) of a
channel's normalized residual on a library of time functions and the nominal model's own
channels: a few terms that carry most of the residual say whether it is a drift, an offset, an
oscillation at a model frequency, a growing oscillation, or proportional to a state.
"""
from __future__ import annotations

import numpy as np

#: Terms whose coefficient falls below this share of the largest are dropped (STLSQ threshold).
THRESHOLD = 0.1
#: STLSQ iterations (the active set settles in a few).
ITERATIONS = 10


def library(time, frequency_hz: float, model: dict) -> dict[str, np.ndarray]:
    """Candidate terms at ``time`` (s), each scaled to unit RMS: constant, drift, quadratic drift,
    oscillation at the residual's dominant frequency (plain and growing), and the nominal model's
    channels (centred).

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    frequency_hz : float
        The residual's dominant frequency (Hz); 0: no oscillation terms.
    model : dict of str to (k,) float
        The nominal model's channels (channel units).

    Returns
    -------
    terms : dict of str to (k,) float
        Term name -> values scaled to unit RMS (-); constant terms other than "1" dropped.
    """
    t = (time - time[0]) / max(time[-1] - time[0], 1e-12)
    phase = 2.0 * np.pi * frequency_hz * (time - time[0])
    terms = {"1": np.ones_like(t), "t": t, "t^2": t * t}
    if frequency_hz > 0:
        terms.update({f"sin({frequency_hz:.3g} Hz)": np.sin(phase), f"cos({frequency_hz:.3g} Hz)": np.cos(phase),
                      f"t sin({frequency_hz:.3g} Hz)": t * np.sin(phase), f"t cos({frequency_hz:.3g} Hz)": t * np.cos(phase)})
    for name, values in model.items():
        terms[name] = values - np.mean(values)
    return {k: v / max(np.sqrt(np.mean(v * v)), 1e-300) for k, v in terms.items() if np.ptp(v) > 0 or k == "1"}


def sparse_terms(residual, terms: dict) -> list[dict]:
    """STLSQ fit ``residual ~ sum c_k term_k``; returns the kept terms with their coefficient
    (normalized units) and the share of the residual's variance they explain together.

    Parameters
    ----------
    residual : (k,) float
        Normalized residual (-), NaN where missing.
    terms : dict of str to (k,) float
        The library (:func:`library`), unit RMS (-).

    Returns
    -------
    kept : list of dict
        ``term``, ``coefficient`` (sigma) and ``explained_share`` (-), largest coefficient first.
    """
    ok = np.isfinite(residual)
    names = list(terms)
    theta = np.column_stack([terms[n][ok] for n in names])
    y = residual[ok]
    active = np.ones(len(names), bool)
    coef = np.zeros(len(names))
    for _ in range(ITERATIONS):
        coef[:] = 0.0
        coef[active] = np.linalg.lstsq(theta[:, active], y, rcond=None)[0]
        keep = np.abs(coef) >= THRESHOLD * np.abs(coef).max()
        if np.array_equal(keep, active):
            break
        active = keep
    explained = 1.0 - np.var(y - theta @ coef) / max(np.var(y) + np.mean(y) ** 2, 1e-300)
    order = np.argsort(-np.abs(coef))
    return [{"term": names[k], "coefficient": float(coef[k]), "explained_share": float(explained)}
            for k in order if active[k] and coef[k] != 0.0]


def describe_terms(channel: str, kept: list[dict]) -> str:
    """One sentence naming the largest kept terms of a channel's residual.

    Parameters
    ----------
    channel : str
        Channel name.
    kept : list of dict
        :func:`sparse_terms`.

    Returns
    -------
    sentence : str
    """
    if not kept:
        return f"{channel}: no library term carries the residual"
    terms = " + ".join(f"{k['coefficient']:+.2g} {k['term']}" for k in kept[:4])
    return f"{channel} residual ~ {terms} (sigma units; {100 * kept[0]['explained_share']:.0f} % of its power)"
