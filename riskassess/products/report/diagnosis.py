"""Report section and figures of `riskassess diagnose`: where the model departs from the data, the
candidates' evidence, the named cause and the held-out gain.

The same figure builders write the stage's PNG files and the report's embedded figures.
"""
from __future__ import annotations

import matplotlib


import numpy as np

from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.plotting import STYLE, legend, panels, plain, write_png
from riskassess.diagnosis.residuals import spectrum

#: Channels shown in the time-series figures: the ones with the largest residual before.
SHOWN_CHANNELS = 6


def _shown(answer: dict, arrays: dict) -> list[str]:
    channels = [str(c) for c in arrays["channels"]]
    rms = {c: answer["residual_figures"]["before"][c]["rms"] for c in channels}
    return sorted(channels, key=lambda c: -rms[c])[:SHOWN_CHANNELS]


def channels_figure(answer: dict, arrays: dict):
    """Measured, nominal-fit and chosen-model channels, with the train / held-out split.

    Parameters
    ----------
    answer : dict
        The diagnosis answer (``diagnosis.json``): ``residual_figures``, ``model``,
        ``split_time_s`` (s).
    arrays : dict of str to numpy.ndarray
        The diagnosis arrays (``diagnosis.npz``): ``time`` (k,) s, ``channels``, and per channel c
        ``measured/c``, ``nominal/c``, ``chosen/c`` (k,) in the channel's SI unit.

    Returns
    -------
    matplotlib.figure.Figure
    """
    shown = _shown(answer, arrays)
    fig, axes = panels(len(shown), 1.3)
    t = arrays["time"]
    for ax, c in zip(axes, shown):
        ax.plot(t, arrays[f"measured/{c}"], ".", ms=1.2, color="0.5", label="measured")
        ax.plot(t, arrays[f"nominal/{c}"], color="tab:blue", label="nominal (fitted)")
        if answer["model"] != "nominal":
            ax.plot(t, arrays[f"chosen/{c}"], "--", color="tab:red", label=answer["model"])
        ax.axvline(answer["split_time_s"], color="k", lw=0.8, ls=":")
        ax.set_ylabel(plain(c))
    axes[0].set_title("measured vs simulated (dotted line: end of the fitted part; the rest is held out)")
    legend(axes[0])
    return fig


def residuals_figure(answer: dict, arrays: dict):
    """Normalized residuals before (nominal) and after (chosen model), per shown channel.

    Parameters
    ----------
    answer : dict
        The diagnosis answer (``diagnosis.json``).
    arrays : dict of str to numpy.ndarray
        The diagnosis arrays: ``time`` (k,) s, ``channels``, and per channel c ``residual_before/c``
        and ``residual_after/c`` (k,), residual over the channel's noise sigma (-).

    Returns
    -------
    matplotlib.figure.Figure
    """
    shown = _shown(answer, arrays)
    fig, axes = panels(len(shown), 1.2)
    t = arrays["time"]
    for ax, c in zip(axes, shown):
        ax.plot(t, arrays[f"residual_before/{c}"], color="tab:blue", lw=0.6, label="nominal")
        if answer["model"] != "nominal":
            ax.plot(t, arrays[f"residual_after/{c}"], color="tab:red", lw=0.6, label=answer["model"])
        ax.axhspan(-2, 2, color="tab:green", alpha=0.08, lw=0)
        ax.axvline(answer["split_time_s"], color="k", lw=0.8, ls=":")
        ax.set_ylabel(f"{plain(c)} (sigma)")
    axes[0].set_title("residual / noise (green band: +-2 sigma, where white noise stays)")
    legend(axes[0])
    return fig


def spectrum_figure(answer: dict, arrays: dict):
    """Welch PSD of the worst channel's normalized residual, before and after.

    Parameters
    ----------
    answer : dict
        The diagnosis answer (``diagnosis.json``).
    arrays : dict of str to numpy.ndarray
        The diagnosis arrays: ``time`` (k,) s (evenly sampled) and the normalized residuals
        ``residual_before/c``, ``residual_after/c`` (k,) (-).

    Returns
    -------
    matplotlib.figure.Figure
    """
    worst = _shown(answer, arrays)[0]
    fig, (ax,) = panels(1, 2.2)
    t = arrays["time"]
    for key, color, label in (("residual_before", "tab:blue", "nominal"), ("residual_after", "tab:red", answer["model"])):
        if key == "residual_after" and answer["model"] == "nominal":
            continue
        s = spectrum(t, arrays[f"{key}/{worst}"])
        ax.semilogy(s["frequency_hz"][1:], s["psd"][1:], color=color, label=label)
    ax.axhline(2 * float(np.median(np.diff(t))), color="tab:green", ls="--", lw=0.8, label="white noise")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"PSD of {plain(worst)} (sigma^2/Hz)")
    ax.set_title(f"where in frequency the residual of {plain(worst)} lives")
    legend(ax)
    return fig


