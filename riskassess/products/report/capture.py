"""Report sections that show the capture in 3-D and judge the net itself: rendered snapshots at the
instants that matter, and the thread tensions against the thread's breaking load."""
from __future__ import annotations

import base64

import numpy as np

from riskassess.products.report.blocks import FIGURE_DPI, Figure, Note, Section, Table
from riskassess.products.plotting import WIDTH_IN, legend, mark_release, panels
from riskassess.products.results import RunFolder
from riskassess.products.view.products import ANIMATION, VIEWER
from riskassess.products.view.render import snapshots_png
from riskassess.products.view.scene import scene_of
from structures.net_threads import net_integrity

#: Threads listed by name in the integrity table at most (the rest are counted).
MAX_LISTED_THREADS = 20


def capture_section(run: RunFolder) -> Section:
    """Snapshots of net and debris (LVLH, m) at first contact, peak load, each release and the end,
    with the list of instants and a pointer to the animation and the viewer.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``net.npz``, ``timeseries.npz``, ``bodies.npz``).

    Returns
    -------
    Section
    """
    scene = scene_of(run)
    instants = scene.instants()
    png = snapshots_png(scene, instants, WIDTH_IN, FIGURE_DPI)
    return Section("capture", "The capture in 3-D", [
        Figure("fig-capture", "The net and the debris at first contact, peak contact load, each release and the "
               "end of the run (LVLH, m; the view is the same in every panel). Threads coloured by tension "
               "(one scale for all panels, slack: darkest; the top colour from the 99.5th percentile of the "
               "pulling threads up); debris bodies grey, released pieces cyan; bullets black.", base64.b64encode(png).decode("ascii")),
        Table(["instant", "snapshot time (s)"], [[i.label, f"{i.time:.3f}"] for i in instants],
              "Instants shown (the net snapshot at or just after each)"),
        Note(f"Next to this report: {ANIMATION} (the capture as an animation) and {VIEWER} (interactive: scrub "
             f"time, rotate, toggle net, bodies and contact forces; opens offline in any browser)."),
    ])


def _thread_name(scene, t: int) -> str:
    a, b = scene.threads[t]
    first_bullet = scene.positions.shape[1] - scene.n_bullets
    kind = "bullet tether" if max(a, b) >= first_bullet else "thread"
    return f"{kind} {a}-{b}"


def net_integrity_section(run: RunFolder) -> Section:
    """Highest and median thread tension (N) at the net snapshots against the thread's breaking load
    (``net.thread.breaking_load``, N, when the case gives it), and the threads that reach it.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``net.npz``, ``case.json``).

    Returns
    -------
    Section
    """
    scene = scene_of(run)
    thread = run.key(run.case, "net", "thread")
    integrity = net_integrity(scene.tension, scene.time, thread.get("breaking_load"))
    t = scene.time
    fig, (ax,) = panels(1, 2.2)
    ax.plot(t, scene.tension.max(axis=1), color="k", label="highest thread tension")
    ax.plot(t, np.median(scene.tension, axis=1), color="tab:blue", lw=0.8, label="median thread tension")
    if integrity.assessed:
        ax.axhline(integrity.breaking_load, color="tab:red", ls="--", label=f"breaking load "
                   f"{integrity.breaking_load:.4g} N")
    for release in sorted(set(scene.released_from[np.isfinite(scene.released_from)])):
        mark_release(ax, release, "release")
    ax.set_ylabel("tension (N)")
    ax.set_title("thread tension at the net snapshots")
    legend(ax)
    top = int(integrity.peak_tension.argmax())
    rows = [["highest peak tension (N)", f"{integrity.peak_tension[top]:.4g}"],
            ["at (s)", f"{integrity.peak_time[top]:.3f}"],
            ["in", _thread_name(scene, top)],
            ["breaking load of a thread (N)", f"{integrity.breaking_load:.4g}" if integrity.assessed
             else "not given"],
            ["margin of safety (-)", "-" if integrity.margin_of_safety is None
             else f"{integrity.margin_of_safety:.3g}"],
            ["threads at or over the breaking load", str(len(integrity.over)) if integrity.assessed
             else "not assessed"]]
    blocks = [Figure.from_matplotlib("fig-net-tension", "Highest and median tension over the net's threads at "
                                     "each net snapshot (tension-only Kelvin-Voigt law of the simulation); a "
                                     "peak between snapshots is not seen.", fig),
              Table(["quantity", "value"], rows, "Net integrity")]
    if not integrity.assessed:
        blocks.append(Note("Net integrity not assessed: the case gives no breaking load of the thread. Add "
                           "net.thread.breaking_load (N) to the case (docs/case-format.md) to judge it.", "warning"))
    elif len(integrity.over):
        listed = integrity.over[:MAX_LISTED_THREADS]
        blocks.append(Note(f"NET DAMAGE: {len(integrity.over)} thread(s) reach the breaking load.", "alarm"))
        blocks.append(Table(["thread (nodes)", "peak tension (N)", "at (s)"],
                            [[_thread_name(scene, k), f"{integrity.peak_tension[k]:.4g}",
                              f"{integrity.peak_time[k]:.3f}"] for k in listed],
                            "Threads at or over the breaking load" + (
                                f" (the {len(listed)} highest of {len(integrity.over)})"
                                if len(integrity.over) > len(listed) else ""),
                            alarm_rows=set(range(len(listed)))))
    else:
        blocks.append(Note("Every thread holds: no sampled tension reaches the breaking load."))
    return Section("net-integrity", "Net threads: tension and integrity", blocks)
