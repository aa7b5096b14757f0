"""Residual analysis: simulated against measured, per channel, normalized by the noise.

For each channel: RMS and mean of the normalized residual (1 and 0 for a right model and noise
level), whiteness (Ljung-Box), a linear trend, where in time the residual lives (RMS per tenth
of the record) and in frequency (Welch PSD: dominant frequency and its share of the power).
"""
from __future__ import annotations

import numpy as np
from scipy import signal, stats

from riskassess.diagnosis.plants.channels import QUATERNION

#: Ljung-Box lags: 20 samples (2 s at 10 Hz) cover the correlation of a slowly drifting residual.
LJUNG_BOX_LAGS = 20
#: Windows over which the residual's RMS is reported ("where in time").
TIME_WINDOWS = 10
#: A p-value below this counts as "not white" / "a trend" in the descriptions.
SIGNIFICANCE = 1e-3


def aligned_quaternion(model: dict, measured: dict) -> dict:
    """``model`` with its quaternion signs turned to the measured ones sample by sample.

    Parameters
    ----------
    model : dict of str to (k,) float
        Predicted channels.
    measured : dict of str to (k,) float
        Measured channels.

    Returns
    -------
    model : dict of str to (k,) float
        A copy with q_w..q_z negated where they point against the measured quaternion (unchanged
        without all four in both).
    """
    if not all(c in measured and c in model for c in QUATERNION):
        return model
    dot = sum(np.nan_to_num(model[c] * measured[c]) for c in QUATERNION)
    sign = np.where(dot < 0, -1.0, 1.0)
    return {**model, **{c: sign * model[c] for c in QUATERNION}}


def normalized_residuals(model: dict, measured: dict, noise: dict) -> dict:
    """(measured - model) / sigma per measured channel (NaN where a sample is missing).

    Parameters
    ----------
    model : dict of str to (k,) float
        Predicted channels (channel units).
    measured : dict of str to (k,) float
        Measured channels (channel units).
    noise : dict of str to float
        1-sigma noise per channel (channel units).

    Returns
    -------
    residuals : dict of str to (k,) float
        Per channel both have (-).
    """
    model = aligned_quaternion(model, measured)
    return {c: (measured[c] - model[c]) / noise[c] for c in measured if c in model}


