"""Shared look of the report's figures: sizes, fonts, time axes, allowable bands, release marks.

Section builders run inside ``matplotlib.rc_context(STYLE)`` (see :mod:`.report.document`). Figures are
:class:`matplotlib.figure.Figure` objects rendered by Agg on save, never pyplot figures: writing a
product neither needs a display nor changes the backend of the user's session (a notebook keeps
its inline plots).
"""
from __future__ import annotations

import io
from pathlib import Path

from matplotlib.figure import Figure

from riskassess.products.results import atomic_write_bytes

#: Figure width fits an A4 page with 2 cm margins (17 cm); fonts stay readable at that size.
WIDTH_IN = 6.7
STYLE = {"font.size": 8.5, "axes.titlesize": 9, "axes.labelsize": 8.5, "legend.fontsize": 7.5,
         "xtick.labelsize": 8, "ytick.labelsize": 8, "axes.grid": True, "grid.alpha": 0.3, "lines.linewidth": 1.0,
         "legend.framealpha": 0.85}
COMPONENT_COLORS = ("tab:blue", "tab:orange", "tab:green")


def plain(text) -> str:
    """User text (a case, body, joint, location or channel name) as a literal matplotlib label.

    Matplotlib reads a string with an even number of unescaped ``$`` as math text (``$x^{$`` stops
    the figure with a ParseException) and hides legend entries whose label starts with ``_``.
    Every ``$`` is escaped (outside math text a ``\\$`` shows as ``$``, and a backslash is literal),
    and a leading ``_`` gets a space before it. Every plot passes user text through this helper.

    Parameters
    ----------
    text : object
        User text; converted with ``str``.
    """
    text = str(text).replace("$", r"\$")
    return f" {text}" if text.startswith("_") else text


def png_bytes(fig, dpi: float) -> bytes:
    """Render a matplotlib figure as PNG at ``dpi`` (dots per inch).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : float
        Resolution (dots per inch).
    """
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def write_png(fig, path, dpi: float) -> None:
    """Render a figure as PNG and write it to ``path`` atomically (a reader never sees half a file).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : Path or str
        Destination ``.png`` file; its folder must exist.
    dpi : float
        Resolution (dots per inch).
    """
    atomic_write_bytes(Path(path), png_bytes(fig, dpi))


def panels(n: int, height_in: float = 2.0, sharex: bool = True):
    """A figure of ``n`` stacked panels sharing the time axis; returns (fig, list of axes).

    Parameters
    ----------
    n : int
        Number of panels.
    height_in : float
        Height of each panel (inch).
    sharex : bool
        Panels share the x axis (labelled "time (s)" on the lowest).
    """
    fig = Figure(figsize=(WIDTH_IN, 0.5 + height_in * n), layout="constrained")
    axes = fig.subplots(n, 1, sharex=sharex, squeeze=False)
    axes[-1, 0].set_xlabel("time (s)")
    return fig, list(axes[:, 0])


def legend(ax) -> None:
    """Legend outside the axes, on the right, so it never hides a curve.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes whose labelled artists go in the legend.
    """
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def shade_not_judged(ax, until: float) -> None:
    """Grey band over the initial transient whose loads are not judged (s).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes with time (s) on x.
    until : float
        End of the transient (s); nothing is drawn when <= 0.
    """
    if until > 0:
        ax.axvspan(0.0, until, color="0.85", alpha=0.6, lw=0, label=f"not judged (< {until:g} s)")


def mark_release(ax, time: float, label: str | None = "release") -> None:
    """Dotted red vertical line at the time a location released.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes with time (s) on x.
    time : float
        Release time (s).
    label : str, optional
        Legend label; None for no legend entry.
    """
    ax.axvline(time, color="tab:red", ls=":", lw=1.2, label=label)


def allowable_band(ax, low: float, high: float, decisive: float, scale: float = 1.0, unit: str = "") -> None:
    """Allowable range (shaded) and the value that decides pass/fail (dashed), in plot units.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes with the demand on y, in plot units.
    low, high : float
        Ends of the allowable range, SI.
    decisive : float
        The allowable that decides pass / fail, SI.
    scale : float
        Factor from SI to plot units (e.g. 1e-6 for Pa to MPa).
    unit : str
        Plot unit shown in the legend.
    """
    if high > low:
        ax.axhspan(low * scale, high * scale, color="tab:red", alpha=0.12, lw=0,
                   label=f"allowable {low * scale:.4g}-{high * scale:.4g} {unit}")
    ax.axhline(decisive * scale, color="tab:red", ls="--", lw=1.0, label=f"decisive {decisive * scale:.4g} {unit}")
