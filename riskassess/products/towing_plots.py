"""Figures of the towing stages (PNG, written atomically): a tow's time series and the
identification's convergence and data-versus-fit comparison."""
from __future__ import annotations

from pathlib import Path

import numpy as np

import matplotlib
from matplotlib.figure import Figure

from riskassess.products.plotting import STYLE, legend, panels, plain, write_png


def _save(fig, path: Path) -> None:
    write_png(fig, path, dpi=130)


def _tow_panels(axes, s, label, style="-"):
    label = plain(label)
    t = s["time"]
    axes[0].plot(t, s["main_tether_tension"], style, label=f"{label} main tether")
    axes[0].plot(t, s["thrust"], style, color="0.5", lw=0.8, label=f"{label} thrust")
    axes[1].plot(t, np.linalg.norm(s["debris_com_inertial"] - s["chaser_com_inertial"], axis=1), style,
                 label=f"{label} chaser-debris".strip())
    axes[2].plot(t, np.linalg.norm(s["chaser_omega_body"], axis=1), style, label=f"{label} chaser")
    axes[2].plot(t, np.linalg.norm(s["debris_omega_body"], axis=1), style, label=f"{label} debris")


def tow_figure(series: dict, title: str, others: dict | None = None):
    """Main-tether tension and thrust, chaser-debris distance, angular rates against time;
    ``others`` (label -> series) are drawn dashed on the same axes (e.g. thrust laws compared).
    Call inside ``matplotlib.rc_context(STYLE)``; returns the matplotlib figure.

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        A tow's series: ``time`` (k,) s, ``main_tether_tension`` and ``thrust`` (k,) N,
        ``debris_com_inertial`` and ``chaser_com_inertial`` (k, 3) m (inertial frame),
        ``chaser_omega_body`` and ``debris_omega_body`` (k, 3) rad/s (body frames).
    title : str
        Figure title (a case name).
    others : dict of str to dict, optional
        Label -> series of the same form, drawn dashed.
    """
    fig, axes = panels(3, 1.8)
    _tow_panels(axes, series, "")
    for label, other in (others or {}).items():
        _tow_panels(axes, other, label, "--")
    axes[0].set_ylabel("force (N)")
    axes[0].set_title(f"{plain(title)}: main-tether tension and thrust")
    axes[1].set_ylabel("|r_D/C| (m)")
    axes[2].set_ylabel("|omega| (rad/s)")
    for ax in axes:
        legend(ax)
    return fig


def plot_tow(series: dict, path: Path, title: str, others: dict | None = None) -> None:
    """:func:`tow_figure` written to ``path`` as PNG.

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        A tow's series (see :func:`tow_figure`).
    path : Path
        Destination ``.png`` file; its folder must exist.
    title : str
        Figure title (a case name).
    others : dict of str to dict, optional
        Label -> series of the same form, drawn dashed.
    """
    with matplotlib.rc_context(STYLE):
        _save(tow_figure(series, title, others), path)


def plot_convergence(histories: dict, path: Path, title: str) -> None:
    """Best cost against evaluations for each optimizer run (label -> (evaluations, best cost)).

    Parameters
    ----------
    histories : dict of str to (array, array)
        Optimizer label -> (cost evaluations (n,) int, best cost so far (n,) float, > 0 for the log
        axis; the cost is dimensionless).
    path : Path
        Destination ``.png`` file; its folder must exist.
    title : str
        Figure title.
    """
    with matplotlib.rc_context(STYLE):
        fig, (ax,) = panels(1, 2.6, sharex=False)
        for label, (evaluations, best) in histories.items():
            ax.semilogy(evaluations, best, label=plain(label))
        ax.set_xlabel("cost evaluations (each: one simulation per spin rate)")
        ax.set_ylabel("best cost")
        ax.set_title(plain(title))
        legend(ax)
        _save(fig, path)


