"""Figures of `riskassess approach`: MU paths with the keep-out circle, thrust magnitudes and
angles, masses and mouth width. Shared by the output folder's PNGs and the report section."""
from __future__ import annotations

import numpy as np

from matplotlib.figure import Figure
from matplotlib.patches import Circle

from riskassess.products.plotting import legend, panels, plain, write_png


def trajectory_figure(answer: dict, arrays: dict):
    """MU paths (nodes and re-simulation), mouth segments every few nodes, the keep-out circle.

    Parameters
    ----------
    answer : dict
        The approach answer (``case``, ``final_time`` (s), ``fuel_kg``).
    arrays : dict of str to numpy.ndarray
        The approach arrays (``approach.npz``): ``unit_paths`` (2, 2, n) and ``resim_unit_paths``
        (2, 2, m) MU positions (MU, x/y, node or sample) (m, world frame), ``debris_center`` (2,) m
        world, ``keep_out_radius`` (m); with a 3-D replay, ``replay_mouth_edge`` (k, p, 3) m.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = Figure(figsize=(6.7, 4.2), layout="constrained")
    ax = fig.subplots()
    paths, fine = arrays["unit_paths"], arrays["resim_unit_paths"]
    for k, color in enumerate(("tab:blue", "tab:orange")):
        ax.plot(fine[k, 0], fine[k, 1], color=color, lw=1.0, label=f"MU{k + 1} (re-simulated)")
        ax.plot(paths[k, 0], paths[k, 1], ".", ms=2.5, color=color, label=f"MU{k + 1} collocation points")
    for j in range(0, paths.shape[2], max(1, paths.shape[2] // 12)):
        ax.plot(paths[:, 0, j], paths[:, 1, j], color="0.6", lw=0.6)
    ax.plot(*paths[:, :, -1].T, color="k", lw=1.2, label="net mouth at t_f")
    center, radius = arrays["debris_center"], float(arrays["keep_out_radius"])
    ax.add_patch(Circle(center, radius, color="tab:red", alpha=0.2, lw=0, label="keep-out circle"))
    ax.plot(*center, "+", color="tab:red")
    if "replay_unit_positions" in arrays:
        edge = arrays["replay_mouth_edge"][-1]
        ax.plot(edge[:, 0], edge[:, 1], "--", color="tab:green", label="3-D net mouth edge at t_f")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m, world)")
    ax.set_ylabel("y (m, world)")
    ax.set_title(f"{plain(answer['case'])}: t_f = {answer['final_time']:.4g} s, fuel {answer['fuel_kg']:.4g} kg")
    legend(ax)
    return fig


def controls_figure(answer: dict, arrays: dict):
    """Thrust magnitudes, thrust angles, and masses or mouth width over time.

    Parameters
    ----------
    answer : dict
        The approach answer (``kind``: ``rigid_rod`` or another model).
    arrays : dict of str to numpy.ndarray
        The approach arrays (``approach.npz``): ``t`` (n,) s and ``resim_t`` (m,) s,
        ``resim_controls`` (6, m) whose rows 0 and 1 are the thrust magnitudes (N),
        ``thrust_angles`` (2, n) rad, ``masses`` (2, n) kg, ``thrust_bounds`` (2,) N.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax_t, ax_a, ax_m) = panels(3, 1.6)
    t, rt = arrays["t"], arrays["resim_t"]
    for k, color in enumerate(("tab:blue", "tab:orange")):
        ax_t.plot(rt, arrays["resim_controls"][k], color=color, label=f"T{k + 1}")
        ax_a.plot(t, np.degrees(arrays["thrust_angles"][k]), ".", ms=2.5, color=color, label=f"theta{k + 1}")
        ax_m.plot(t, arrays["masses"][k], color=color, label=f"m{k + 1}")
    for bound in arrays["thrust_bounds"]:
        ax_t.axhline(bound, color="0.5", ls=":", lw=0.8)
    ax_t.set_ylabel("thrust (N)")
    ax_a.set_ylabel("angle (deg)")
    ax_a.set_title("thrust angles, [0, 360) deg" + (" from the rod, clockwise" if answer["kind"] == "rigid_rod"
                                                    else " from world x"))
    ax_m.set_ylabel("mass (kg)")
    for ax in (ax_t, ax_a, ax_m):
        legend(ax)
    return fig


def write_plots(out, answer: dict, arrays: dict) -> list[str]:
    """approach_trajectory.png and approach_controls.png into ``out``; returns their names.

    Parameters
    ----------
    out : Path
        The approach output folder (existing).
    answer : dict
        The approach answer.
    arrays : dict of str to numpy.ndarray
        The approach arrays (see :func:`trajectory_figure`, :func:`controls_figure`).
    """
    names = []
    for name, make in (("approach_trajectory.png", trajectory_figure), ("approach_controls.png", controls_figure)):
        write_png(make(answer, arrays), out / name, dpi=120)
        names.append(name)
    return names
