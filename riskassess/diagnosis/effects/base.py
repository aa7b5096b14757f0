"""The one interface every candidate effect implements (one module per effect in this package).

An effect is a physical extension of the nominal model with named SI parameters. It changes
the model in one or more of four ways, each a pure function:

* ``law``: a numba load law ``law(t, x, p, env, load, xe, xe_rate)`` adding torques / forces to the
  fast model (:mod:`riskassess.diagnosis.plants.dynamics`), from the physical parameters ``p``, and the rates
  of its own states;
* ``modify_plant``: new mass properties or geometry (e.g. a CoM offset);
* ``sample_times`` / ``measure``: a sensor effect (time shift, bias) on the simulated channels;
* ``add_to_exudyn``: the same physics on the Exudyn builder (:mod:`riskassess.diagnosis.exudyn_model`),
  through user-function loads that call the same pure force law;
* ``towing_law``: the same physics on the towing model (:mod:`riskassess.diagnosis.plants.towing_dynamics`; the fast
  model and its Exudyn reference both call it), for effects that apply to the towing scenario.

An effect with states of its own (a damper's rotor rate, a stick anchor, a relaxing branch's
tension) declares them here and nowhere else: how many (``extra_states`` in the fast model,
``towing_extra_states`` in the towing model) and their values at t = 0 (:meth:`Effect.initial_extra_states`,
:meth:`Effect.initial_towing_states`). The models allocate the blocks after their base state when they
are built (:func:`riskassess.diagnosis.model.predict`; a pair's second block after the first's) and
hand each law its own block as ``xe`` (and, in the fast model, the same block of the derivative as
``xe_rate``), indexed from 0. Adding an effect with states is adding its file.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riskassess.diagnosis.plants.dynamics import no_load
from riskassess.diagnosis.plants.plant import Plant
from riskassess.diagnosis.plants.towing_dynamics import no_towing_load


@dataclass(frozen=True)
class Parameter:
    """A physical parameter: name, unit, meaning, a typical magnitude for this case (scale of
    the fit and of test draws) and hard bounds. ``log``: the fit works on ln(value / typical)
    (a positive parameter known to within orders of magnitude, or one of a product that the data
    see better than its factors; ``lower`` must then be > 0)."""

    name: str
    unit: str
    description: str
    typical: float
    lower: float
    upper: float
    log: bool = False


def switched_off(specs: list[Parameter]) -> np.ndarray:
    """The parameters at zero, clipped into their bounds (SI): the effect switched off.

    Parameters
    ----------
    specs : list of Parameter, length m
        The effect's parameters (:meth:`Effect.parameter_specs`).

    Returns
    -------
    values : (m,) float
        max(lower, min(0, upper)) per parameter, in each parameter's unit.
    """
    return np.clip(np.zeros(len(specs)), [p.lower for p in specs], [p.upper for p in specs])


class Effect:
    """Base class; subclasses set the class attributes and override what they change."""

    #: Stable id (used in case files, JSON output and docs).
    id: str = ""
    #: One line saying what the effect is.
    title: str = ""
    #: Scenario kinds it applies to.
    scenarios: tuple[str, ...] = ("tumbling_rigid", "hinged_appendage")
    #: It is seen only if one of these channels is measured.
    channels: tuple[str, ...] = ()
    #: What it reads of a circular orbit outside the towing scenario (e.g. ``"its altitude"``), for the
    #: reason it gives when the case has none; "" for an effect that needs no orbit.
    needs_orbit: str = ""
    #: Number of its own states in the fast model (its law's ``xe``; values at t = 0:
    #: :meth:`initial_extra_states`).
    extra_states: int = 0
    #: Number of its own states in the towing model (its towing law's ``xe``; values at t = 0:
    #: :meth:`initial_towing_states`).
    towing_extra_states: int = 0
    #: numba load law of the fast model (``no_load``: none).
    law = staticmethod(no_load)
    #: numba load law of the towing model (:mod:`riskassess.diagnosis.plants.towing_dynamics`; ``no_towing_load``: none).
    towing_law = staticmethod(no_towing_load)

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        """The effect's physical parameters for this case: names, SI units, typical sizes and bounds.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case (:mod:`riskassess.cases.diagnosis`); its plant sizes the typical
            values and bounds (inertia, hinge spring, orbit).
        channels : sequence of str, optional
            Measured channel names (:mod:`riskassess.diagnosis.plants.channels`); None: every channel. Only an
            effect whose parameters follow the channels (``sensor_bias``) reads it.

        Returns
        -------
        specs : list of Parameter, length m
            In the order of the effect's value vector ``values`` used by every other method.
        """
        raise NotImplementedError

    def not_applicable(self, case, channels) -> str | None:
        """Why the effect cannot be diagnosed for this case and these channels, or None.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; its ``kind`` must be one of :attr:`scenarios`.
        channels : sequence of str
            Measured channel names; at least one of :attr:`channels` must be among them.
            A circular orbit is needed outside the towing scenario if :attr:`needs_orbit` says so.

        Returns
        -------
        reason : str or None
            A sentence for the report, or None when the effect applies.
        """
        if self.needs_orbit and case.kind != "towing" and case.orbit.kind != "circular":
            return f"the case has no orbit ([orbit] kind = 'circular' with {self.needs_orbit})"
        if case.kind not in self.scenarios:
            return f"applies to the {' / '.join(self.scenarios)} scenario(s), not to '{case.kind}'"
        if self.channels and not set(self.channels) & set(channels):
            return f"needs one of the channels {', '.join(self.channels)}"
        return None

    def initial_extra_states(self, plant: Plant) -> np.ndarray:
        """Values at t = 0 of the effect's own states in the fast model (none by default).

        Parameters
        ----------
        plant : Plant
            The plant the law runs on (after :meth:`modify_plant`; SI, its initial state).

        Returns
        -------
        xe0 : (extra_states,) float
            In the layout and units the effect's :attr:`law` reads them.
        """
        return np.zeros(self.extra_states)

    def initial_towing_states(self, model) -> np.ndarray:
        """Values at t = 0 of the effect's own states in the towing model (none by default).

        Parameters
        ----------
        model : TowingModel
            The built lower-order towing model (:class:`multibody.towing.TowingModel`: initial state,
            ``omega_body`` (rad/s, body frames), ...).

        Returns
        -------
        xe0 : (towing_extra_states,) float
            In the layout and units the effect's :attr:`towing_law` reads them.
        """
        return np.zeros(self.towing_extra_states)

    def law_parameters(self, plant: Plant, values: np.ndarray) -> np.ndarray:
        """Parameters ``p`` of the numba law from the physical values (same order by default).

        Parameters
        ----------
        plant : Plant
            The plant the law runs on (after :meth:`modify_plant`).
        values : (m,) float
            Physical parameter values, SI, in the order of :meth:`parameter_specs`.

        Returns
        -------
        p : (j,) float
            The array handed to :attr:`law` as ``p`` (layout chosen by the effect).
        """
        return np.asarray(values, float)

    def towing_law_parameters(self, plant, values: np.ndarray) -> np.ndarray:
        """Parameters ``p`` of the towing law from the physical values (same order by default).

        Parameters
        ----------
        plant : TowingPlant
            The towing plant the law runs on (after :meth:`modify_plant`).
        values : (m,) float
            Physical parameter values, SI, in the order of :meth:`parameter_specs`.

        Returns
        -------
        p : (j,) float
            The array handed to :attr:`towing_law` as ``p`` (layout chosen by the effect).
        """
        return np.asarray(values, float)

    def modify_plant(self, plant: Plant, values: np.ndarray) -> Plant:
        """The plant with the effect's changes of mass properties or geometry (none by default).

        Parameters
        ----------
        plant : Plant or TowingPlant
            The nominal plant (SI; frames in :mod:`riskassess.diagnosis.plants.plant`,
            :mod:`riskassess.diagnosis.plants.towing_plant`).
        values : (m,) float
            Physical parameter values, SI, in the order of :meth:`parameter_specs`.

        Returns
        -------
        plant : Plant or TowingPlant
            A changed copy, or ``plant`` itself.
        """
        return plant

    def sample_times(self, times: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Times at which the model's state is read for samples tagged ``times`` (unchanged by default).

        Parameters
        ----------
        times : (k,) float
            Sample time tags (s, from the record's t = 0, non-decreasing).
        values : (m,) float
            Physical parameter values, SI, in the order of :meth:`parameter_specs`.

        Returns
        -------
        times : (k,) float
            Times (s) at which the simulated state is sampled.
        """
        return times

    def measure(self, outputs: dict, values: np.ndarray, names) -> dict:
        """The measured channels from the simulated ones (``names``: the parameter names).

        Parameters
        ----------
        outputs : dict of str to (k,) float
            Simulated channels by name, units and frames of :mod:`riskassess.diagnosis.plants.channels`.
        values : (m,) float
            Physical parameter values, SI, in the order of :meth:`parameter_specs`.
        names : sequence of str, length m
            The parameter names of ``values`` (a sensor effect finds its channel by name).

        Returns
        -------
        outputs : dict of str to (k,) float
            The channels as the sensors report them (unchanged by default).
        """
        return outputs

    def starts(self, specs: list[Parameter]) -> list[np.ndarray]:
        """Starting points of the fit (physical values): by default one, at a third of typical.

        Parameters
        ----------
        specs : list of Parameter, length m
            The effect's parameters (:meth:`parameter_specs`).

        Returns
        -------
        starts : list of (m,) float
            Starting values, each in the parameters' SI units.
        """
        return [np.array([p.typical / 3.0 if p.lower <= p.typical / 3.0 <= p.upper else 0.0 for p in specs])]

    def stiffness_rate(self, plant: Plant, specs: list[Parameter]) -> float:
        """Fastest decay rate (1/s) the law can add within its bounds; the fit's RK4 step stays below
        1.5 / rate (RK4 is stable up to 2.78 / rate).

        Parameters
        ----------
        plant : Plant
            The nominal plant.
        specs : list of Parameter
            The effect's parameters, whose bounds limit the rate.

        Returns
        -------
        rate : float
            (1/s); 0 when the law adds no stiff term.
        """
        return 0.0

    def parameter_free_stiffness_rate(self, plant: Plant) -> float:
        """Decay rate (1/s) the law adds whatever its parameters (a stick law's hold, for example);
        :func:`riskassess.diagnosis.model.predict` keeps its default RK4 step below 1.5 / rate.

        Parameters
        ----------
        plant : Plant
            The plant the law runs on.

        Returns
        -------
        rate : float
            (1/s); 0 when the law adds no stiff term.
        """
        return 0.0

    def add_to_exudyn(self, builder, values: np.ndarray, names) -> None:
        """Apply the effect to an Exudyn scenario builder before it is assembled.

        Parameters
        ----------
        builder : ExudynScenario
            The builder (:class:`riskassess.diagnosis.exudyn_model.ExudynScenario`); the effect registers
            body torques (N m, body frame), hinge torques (N m, about the hinge axis), CoM accelerations
            (m/s^2, I) or a damper through its ``add_*`` hooks.
        values : (m,) float
            Physical parameter values, SI, in the order of :meth:`parameter_specs`.
        names : sequence of str, length m
            The parameter names of ``values``.
        """


