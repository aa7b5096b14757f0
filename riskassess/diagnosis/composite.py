"""Two catalog effects at once: the model that forward selection fits when one effect is not enough.

:class:`EffectPair` implements the :class:`~riskassess.diagnosis.effects.base.Effect` interface by
applying both effects: parameters concatenated (the first effect's, then the second's), plant
modifications, sample times and sensor models chained, and the two numba load laws called in turn
by one compiled law (:func:`paired_law`), so the pair runs in the same fast model, towing model and
Exudyn builder as a single effect. The pair's own states are both effects' blocks, the first's then
the second's (``extra_states`` and ``towing_extra_states`` add up); the pair law hands each law its
own block, so two effects with states pair like any others.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from riskassess.diagnosis.plants.dynamics import LAW_SIGNATURE
from riskassess.diagnosis.effects.base import Effect, Parameter, own_states, switched_off
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE

_COMPILED: dict = {}     # (law, law, splits, towing) -> compiled pair law: each pair compiles once per process


def can_pair(first: Effect, second: Effect) -> bool:
    """Whether the two effects can be fitted together: two different effects (each keeps its own states).

    Parameters
    ----------
    first, second : Effect
        Catalog effects.

    Returns
    -------
    ok : bool
    """
    return first.id != second.id


def paired_law(law_a, law_b, split: int, states_split: int = 0, towing: bool = False):
    """One compiled load law that calls ``law_a`` with ``p[:split]`` and its own states (the first
    ``states_split`` entries of the pair's block) and ``law_b`` with ``p[split:]`` and the rest (the
    fast model's signature, or the towing model's with ``towing``).

    Parameters
    ----------
    law_a, law_b : compiled function
        The two effects' laws (``LAW_SIGNATURE`` or ``TOWING_LAW_SIGNATURE``).
    split : int
        Length of ``law_a``'s parameter array.
    states_split : int
        Number of ``law_a``'s own states (its effect's ``extra_states`` or ``towing_extra_states``).
    towing : bool
        Whether the laws are towing laws.

    Returns
    -------
    law : compiled function
        Same signature; cached per (laws, splits, towing).
    """
    key = (law_a, law_b, split, states_split, towing)
    if key not in _COMPILED:
        if towing:
            @njit(TOWING_LAW_SIGNATURE)
            def law(t, x, v, p, env, state, step, load):
                law_a(t, x, v, np.ascontiguousarray(p[:split]), env, state[:states_split], step, load)
                law_b(t, x, v, np.ascontiguousarray(p[split:]), env, state[states_split:], step, load)
        else:
            @njit(LAW_SIGNATURE)
            def law(t, x, p, env, load, xe, xe_rate):
                law_a(t, x, np.ascontiguousarray(p[:split]), env, load, xe[:states_split], xe_rate[:states_split])
                law_b(t, x, np.ascontiguousarray(p[split:]), env, load, xe[states_split:], xe_rate[states_split:])
        _COMPILED[key] = law
    return _COMPILED[key]


class EffectPair(Effect):
    """``first`` and ``second`` together, for one case (parameter counts and law layouts are fixed
    by the case's plant and channels)."""

    linear = False

    def __init__(self, first: Effect, second: Effect, case, channels, plant, start_values=(None, None)):
        self.first, self.second = first, second
        self.id = f"{first.id}+{second.id}"
        self.title = f"{first.title}, and {second.title}"
        self.scenarios = tuple(s for s in first.scenarios if s in second.scenarios)
        self.extra_states = first.extra_states + second.extra_states
        self.towing_extra_states = first.towing_extra_states + second.towing_extra_states
        self._specs = (first.parameter_specs(case, channels), second.parameter_specs(case, channels))
        self._start_values = start_values
        self.n_first = len(self._specs[0])
        self._plant = plant

    @property
    def law(self):
        """The fast model's pair law (compiled on first use: ~1 s)."""
        split = len(self.first.law_parameters(self._plant, switched_off(self._specs[0])))
        return paired_law(self.first.law, self.second.law, split, self.first.extra_states)

    @property
    def towing_law(self):
        """The towing model's pair law (compiled on first use)."""
        split = len(self.first.towing_law_parameters(self._plant, switched_off(self._specs[0])))
        return paired_law(self.first.towing_law, self.second.towing_law, split, self.first.towing_extra_states,
                          towing=True)

    def initial_extra_states(self, plant):
        """Both effects' own states in the fast model, the first's block then the second's.

        Parameters
        ----------
        plant : Plant
            The plant the laws run on.

        Returns
        -------
        xe0 : (extra_states,) float
        """
        return np.r_[own_states(self.first, plant), own_states(self.second, plant)]

    def initial_towing_states(self, model):
        """Both effects' own states in the towing model, the first's block then the second's.

        Parameters
        ----------
        model : TowingModel
            The built towing model.

        Returns
        -------
        xe0 : (towing_extra_states,) float
        """
        return np.r_[own_states(self.first, model, towing=True), own_states(self.second, model, towing=True)]

    def _split(self, values):
        values = np.asarray(values, float)
        return values[:self.n_first], values[self.n_first:]

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """Both effects' parameters; a name the two share is prefixed with its effect's id.

        Parameters
        ----------
        case : DiagnosisCase
            Not read (the specs were made for the pair's case).
        channels : sequence of str, optional
            Not read.
        """
        a, b = self._specs
        shared = {p.name for p in a} & {p.name for p in b}
        rename = [lambda p, e=e: p if p.name not in shared else Parameter(f"{e.id}.{p.name}", p.unit, p.description,
                                                                           p.typical, p.lower, p.upper, p.log)
                  for e in (self.first, self.second)]
        return [rename[0](p) for p in a] + [rename[1](p) for p in b]

    def not_applicable(self, case, channels):
        """The first reason either effect gives, or None.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case.
        channels : sequence of str
            Measured channel names.
        """
        return self.first.not_applicable(case, channels) or self.second.not_applicable(case, channels)

    def law_parameters(self, plant, values):
        """Both laws' parameters, concatenated.

        Parameters
        ----------
        plant : Plant
            The plant the law runs on.
        values : (m_first + m_second,) float
            Both effects' physical values (SI), the first's then the second's.
        """
        a, b = self._split(values)
        return np.r_[self.first.law_parameters(plant, a), self.second.law_parameters(plant, b)]

    def towing_law_parameters(self, plant, values):
        """Both towing laws' parameters, concatenated.

        Parameters
        ----------
        plant : TowingPlant
            The towing plant the law runs on.
        values : (m_first + m_second,) float
            Both effects' physical values (SI), the first's then the second's.
        """
        a, b = self._split(values)
        return np.r_[self.first.towing_law_parameters(plant, a), self.second.towing_law_parameters(plant, b)]

    def modify_plant(self, plant, values):
        """The plant changed by the first effect, then by the second.

        Parameters
        ----------
        plant : Plant or TowingPlant
            The nominal plant.
        values : (m_first + m_second,) float
            Both effects' physical values (SI), the first's then the second's.
        """
        a, b = self._split(values)
        return self.second.modify_plant(self.first.modify_plant(plant, a), b)

    def sample_times(self, times, values):
        """The sample times shifted by the first effect, then by the second.

        Parameters
        ----------
        times : (k,) float
            Sample time tags (s).
        values : (m_first + m_second,) float
            Both effects' physical values (SI), the first's then the second's.
        """
        a, b = self._split(values)
        return self.second.sample_times(self.first.sample_times(times, a), b)

    def measure(self, outputs, values, names):
        """The channels measured through the first effect's sensor model, then the second's.

        Parameters
        ----------
        outputs : dict of str to (k,) float
            Simulated channels (channel units).
        values : (m_first + m_second,) float
            Both effects' physical values (SI), the first's then the second's.
        names : sequence of str
            Both effects' parameter names, in the same order.
        """
        a, b = self._split(values)
        names = list(names)
        return self.second.measure(self.first.measure(outputs, a, names[:self.n_first]), b, names[self.n_first:])

    def starts(self, specs):
        """Each effect's own starts, and its fitted values from its single fit when known (forward
        selection's step 1): the pair starts where each effect alone ended.

        Parameters
        ----------
        specs : list of Parameter
            Both effects' parameters (:meth:`parameter_specs`).

        Returns
        -------
        starts : list of (m_first + m_second,) float
            At most four combinations (SI).
        """
        a_specs, b_specs = specs[:self.n_first], specs[self.n_first:]
        firsts = [v for v in (self._start_values[0],) if v is not None] + self.first.starts(a_specs)
        seconds = [v for v in (self._start_values[1],) if v is not None] + self.second.starts(b_specs)
        return [np.r_[a, b] for a in firsts[:2] for b in seconds[:2]]

    def stiffness_rate(self, plant, specs):
        """The larger of the two effects' rates (1/s).

        Parameters
        ----------
        plant : Plant
            The nominal plant.
        specs : list of Parameter
            Both effects' parameters.

        Returns
        -------
        rate : float
            (1/s).
        """
        return max(self.first.stiffness_rate(plant, specs[:self.n_first]),
                   self.second.stiffness_rate(plant, specs[self.n_first:]))

    def parameter_free_stiffness_rate(self, plant):
        """The larger of the two effects' parameter-free rates (1/s).

        Parameters
        ----------
        plant : Plant
            The plant.

        Returns
        -------
        rate : float
            (1/s).
        """
        return max(self.first.parameter_free_stiffness_rate(plant), self.second.parameter_free_stiffness_rate(plant))

    def add_to_exudyn(self, builder, values, names):
        """Both effects on the Exudyn builder.

        Parameters
        ----------
        builder : ExudynScenario
            The scenario builder.
        values : (m_first + m_second,) float
            Both effects' physical values (SI), the first's then the second's.
        names : sequence of str
            Both effects' parameter names.
        """
        a, b = self._split(values)
        names = list(names)
        self.first.add_to_exudyn(builder, a, names[:self.n_first])
        self.second.add_to_exudyn(builder, b, names[self.n_first:])

