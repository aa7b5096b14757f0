"""The interface every optimizer of the towing identification implements (one module each in
:mod:`riskassess.stages.optimizers`)."""
from __future__ import annotations

from typing import Protocol

import numpy as np


class Optimizer(Protocol):
    """An optimizer: a module of :mod:`riskassess.stages.optimizers` defines

    Attributes
    ----------
    NAME : str
        The name a case (``identification.searches``) and the CLI (``--optimizers``) use.
    """

    NAME: str

    def search(self, problem, x0, settings) -> tuple[np.ndarray, float]:
        """Minimize the bounded pymoo ``problem`` from ``x0``.

        Parameters
        ----------
        problem : riskassess.stages.identify.TowingFit
            The bounded pymoo problem (4 variables: s = [log10 k_ST, l_ST0 (m), log10 c_ST, m_P/m_net]).
        x0 : (4,) float
            Start point (an optimizer that spreads its own start over the bounds may ignore it).
        settings : riskassess.cases.towing.Optimizers
            The case's ``identification.optimizers`` table.

        Returns
        -------
        s : (4,) float
            The best point found.
        cost : float
            Its cost.
        """
