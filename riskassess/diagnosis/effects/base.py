"""The one interface every candidate effect implements (one module per effect in this package).

An effect is a physical extension of the nominal model with named SI parameters. It changes
the model in one or more of four ways, each a pure function:

* ``law``: a numba load law ``law(t, x, p, env, load)`` adding torques / forces / extra-state
  rates to the fast model (:mod:`riskassess.diagnosis.dynamics`), from the physical parameters ``p``;
* ``modify_plant``: new mass properties or geometry (e.g. a CoM offset);
* ``sample_times`` / ``measure``: a sensor effect (time shift, bias) on the simulated channels;
* ``add_to_exudyn``: the same physics on the Exudyn builder (:mod:`riskassess.diagnosis.exudyn_model`),
  through user-function loads that call the same pure force law;
* ``towing_law``: the same physics on the towing model (:mod:`riskassess.diagnosis.towing_dynamics`; the fast
  model and its Exudyn reference both call it), for effects that apply to the towing scenario.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riskassess.diagnosis.dynamics import no_load
from riskassess.diagnosis.plant import Plant
from riskassess.diagnosis.towing_dynamics import no_towing_load


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
    """The parameters at zero, clipped into their bounds (SI): the effect switched off."""
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
    #: Whether its laws use the models' extra-state slot (the fast model's X_E, the towing model's
    #: effect states): two such effects cannot be fitted together (riskassess.diagnosis.composite).
    extra_state: bool = False
    #: numba load law of the fast model (``no_load``: none).
    law = staticmethod(no_load)
    #: numba load law of the towing model (:mod:`riskassess.diagnosis.towing_dynamics`; ``no_towing_load``: none).
    towing_law = staticmethod(no_towing_load)

    def parameter_specs(self, case, channels=None) -> list[Parameter]:
        raise NotImplementedError

    def not_applicable(self, case, channels) -> str | None:
        """Why the effect cannot be diagnosed for this case and these channels, or None."""
        if case.kind not in self.scenarios:
            return f"applies to the {' / '.join(self.scenarios)} scenario(s), not to '{case.kind}'"
        if self.channels and not set(self.channels) & set(channels):
            return f"needs one of the channels {', '.join(self.channels)}"
        return None

    def law_parameters(self, plant: Plant, values: np.ndarray) -> np.ndarray:
        """Parameters ``p`` of the numba law from the physical values (same order by default)."""
        return np.asarray(values, float)

    def towing_law_parameters(self, plant, values: np.ndarray) -> np.ndarray:
        """Parameters ``p`` of the towing law from the physical values (same order by default)."""
        return np.asarray(values, float)

    def modify_plant(self, plant: Plant, values: np.ndarray) -> Plant:
        return plant

    def sample_times(self, times: np.ndarray, values: np.ndarray) -> np.ndarray:
        return times

    def measure(self, outputs: dict, values: np.ndarray, names) -> dict:
        """The measured channels from the simulated ones (``names``: the parameter names)."""
        return outputs

    def starts(self, specs: list[Parameter]) -> list[np.ndarray]:
        """Starting points of the fit (physical values): by default one, at a third of typical."""
        return [np.array([p.typical / 3.0 if p.lower <= p.typical / 3.0 <= p.upper else 0.0 for p in specs])]

    def stiffness_rate(self, plant: Plant, specs: list[Parameter]) -> float:
        """Fastest decay rate (1/s) the law can add within its bounds; the fit's RK4 step stays below
        1.5 / rate (RK4 is stable up to 2.78 / rate)."""
        return 0.0

    def parameter_free_stiffness_rate(self, plant: Plant) -> float:
        """Decay rate (1/s) the law adds whatever its parameters (a stick law's hold, for example);
        :func:`riskassess.diagnosis.model.predict` keeps its default RK4 step below 1.5 / rate."""
        return 0.0

    def add_to_exudyn(self, builder, values: np.ndarray, names) -> None:
        """Apply the effect to an Exudyn scenario builder before it is assembled."""


def torque_scale(plant: Plant) -> float:
    """Size of the hinge's torques (N m): the spring at the initial (or a 0.05 rad) angle, or the
    appendage's inertia times the square of the motion's fastest rate."""
    angle = max(abs(plant.hinge_angle0), 0.05)
    return max(plant.stiffness * angle, plant.hinge_inertia() * plant.rate_scale() ** 2 * angle, 1e-6)


def reference_angle(plant: Plant) -> float:
    """Hinge angle amplitude of the nominal motion (rad), at least 0.05 rad."""
    omega = np.sqrt(plant.stiffness / plant.hinge_inertia()) if plant.stiffness > 0 else 0.0
    return max(abs(plant.hinge_angle0), abs(plant.hinge_rate0) / omega if omega else 0.0, 0.05)
