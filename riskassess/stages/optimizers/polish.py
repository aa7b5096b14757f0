"""Polish: a short pattern search from another optimizer's best point (``pso+pattern``), with
``optimizers.polish_delta`` as first step and ``optimizers.polish_evaluations`` as budget."""
from __future__ import annotations

from riskassess.stages.optimizers.pattern import restarted_pattern_search

NAME = "polish"


def search(problem, x0, settings):
    """:func:`~riskassess.stages.optimizers.pattern.restarted_pattern_search` with the polish settings.

    Parameters
    ----------
    problem : riskassess.stages.identify.TowingFit
        The bounded pymoo problem (4 variables).
    x0 : (4,) float
        Start point: another optimizer's best s.
    settings : identification.optimizers table
        ``polish_delta`` (first step, fraction of each bound range) and ``polish_evaluations``.

    Returns
    -------
    s : (4,) float
    cost : float
    """
    return restarted_pattern_search(problem, x0, settings, settings.polish_delta, settings.polish_evaluations)
