"""Case files of `riskassess approach`: the net approach with two maneuverable units (MUs).

Seed paper: Liu & Poddar, "Space debris capturing tether-net system simplified as a 2-D
problem" (``maneuverable-units-2d-guidance``). SI units; positions in the paper's planar
world frame ("world", x-y), the debris centre fixed in it. ``model.kind`` picks the case study:
``rigid_rod`` (case study 1, eqs. 1-8) or ``independent_units`` (case study 2, eqs. 9-19);
``objective.kind`` picks ``min_fuel`` (fixed final time), ``min_time`` or ``combined``.
"""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field, model_validator

from riskassess.cases.impact import NonNegative, Positive, Strict
from riskassess.cases.inputs import KIND_NOTE, CaseName, Text

Vector2 = Annotated[list[float], Field(min_length=2, max_length=2)]


class RigidRod(Strict):
    kind: Literal["rigid_rod"]
    mass: Positive = Field(description="Mass of one MU, constant (kg); the paper's case study 1 gives none.")
    length: Positive = Field(description="Length L of the rigid massless rod between the MUs (m).")
    fuel_rate: NonNegative = Field(0.0014, description="Fuel mass per thrust impulse k (kg/(N s)); the rod model "
                                                       "keeps its mass, k only reports the fuel k*integral(F1+F2).")
    com_position: Vector2 = Field(description="Initial centre of mass (x_com, y_com), world frame (m).")
    rod_angle: float = Field(0.0, description="Initial rod angle phi from the world x axis (rad).")
    com_velocity: Vector2 = Field([0.0, 0.0], description="Initial CoM velocity, world frame (m/s).")
    rod_rate: float = Field(0.0, description="Initial rod angular rate (rad/s).")


class IndependentUnits(Strict):
    kind: Literal["independent_units"]
    fuel_rate: Positive = Field(description="Fuel mass per thrust impulse k, eq. 11 (kg/(N s)).")
    initial_mass: Positive = Field(description="Mass of each MU at t = 0 (kg).")
    min_mass: NonNegative | None = Field(None, description="Lowest allowed mass of each MU, eq. 16 (kg).")
    unit_1_position: Vector2 = Field(description="Initial position of MU1, world frame (m).")
    unit_2_position: Vector2 = Field(description="Initial position of MU2, world frame (m).")
    unit_1_velocity: Vector2 = Field([0.0, 0.0], description="Initial velocity of MU1, world frame (m/s).")
    unit_2_velocity: Vector2 = Field([0.0, 0.0], description="Initial velocity of MU2, world frame (m/s).")
    width_min: Positive | None = Field(None, description="Smallest mouth width (MU distance), eq. 15 (m).")
    width_max: Positive | None = Field(None, description="Largest mouth width (MU distance), eq. 15 (m).")
    position_min: float | None = Field(None, description="Lower bound of every MU coordinate (m).")
    position_max: float | None = Field(None, description="Upper bound of every MU coordinate (m).")

    @model_validator(mode="after")
    def _pairs(self):
        for low, high in (("width_min", "width_max"), ("position_min", "position_max")):
            a, b = getattr(self, low), getattr(self, high)
            if (a is None) != (b is None):
                raise ValueError(f"give both '{low}' and '{high}' (m) or neither")
            if a is not None and a >= b:
                raise ValueError(f"'{low}' must be < '{high}'. Got {a:g} >= {b:g} instead")
        return self


class Debris(Strict):
    center: Vector2 = Field([0.0, 0.0], description="Debris centre (x_o, y_o), world frame (m).")
    keep_out_radius: Positive = Field(description="Radius r_o of the keep-out circle no MU may enter (m).")


class Thrust(Strict):
    min: NonNegative = Field(description="Smallest thrust magnitude of each MU (N).")
    max: Positive = Field(description="Largest thrust magnitude of each MU (N).")

    @model_validator(mode="after")
    def _ordered(self):
        if self.min >= self.max:
            raise ValueError(f"'min' must be < 'max' (N). Got {self.min:g} >= {self.max:g} instead")
        return self