def plot_fit(data: dict, fitted: dict, path: Path, title: str) -> None:
    """One run's data (solid) against the identified model (dashed).

    Parameters
    ----------
    data : dict of str to numpy.ndarray
        The measured tow series (see :func:`tow_figure` for keys, shapes, units and frames).
    fitted : dict of str to numpy.ndarray
        The identified model's series, same form.
    path : Path
        Destination ``.png`` file; its folder must exist.
    title : str
        Figure title.
    """
    with matplotlib.rc_context(STYLE):
        fig, axes = panels(3, 1.8)
        _tow_panels(axes, data, "data")
        _tow_panels(axes, fitted, "identified", "--")
        axes[0].set_ylabel("force (N)")
        axes[0].set_title(plain(title))
        axes[1].set_ylabel("|r_D/C| (m)")
        axes[2].set_ylabel("|omega| (rad/s)")
        for ax in axes:
            legend(ax)
        _save(fig, path)


def plot_control(runs: dict, path: Path, title: str, target_elongation: float | None) -> None:
    """Thrust laws compared on one plant: main-tether tension, elongation (with the MRAC target dotted)
    and debris angular rate against time, one line per law; written to ``path`` as PNG.

    Parameters
    ----------
    runs : dict of str to dict
        Law name -> a tow's series: ``time`` (k,) s, ``main_tether_tension`` (k,) N,
        ``main_tether_elongation`` (k,) m, ``debris_omega_body`` (k, 3) rad/s (debris body frame).
    path : Path
        Output PNG.
    title : str
        Figure title (plant and spin rate).
    target_elongation : float or None
        The MRAC laws' target elongation (m), drawn dotted; None: not drawn.
    """
    with matplotlib.rc_context(STYLE):
        fig, axes = panels(3, 1.8)
        _control_panels(axes, runs, target_elongation)
        axes[0].set_title(plain(title))
        for ax in axes:
            legend(ax)
        _save(fig, path)


def _control_panels(axes, runs: dict, target_elongation: float | None) -> None:
    """Tension, elongation (target dotted) and debris rate of each law into three stacked axes."""
    for law, s in runs.items():
        t = s["time"]
        axes[0].plot(t, s["main_tether_tension"], lw=0.8, label=plain(law))
        axes[1].plot(t, s["main_tether_elongation"], lw=0.8, label=plain(law))
        axes[2].plot(t, np.rad2deg(np.linalg.norm(s["debris_omega_body"], axis=1)), lw=0.8, label=plain(law))
    if target_elongation is not None:
        axes[1].axhline(target_elongation, color="k", ls=":", lw=1.0, label="MRAC target")
    axes[0].set_ylabel("T_MT (N)")
    axes[1].set_ylabel("z (m)")
    axes[2].set_ylabel("|omega_D| (deg/s)")
    axes[2].set_xlabel("t (s)")


def plot_control_plants(plants: dict, path: Path, title: str, target_elongation: float | None) -> None:
    """Thrust laws on two (or more) plants side by side: one column per plant (main-tether tension,
    elongation with the MRAC target dotted, debris angular rate against time), rows on common y axes,
    so the lower-order and full-net results of one spin rate are read next to each other; PNG.

    Parameters
    ----------
    plants : dict of str to dict
        Plant name -> {law name -> a tow's series as in :func:`plot_control`}.
    path : Path
        Output PNG.
    title : str
        Figure title (spin rate, desired elongation).
    target_elongation : float or None
        The MRAC laws' target elongation (m), drawn dotted; None: not drawn.
    """
    with matplotlib.rc_context(STYLE):
        fig = Figure(figsize=(4.2 * len(plants), 6.2), layout="constrained")
        grid = fig.subplots(3, len(plants), sharex=True, sharey="row", squeeze=False)
        for column, (plant, runs) in enumerate(plants.items()):
            axes = list(grid[:, column])
            _control_panels(axes, runs, target_elongation)
            axes[0].set_title(plain(plant))
        grid[0, -1].legend(fontsize="small")
        fig.suptitle(plain(title))
        _save(fig, path)