def own_states(effect: Effect, model, towing: bool = False) -> np.ndarray:
    """The effect's own states at t = 0, checked against the number it declares: the block the model
    allocates for it after its base state.

    Parameters
    ----------
    effect : Effect
        The effect (a pair: both blocks, the first effect's then the second's).
    model : Plant or TowingModel
        The plant of the fast model (after :meth:`Effect.modify_plant`), or the built towing model.
    towing : bool
        Whether the towing model's states are asked for.

    Returns
    -------
    xe0 : (e,) float
        :meth:`Effect.initial_extra_states` or :meth:`Effect.initial_towing_states`.

    Raises
    ------
    ValueError
        When the values do not match the declared ``extra_states`` / ``towing_extra_states``.
    """
    if towing:
        values, count, names = effect.initial_towing_states(model), effect.towing_extra_states, "towing_extra_states"
    else:
        values, count, names = effect.initial_extra_states(model), effect.extra_states, "extra_states"
    values = np.asarray(values, float).ravel()
    if values.size != count:
        raise ValueError(f"effect '{effect.id}': {values.size} initial state value(s) for its {count} declared "
                         f"{names}; the two must agree")
    return values


def torque_scale(plant: Plant) -> float:
    """Size of the hinge's torques (N m): the spring at the initial (or a 0.05 rad) angle, or the
    appendage's inertia times the square of the motion's fastest rate.

    Parameters
    ----------
    plant : Plant
        A hinged plant (stiffness N m/rad, hinge inertia kg m^2, rates rad/s).

    Returns
    -------
    scale : float
        (N m), at least 1e-6.
    """
    angle = max(abs(plant.hinge_angle0), 0.05)
    return max(plant.stiffness * angle, plant.hinge_inertia() * plant.rate_scale() ** 2 * angle, 1e-6)


def reference_angle(plant: Plant) -> float:
    """Hinge angle amplitude of the nominal motion (rad), at least 0.05 rad.

    Parameters
    ----------
    plant : Plant
        A hinged plant: initial hinge angle (rad) and rate (rad/s), spring (N m/rad).

    Returns
    -------
    angle : float
        max(|theta0|, |theta0'| / omega_hinge, 0.05) (rad).
    """
    omega = np.sqrt(plant.stiffness / plant.hinge_inertia()) if plant.stiffness > 0 else 0.0
    return max(abs(plant.hinge_angle0), abs(plant.hinge_rate0) / omega if omega else 0.0, 0.05)