class FreeTime(Strict):
    final_time_min: Positive = Field(0.1, description="Lower bound of the free final time (s).")
    final_time_max: Positive = Field(20.0, description="Upper bound of the free final time (s).")
    final_time_guess: Positive = Field(7.0, description="Initial guess of the final time (s).")

    @model_validator(mode="after")
    def _ordered(self):
        if not self.final_time_min <= self.final_time_guess <= self.final_time_max:
            raise ValueError("need final_time_min <= final_time_guess <= final_time_max (s). Got "
                             f"{self.final_time_min:g}, {self.final_time_guess:g}, {self.final_time_max:g} instead")
        return self


class MinFuel(Strict):
    kind: Literal["min_fuel"]
    final_time: Positive = Field(description="Fixed mission time (s); the paper's eq. 9 uses 7 s.")


class MinTime(FreeTime):
    kind: Literal["min_time"]


class Combined(FreeTime):
    kind: Literal["combined"]
    time_weight: NonNegative = Field(1.0, description="w1 of eq. 18, weight of the final time (1/s).")
    impulse_weight: NonNegative = Field(1.0, description="w2 of eq. 18, weight of the thrust impulse "
                                                         "integral(T1+T2) dt (1/(N s)).")


class Collocation(Strict):
    intervals: Annotated[int, Field(ge=4, le=1000)] = Field(50, description="Collocation intervals N (-).")
    keep_out_margin: NonNegative = Field(0.02, description="Added to r_o at the collocation points so that the "
                                                           "path between them keeps r_o too (m).")
    final_at_rest: bool = Field(False, description="Require zero velocities at the final time.")
    control_smoothing: NonNegative = Field(1e-4, description="Weight of the tie-breaking penalty on control jumps "
                                                             "between collocation points (-); picks a smooth one "
                                                             "among equally optimal controls.")


class Reference(Strict):
    source: Text = Field(description="Where the reference figures come from.")
    final_time: Positive | None = Field(None, description="Reported final time (s).")
    fuel: Positive | None = Field(None, description="Reported fuel of both MUs (kg).")
    solve_time: Positive | None = Field(None, description="Reported solver wall time (s).")


class Replay(Strict):
    nodes_per_side: Annotated[int, Field(ge=3, le=40)] = Field(8, description="Net nodes along one side (-).")
    side_length: Positive | None = Field(None, description="Side of the square net (m); default: the largest "
                                                           "mouth width (rod: L).")
    net_mass: Positive = Field(0.5, description="Mass of the whole net, spread evenly over its nodes (kg).")
    thread_axial_rigidity: Positive = Field(6.0e3, description="EA of a thread (N); the replay needs little "
                                                               "stretch, not the thread's real EA (a 0.5 ms step).")
    thread_damping: NonNegative = Field(1.5, description="Axial damping of every thread (N s/m).")
    tracking_stiffness: Positive = Field(200.0, description="Position gain of the MU tracking force (N/m).")
    tracking_damping: Positive = Field(40.0, description="Velocity gain of the MU tracking force (N s/m).")
    step: Annotated[float, Field(gt=0, le=1e-2)] = Field(5e-4, description="Exudyn explicit step (s).")


Model = Annotated[Union[RigidRod, IndependentUnits], Field(discriminator="kind")]
Objective = Annotated[Union[MinFuel, MinTime, Combined], Field(discriminator="kind")]


class ApproachCase(Strict):
    kind: Literal["approach"] = Field("approach", description=KIND_NOTE)
    name: CaseName = Field(description="Case name; default output folder runs/<name>.")
    description: Text = Field("", description="What the case is.")
    model: Model
    debris: Debris
    thrust: Thrust
    objective: Objective
    collocation: Collocation = Collocation()
    reference: Reference | None = None
    replay: Replay = Replay()