def ljung_box(r, lags: int = LJUNG_BOX_LAGS) -> tuple[float, float]:
    """Ljung-Box statistic Q and its p-value (chi^2 with ``lags`` dof) of a series (NaNs dropped).

    Parameters
    ----------
    r : (k,) float
        Normalized residual (-), NaN where a sample is missing.
    lags : int
        Number of autocorrelation lags (at most a quarter of the samples).

    Returns
    -------
    q, p_value : float
    """
    r = np.asarray(r, float)
    r = r[np.isfinite(r)] - np.nanmean(r)
    n = len(r)
    lags = min(lags, n // 4)
    denominator = r @ r
    if n < 8 or denominator == 0:
        return 0.0, 1.0
    acf = np.array([r[:-k] @ r[k:] / denominator for k in range(1, lags + 1)])
    q = n * (n + 2) * np.sum(acf ** 2 / (n - np.arange(1, lags + 1)))
    return float(q), float(stats.chi2.sf(q, lags))


def trend(time, r) -> tuple[float, float]:
    """Slope of a straight line through the residual (1/s, normalized units) and its p-value
    (Spearman rank correlation with time: no assumption on the residual's distribution).

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    r : (k,) float
        Normalized residual (-), NaN where a sample is missing.

    Returns
    -------
    slope : float
        (sigma/s).
    p_value : float
    """
    ok = np.isfinite(r)
    slope = float(np.polyfit(time[ok], r[ok], 1)[0])
    return slope, float(stats.spearmanr(time[ok], r[ok]).pvalue)


def spectrum(time, r) -> dict:
    """Welch PSD of the residual (uniform sampling assumed at the median step): frequencies (Hz),
    PSD, the dominant frequency and the share of the power within +-1 bin of it.

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    r : (k,) float
        Normalized residual (-), NaN where a sample is missing.

    Returns
    -------
    spectrum : dict
        ``frequency_hz`` (Hz), ``psd`` (sigma^2/Hz), ``dominant_hz`` (Hz), ``dominant_share`` (-).
    """
    ok = np.isfinite(r)
    dt = float(np.median(np.diff(time)))
    segment = min(int(ok.sum()), 256)
    freq, psd = signal.welch(r[ok] - r[ok].mean(), fs=1.0 / dt, nperseg=segment)
    k = int(np.argmax(psd[1:]) + 1) if len(psd) > 1 else 0
    share = float(psd[max(k - 1, 0):k + 2].sum() / psd.sum()) if psd.sum() > 0 else 0.0
    return {"frequency_hz": freq, "psd": psd, "dominant_hz": float(freq[k]), "dominant_share": share}


def channel_report(time, r) -> dict:
    """Every figure of one channel's normalized residual ``r`` at ``time`` (s).

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    r : (k,) float
        Normalized residual (-), NaN where a sample is missing.

    Returns
    -------
    report : dict
        ``rms``, ``mean`` (sigma), Ljung-Box ``ljung_box_q`` and ``white_p``, ``trend_per_s``
        (sigma/s) and ``trend_p``, ``window_rms`` (sigma) and ``window_start_s`` (s),
        ``dominant_hz`` (Hz), ``dominant_share`` (-).
    """
    ok = np.isfinite(r)
    q, p_white = ljung_box(r)
    slope, p_trend = trend(time, r)
    windows = np.array_split(np.flatnonzero(ok), TIME_WINDOWS)
    spec = spectrum(time, r)
    return {"rms": float(np.sqrt(np.mean(r[ok] ** 2))), "mean": float(np.mean(r[ok])), "ljung_box_q": q,
            "white_p": p_white, "trend_per_s": slope, "trend_p": p_trend,
            "window_rms": [float(np.sqrt(np.mean(r[w] ** 2))) if len(w) else None for w in windows],
            "window_start_s": [float(time[w[0]]) if len(w) else None for w in windows],
            "dominant_hz": spec["dominant_hz"], "dominant_share": spec["dominant_share"]}


def describe(name: str, report: dict) -> str:
    """One sentence on where and how a channel's residual departs from noise.

    Parameters
    ----------
    name : str
        Channel name.
    report : dict
        Its :func:`channel_report`.

    Returns
    -------
    sentence : str
    """
    parts = [f"{name}: RMS {report['rms']:.2f} sigma, mean {report['mean']:+.2f} sigma"]
    parts.append("white" if report["white_p"] >= SIGNIFICANCE else f"not white (Ljung-Box p = {report['white_p']:.1e})")
    if report["trend_p"] < SIGNIFICANCE:
        parts.append(f"trend {report['trend_per_s']:+.3g} sigma/s")
    windows = [w for w in report["window_rms"] if w is not None]
    if windows and max(windows) > 1.5 * max(min(windows), 1e-12):
        k = int(np.argmax(report["window_rms"]))
        parts.append(f"largest from {report['window_start_s'][k]:.0f} s ({max(windows):.2f} sigma)")
    if report["dominant_share"] > 0.3:
        parts.append(f"{100 * report['dominant_share']:.0f} % of its power near {report['dominant_hz']:.3g} Hz")
    return ", ".join(parts)


def analyse(time, model: dict, measured: dict, noise: dict) -> dict:
    """Per channel: the normalized residual series and its report (see :func:`channel_report`).

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    model : dict of str to (k,) float
        Predicted channels (channel units).
    measured : dict of str to (k,) float
        Measured channels (channel units).
    noise : dict of str to float
        1-sigma noise per channel (channel units).

    Returns
    -------
    analysis : dict of str to dict
        Per channel: ``residual`` (k,) (-) and the report's figures.
    """
    residuals = normalized_residuals(model, measured, noise)
    return {c: {"residual": r, **channel_report(time, r)} for c, r in residuals.items()}