def candidates_figure(answer: dict):
    """BIC evidence of each candidate against the nominal model.

    Parameters
    ----------
    answer : dict
        The diagnosis answer: ``candidates`` (``id``, ``delta_bic``), ``cause``,
        ``decisive_delta_bic`` (-).

    Returns
    -------
    matplotlib.figure.Figure
    """
    rows = answer["candidates"]
    fig, (ax,) = panels(1, 0.25 * max(len(rows), 3) + 0.6, sharex=False)
    names = [r["id"] for r in rows][::-1]
    delta = [r["delta_bic"] for r in rows][::-1]
    ax.barh(names, delta, color=["tab:red" if r == answer["cause"] else "tab:gray" for r in names])
    ax.axvline(answer["decisive_delta_bic"], color="k", ls="--", lw=0.8, label="decisive")
    ax.set_xscale("symlog", linthresh=10)
    ax.set_xlabel("BIC(nominal) - BIC(candidate) (-)")
    ax.set_title("evidence of each candidate effect (training part)")
    legend(ax)
    return fig


FIGURES = (("diagnosis_channels.png", "fig-diagnosis-channels",
            "Measured channels and the fitted models; the dotted line ends the part the fit saw.", channels_figure),
           ("diagnosis_residuals.png", "fig-diagnosis-residuals",
            "Residuals normalized by the noise, before (nominal) and after (named cause).", residuals_figure),
           ("diagnosis_spectrum.png", "fig-diagnosis-spectrum",
            "Residual power spectrum of the worst channel.", spectrum_figure))


def _figures(answer: dict, arrays: dict):
    for name, fig_id, caption, build in FIGURES:
        yield name, fig_id, caption, build(answer, arrays)
    if answer["candidates"]:
        yield ("diagnosis_candidates.png", "fig-diagnosis-candidates",
               "Evidence of each candidate effect (symmetric log scale).", candidates_figure(answer))


def write_figures(out, answer: dict, arrays: dict) -> list[str]:
    """Write the PNG figures into ``out`` atomically; returns their names.

    Parameters
    ----------
    out : Path
        The diagnosis output folder (existing).
    answer : dict
        The diagnosis answer.
    arrays : dict of str to numpy.ndarray
        The diagnosis arrays (see :func:`channels_figure`).
    """
    names = []
    with matplotlib.rc_context(STYLE):
        for name, _, _, fig in _figures(answer, arrays):
            write_png(fig, out / name, dpi=150)
            names.append(name)
    return names


def _fmt(value, std=None) -> str:
    text = f"{value:.4g}"
    return text if std is None else f"{text} +- {std:.2g}"


def diagnosis_section(run) -> Section | None:
    """The diagnosis section: named cause, held-out prediction gain per channel, fitted parameters
    and the figures; None unless the folder holds ``diagnosis.json``.

    Parameters
    ----------
    run : RunFolder
        An output folder of ``riskassess diagnose`` (``diagnosis.json``, ``diagnosis.npz``).

    Returns
    -------
    Section or None
    """
    if not run.has("diagnosis.json"):
        return None
    answer = run.json("diagnosis.json")
    arrays = run.arrays("diagnosis.npz")
    cause = answer["cause"]
    kind = "alarm" if cause == "unexplained" else "info"
    confidence = "" if answer["confidence"] is None else f" (confidence {answer['confidence']:.3f})"
    blocks = [Note(f"Cause: {cause}{confidence}. {answer['statement']}.", kind)]
    blocks.append(Table(["channel", "held-out RMSE before", "after", "gain (%)"],
                        [[c, _fmt(answer["rmse_before"][c]), _fmt(answer["rmse_after"][c]),
                          f"{answer['gain_percent'][c]:.1f}"] for c in answer["rmse_before"]]
                        + [["all (sigma-weighted)", "", "", f"{answer['gain_percent']['overall']:.1f}"]],
                        "Prediction of the held-out data (SI units of each channel)"))
    if answer["parameters"]:
        blocks.append(Table(["parameter", "fitted", "unit"],
                            [[n, _fmt(p["value"], p["std"]), p["unit"]] for n, p in answer["parameters"].items()],
                            f"Fitted parameters of {answer['model']} (1 sigma)"))
    blocks.append(Table(["candidate", "delta BIC", "weight", "train RMS (sigma)", "held-out RMS (sigma)", "adequate"],
                        [[r["id"], f"{r['delta_bic']:.1f}", f"{r['weight']:.3g}", f"{r['train_rms_sigma']:.2f}",
                          f"{r['holdout_rms_sigma']:.2f}", "yes" if r["adequate"] else "no"]
                         for r in answer["candidates"]]
                        + [[k, "not applicable", "", "", "", v] for k, v in answer["not_applicable"].items()],
                        "Candidate effects, best first"))
    blocks.append(Note("Residuals before: " + "; ".join(answer["residuals_before"].values())))
    blocks.append(Note("Hint at the form of what the nominal model misses: " + answer["hint"]["statement"]))
    for _, fig_id, caption, fig in _figures(answer, arrays):
        blocks.append(Figure.from_matplotlib(fig_id, caption, fig))
    return Section("diagnosis", "Model diagnosis against measured data", blocks)
