"""Is a judged peak reproducible, or one draw of a chaotic capture?

A net capture is sensitive to its initial state: runs whose launch speeds differ by 1e-7 (far below any
physical uncertainty) follow each other through the first impact and then part, and the late strikes of
the net are different events (docs/structures.md, "Are the judged peaks converged?"). A peak before the
runs part is a deterministic result that converges with the numerics; a peak after it is one sample of a
distribution, which only many draws describe (``assess --monte-carlo``). This module finds when runs part
and labels a run's peaks against a twin run.
"""
from __future__ import annotations

import numpy as np

#: Runs are "together" while their peaks so far agree within this fraction (the convergence tolerance of
#: the judged peaks, issue 23).
REPRODUCIBLE_TOLERANCE = 0.05
#: Relative launch-speed offset of a twin run: far below any physical uncertainty, far above rounding.
TWIN_OFFSET = 1e-7


def parting_time(time, runs, tolerance: float = REPRODUCIBLE_TOLERANCE) -> float:
    """When runs of one demand part (s): the first sample at which their peaks so far (running maxima)
    spread by more than ``tolerance`` of the median (max - min); ``inf`` if they never do. Before it all
    runs' peaks agree within the tolerance (a phase drift of a ringing load that leaves its peaks
    alone does not count).

    Parameters
    ----------
    time : (k,) float
        Sample times (s), shared by the runs.
    runs : sequence of (k,) float
        The demand of each run (any unit), at least two.
    tolerance : float
        Relative agreement of the peaks so far (-).

    Returns
    -------
    float
        Time of the first sample at which the runs' peaks so far disagree (s), or ``inf``.
    """
    running = np.maximum.accumulate(np.asarray(runs, float), axis=1)
    spread = running.max(axis=0) - running.min(axis=0)
    apart = np.flatnonzero(spread > tolerance * np.maximum(np.abs(np.median(running, axis=0)), 1e-300))
    return float(np.asarray(time)[apart[0]]) if apart.size else float("inf")


def twin_label(time, demand, twin_demand, skip_until: float) -> dict:
    """Whether a run's judged peak is reproduced by its twin: the peak lies before the two runs' judged
    peaks so far part.

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    demand, twin_demand : (k,) float
        The judged demand of the run and of its twin (same unit).
    skip_until : float
        Loads before this time are not judged (s).

    Returns
    -------
    dict
        ``reproduced`` (bool), ``parting_time_s`` (s; None when the runs never part), ``twin_peak`` (the
        twin's judged peak) and ``window`` ("deterministic" or "chaotic").
    """
    time = np.asarray(time, float)
    judged = time >= skip_until
    t, a, b = time[judged], np.asarray(demand, float)[judged], np.asarray(twin_demand, float)[judged]
    parting = parting_time(t, [a, b])
    peak_time = t[int(np.argmax(a))]
    reproduced = bool(peak_time < parting)
    return {"reproduced": reproduced, "parting_time_s": None if np.isinf(parting) else parting,
            "twin_peak": float(b.max()), "window": "deterministic" if reproduced else "chaotic"}
