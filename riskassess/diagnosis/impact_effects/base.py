"""The interface of an impact-model effect: one physical parameter of the impact case (contact law,
thread, net, launch) that differs from the case's value.

An effect names its parameter (:class:`riskassess.diagnosis.effects.base.Parameter`: SI unit, the
case's value as ``typical``, hard bounds, log or linear fit variable), the parameter's value in the
impact case (:meth:`ImpactEffect.case_value`; the nominal model) and the changes of the impact case
file that set it (:meth:`ImpactEffect.overrides`, dotted keys of the case file). The fit
(:mod:`riskassess.diagnosis.impact_fit`) runs the coupled impact simulation itself with those changes.
"""
from __future__ import annotations

import copy

import numpy as np

from riskassess.diagnosis.effects.base import Parameter


class ImpactEffect:
    """Base class; subclasses set the class attributes and override :meth:`parameter` and :meth:`overrides`."""

    #: Stable id (case files, JSON output, docs).
    id: str = ""
    #: One line saying what the effect is.
    title: str = ""
    #: Scenario kinds it applies to.
    scenarios: tuple[str, ...] = ("impact",)

    def parameter(self, impact_case) -> Parameter:
        """The effect's physical parameter for this impact case.

        Parameters
        ----------
        impact_case : riskassess.cases.impact.Case
            The validated impact case (its value sizes ``typical`` and the bounds).

        Returns
        -------
        Parameter
        """
        raise NotImplementedError

    def case_value(self, impact_case) -> float:
        """The parameter's value in the impact case (the nominal model), in its unit.

        Parameters
        ----------
        impact_case : riskassess.cases.impact.Case
            The validated impact case.

        Returns
        -------
        value : float
        """
        raise NotImplementedError

    def overrides(self, impact_case, value: float) -> dict:
        """The impact case's keys that set the parameter to ``value``.

        Parameters
        ----------
        impact_case : riskassess.cases.impact.Case
            The validated impact case.
        value : float
            The parameter's value (its unit).

        Returns
        -------
        overrides : dict of str to object
            Dotted case key -> value (SI, as the case file takes it).
        """
        raise NotImplementedError

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """The parameter as a one-element list, for a diagnosis case (the ``[[effects]]`` check of
        :mod:`riskassess.cases.diagnosis`).

        Parameters
        ----------
        case : ImpactDiagnosisCase
            The validated impact diagnosis case.
        channels : sequence of str, optional
            Unused (every impact effect is seen in the fitted channels).

        Returns
        -------
        specs : list of Parameter, length 1
        """
        return [self.parameter(case.impact_case)]

    def not_applicable(self, case, channels) -> str | None:
        """Why the effect cannot be diagnosed for this case, or None.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case.
        channels : sequence of str
            Measured channel names (unused).

        Returns
        -------
        reason : str or None
        """
        if case.kind not in self.scenarios:
            return f"applies to the {' / '.join(self.scenarios)} scenario, not to '{case.kind}'"
        return None


def relative_bounds(value: float, factor: float) -> tuple[float, float]:
    """(value / factor, value * factor): the range of a positive parameter known to within ``factor``.

    Parameters
    ----------
    value : float
        The case's value (> 0).
    factor : float
        (-), > 1.

    Returns
    -------
    lower, upper : float
    """
    return value / factor, value * factor


def case_with_overrides(raw: dict, overrides: dict) -> dict:
    """A copy of a parsed impact case file with dotted keys set (tables and leaves created where
    missing, e.g. ``net.thread.bending_rigidity``).

    Parameters
    ----------
    raw : dict
        The parsed case file; not changed.
    overrides : dict of str to object
        Dotted key -> value.

    Returns
    -------
    dict
    """
    out = copy.deepcopy(raw)
    for key, value in overrides.items():
        node = out
        parts = key.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value.item() if isinstance(value, np.generic) else value
    return out
