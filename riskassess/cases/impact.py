"""Case files: TOML, validated once on load into typed objects.

Every quantity is SI (m, kg, s, N, rad); the field descriptions below state the unit and
are the schema documentation (``riskassess schema`` prints them). Frames:

* **LVLH**: chaser-centred, x radial, y along-track (flight direction), z cross-track.
* **target frame**: the debris reference frame in which body geometry, centres of
  mass, inertia and joints are given; its pose in LVLH at t = 0 is ``target.position_lvlh``
  and ``target.attitude_rotation_vector`` (target->LVLH).

:func:`load_case` raises :class:`CaseError` listing every problem as
``file: key.path: message`` before any simulation starts.
"""
from __future__ import annotations

import copy
import json
import re
from pathlib import Path
from typing import Annotated, Literal, Union, get_args

import numpy as np
from pydantic import BaseModel, Field, ValidationError, create_model, field_validator, model_validator

from multibody.shapes import SHAPES as CONTACT_SHAPES
from multibody.load_filter import NYQUIST_FRACTION
from riskassess.cases.inputs import (JSON_FILE_LIMIT, KIND_NOTE, MESH_FILE_LIMIT, CaseError, CaseName, ItemName,
                                    RelativeFile, Strict, Text, decode_utf8, read_limited, read_toml, resolve_reference,
                                    unique_names)
from riskassess.cases.target_geometry import target_points_lvlh, target_vertices_lvlh
from riskassess.cases.uncertain import parse_uncertain
from structures.capture_window import CAPTURE_ENERGY_FRACTION, CAPTURE_HOLD_TRAVEL_M
from structures.modal_load import SAMPLES_PER_MODE_PERIOD
from structures.section_shapes import SHAPES

Vector3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]


def check_physical_inertia(j):
    """The inertia tensor ``j`` (3, 3) (kg m^2) of a rigid body, or ValueError: it must be
    symmetric, positive definite and obey the triangle inequality of principal moments.

    Parameters
    ----------
    j : (3, 3) float or nested list
        Inertia about the CoM (kg m^2), in whatever frame the case gives it.

    Returns
    -------
    (3, 3) float or nested list
        ``j`` unchanged (usable as a validator).
    """
    m = np.asarray(j, float)
    if not np.allclose(m, m.T, rtol=1e-9, atol=1e-9 * np.abs(m).max()):
        raise ValueError("inertia must be symmetric")
    eig = np.linalg.eigvalsh(m)
    if eig.min() <= 0:
        raise ValueError(f"inertia must be positive definite (principal moments {eig.round(6).tolist()})")
    if eig[0] + eig[1] < eig[2] * (1 - 1e-9):
        raise ValueError(f"principal moments {eig.round(6).tolist()} violate the triangle inequality")
    return j


# ---------------------------------------------------------------------------- simulation
class Simulation(Strict):
    end_time: Positive = Field(description="Simulated time (s).")
    step: Annotated[float, Field(gt=0, le=1e-2)] = Field(
        1e-4, description="Fixed integrator step (s); see docs/model.md for the convergence study.")
    integrator: Literal["VelocityVerlet", "RK44", "ExplicitMidpoint"] = Field(
        "VelocityVerlet", description="Exudyn explicit integrator.")
    output_rate: Positive = Field(1000.0, description="Time-series samples per second (Hz).")
    net_output_rate: Positive = Field(50.0, description="Net snapshots per second (Hz), for VTK export.")
    contact_substep: Positive = Field(
        2e-6, description="Shortest sub-step of the contact impulse integration (s); each node's sub-step resolves "
                          "its contact's period (0.02 rad per sub-step) and is never shorter; >= step turns "
                          "sub-cycling off.")
    net_integration: Literal["kernel", "exudyn"] = Field(
        "kernel", description="Who integrates the net nodes: 'kernel' (the compiled force kernel, inside the "
                              "bodies' VelocityVerlet step; fast) or 'exudyn' (one Exudyn node for the whole net, "
                              "the reference path). Runge-Kutta integrators always use 'exudyn'.")
    implicit_contact_speed: Annotated[float, Field(ge=0, le=1.0)] = Field(
        0.15, description="A node's single contact approaching or separating slower than this (m/s) takes one "
                          "implicit step instead of the explicit sub-cycle (docs/model.md, 'Contact'); 0 sub-cycles "
                          "every contact (the reference path, about 2.4 times slower).")
    coupling: Literal["coupled", "sequential"] = Field(
        "coupled", description="'coupled': net and debris in one system (the tool's model); 'sequential': the seed "
                               "paper's method, the net against the debris held fixed, then the recorded contact "
                               "force and moment histories applied to the free debris (docs/model.md).")

    @model_validator(mode="after")
    def _rates_fit_step(self):
        if self.output_rate * self.step > 1.0 + 1e-9:
            raise ValueError(f"output_rate must be <= 1/step = {1 / self.step:g} Hz. Got {self.output_rate:g} instead")
        if self.end_time < self.step:
            raise ValueError(f"end_time must be >= step ({self.step:g} s). Got {self.end_time:g} instead")
        return self


# ---------------------------------------------------------------------------- orbit
class CircularOrbit(Strict):
    kind: Literal["circular"]
    altitude: Annotated[float, Field(ge=100e3, le=1e8)] = Field(
        description="Altitude of the circular reference orbit above the equatorial radius (m); "
                    "sets the Clohessy-Wiltshire mean motion.")


class NoOrbit(Strict):
    kind: Literal["none"]


# ---------------------------------------------------------------------------- net
class Thread(Strict):
    diameter: Annotated[float, Field(gt=0, le=0.05)] = Field(
        description="Thread diameter (m); node contact radius is half of it.")
    density: Annotated[float, Field(gt=0, le=25000)] | None = Field(
        None, description="Thread material density (kg/m^3); gives the node mass.")
    modulus: Annotated[float, Field(gt=0, le=1e13)] | None = Field(
        None, description="Young's modulus (Pa); stiffness = E A / l0.")
    stiffness: Positive | None = Field(
        None, description="Axial stiffness of one mesh-length thread (N/m), instead of modulus.")
    damping: NonNegative = Field(description="Axial damping of a thread (N s/m).")
    bending: bool = Field(False, description="Add thread bending stiffness (EI from modulus or bending_rigidity).")
    bending_rigidity: Positive | None = Field(None, description="Thread bending rigidity EI (N m^2).")
    breaking_load: Positive | None = Field(
        None, description="Breaking load of one thread (N), e.g. the maker's minimum breaking strength of the "
                          "line; the report compares every thread's peak tension with it. No default: without "
                          "it the net's integrity is 'not assessed'.")

    @model_validator(mode="after")
    def _one_stiffness(self):
        if (self.modulus is None) == (self.stiffness is None):
            raise ValueError("give exactly one of 'modulus' (Pa) or 'stiffness' (N/m)")
        if self.bending and self.modulus is None and self.bending_rigidity is None:
            raise ValueError("'bending = true' needs 'modulus' or 'bending_rigidity'")
        return self


class Trigger(Strict):
    """When a net mechanism fires (the closing's winch starts, the main tether's spool brakes): a time, or the net's
    first contact plus a delay (:class:`multibody.closing_winch.ContactTrigger`)."""

    start: NonNegative | Literal["first_contact"] = Field(
        "first_contact", description="When it fires: a time (s), or 'first_contact' (the net's first contact "
                                     "with any body, nodes' or threads', plus the delay): a mission fires the closing on "
                                     "the net's sensed arrival and waits for the wrap.")
    delay_s: NonNegative | None = Field(
        None, description="With start = 'first_contact': the wait after it (s). Give this or delay_travel_m; "
                          "neither: 0.")
    delay_travel_m: NonNegative | None = Field(
        None, description="With start = 'first_contact': the wait after it as net travel (m), delay = this / "
                          "launch.velocity (the capture keeps its shape in units of travel, docs/structures.md; "
                          "14 m is the seed's 7 s at 2 m/s, Boonrath et al. 2024 Sec. 4.1).")

    @model_validator(mode="after")
    def _delay(self):
        if self.delay_s is not None and self.delay_travel_m is not None:
            raise ValueError("give at most one of 'delay_s' (s) or 'delay_travel_m' (m)")
        if self.start != "first_contact" and (self.delay_s is not None or self.delay_travel_m is not None):
            raise ValueError(f"a delay goes with start = 'first_contact'; start = {self.start!r} is already a time")
        return self


class Closing(Trigger):
    """The net's closing mechanism (docs/model.md, "Closing the net"): a loop of tension-only threads laced through
    the four bullets and two perimeter nodes per side (Boonrath, Singh & Botta 2024, Sec. 2.1), reeled in by a winch
    from its trigger over ``duration_s`` to ``closed_fraction`` of its open length. Off (no table): the net stays open."""

    duration_s: Positive = Field(
        description="Reel-in time from open to closed (s): the natural lengths shorten linearly over it.")
    closed_fraction: Annotated[float, Field(gt=0, le=1)] = Field(
        description="The closed loop's natural length over its open length, the mouth's perimeter in the launch "
                    "shape (-).")
    axial_rigidity: Positive = Field(description="EA of the closing thread (N); a thread of natural length l0 "
                                                 "gets EA / l0 (N/m).")
    damping: NonNegative | None = Field(
        None, description="Axial damping of each closing thread (N s/m); default net.thread.damping.")


class Tether(Trigger):
    """The main tether (docs/model.md, "The main tether"): a tension-only Kelvin-Voigt line (the towing model's main
    tether law, Boonrath, Singh & Botta 2024 eq. (5a)) from the net's central node (the grid's middle node; for an
    even nodes_per_side the node (n/2, n/2), half a mesh off the centre) to a chaser holding station at a fixed
    anchor (its thrusters hold it: a kinematic chaser, as the towing seed's pre-tow phase). The spool pays out freely
    while the net flies (no tension), brakes at its trigger (the natural length frozen at the node's distance plus
    ``slack_m``), then optionally reels in. Off (no table): the net flies free of the chaser (the default)."""

    stiffness: Positive | None = Field(
        None, description="k (N/m) of the whole line, e.g. Boonrath et al. Table 1's k_MT = 3000 N/m. Give this "
                          "or axial_rigidity.")
    axial_rigidity: Positive | None = Field(
        None, description="EA of the line (N): k = EA / l0 with l0 the natural length at the brake (and as the "
                          "reel shortens it).")
    damping: NonNegative = Field(description="c (N s/m) of the line, e.g. Boonrath et al. Table 1's c_MT = 300.")
    standoff_m: Positive = Field(
        15.0, description="The chaser's anchor lies this far (m) back along launch.direction from the net's centre "
                          "at launch (launch.distance + this from the aim point). Default 15 m: Boonrath et al. "
                          "Table 1's main tether length l_MT,0 [assumed: the seed gives no launch range].")
    anchor_lvlh: Vector3 | None = Field(
        None, description="The anchor (m), LVLH, instead of standoff_m.")
    slack_m: NonNegative = Field(0.0, description="Added to the node's distance when the spool brakes (m).")
    reel_rate_m_s: NonNegative = Field(
        0.0, description="After the brake the spool reels in at this rate (m/s); 0: it holds (the brake only).")
    reel_in_m: NonNegative = Field(
        0.0, description="Length (m) the spool reels in after the brake, then it holds; needs reel_rate_m_s > 0.")

    @model_validator(mode="after")
    def _line(self):
        if (self.stiffness is None) == (self.axial_rigidity is None):
            raise ValueError("give exactly one of 'stiffness' (N/m) or 'axial_rigidity' (N)")
        if (self.reel_rate_m_s > 0.0) != (self.reel_in_m > 0.0):
            raise ValueError("a reel-in needs both 'reel_rate_m_s' (m/s) and 'reel_in_m' (m) > 0, or neither. "
                             f"Got {self.reel_rate_m_s} and {self.reel_in_m} instead")
        return self


class Net(Strict):
    side_length: Positive = Field(description="Side of the square net (m).")
    nodes_per_side: Annotated[int, Field(ge=2, le=200)] = Field(description="Nodes along one side (-).")
    thread: Thread
    node_mass: Positive | None = Field(
        None, description="Mass of one net node (kg); default: thread mass spread evenly over the nodes.")
    closing: Closing | None = Field(
        None, description="The closing mechanism ([net.closing]); none: the net stays open (the default).")
    tether: Tether | None = Field(
        None, description="The main tether to a station-keeping chaser ([net.tether]); none: the net flies free "
                          "(the default).")

    @model_validator(mode="after")
    def _mass_source(self):
        if self.node_mass is None and self.thread.density is None:
            raise ValueError("give 'node_mass' (kg) or 'thread.density' (kg/m^3)")
        return self

    @property
    def mesh_size(self) -> float:
        return self.side_length / (self.nodes_per_side - 1)


class Bullets(Strict):
    mass: Positive = Field(description="Mass of each of the four corner bullets (kg).")
    radius: Annotated[float, Field(gt=0, le=1.0)] = Field(description="Bullet contact radius (m).")
    tether_length: Positive | None = Field(
        None, description="Thread from corner node to bullet (m); default one mesh size.")


class Launch(Strict):
    distance: Positive = Field(description="Distance from the net centre to the aim point along 'direction' (m).")
    velocity: Annotated[float, Field(gt=0, le=500)] = Field(description="Net speed along 'direction' (m/s).")
    direction: Vector3 = Field(description="Launch direction, LVLH (-), normalised on load.")
    aim_point: Vector3 = Field([0.0, 0.0, 0.0], description="Aim point, target frame (m).")
    sag: Annotated[float, Field(ge=0.0, le=20.0)] = Field(
        0.0, description="The net arrives as a bowl, its centre trailing its corners by this depth (m) along "
                         "'direction' (a paraboloid; the mesh drawn in so that no thread starts stretched; "
                         "'distance' places the corners' plane). 0: flat, the default. A flat net striking a "
                         "face parallel to it is a singular case: all nodes over the face strike within one step "
                         "(docs/model.md, 'The wrapping contact level'); the seed paper states no shape.")

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v):
        if np.linalg.norm(v) == 0:
            raise ValueError("direction must be a non-zero vector")
        return v


class Contact(Strict):
    stiffness: Positive = Field(description="Hertz stiffness k_n (N/m^exponent).")
    exponent: Annotated[float, Field(ge=1.0, le=3.0)] = Field(1.5, description="Hertz exponent n (-).")
    hunt_crossley_alpha: NonNegative = Field(
        description="Hunt-Crossley factor alpha (s/m): d_n = 1.5 alpha k_n.")
    mu_static: NonNegative = Field(description="Static friction coefficient (-).")
    mu_kinetic: NonNegative = Field(description="Kinetic friction coefficient (-).")
    transition_speed: Positive = Field(description="Static-to-kinetic transition slip speed V_t0 (m/s).")
    thread_segments: bool = Field(
        False, description="Threads touch the box shapes too, not only the nodes: the segment between a thread's two "
                           "nodes takes the same contact law at its deepest point, the force split over the two "
                           "nodes (multibody/contact_segment.py), so a thread cannot pass through a thin part (the "
                           "solar array, the ASAR) between its nodes. false: node contact alone, the seed paper's "
                           "model (docs/model.md, 'Contact'). Other shapes (cylinders, spheres, meshes) keep node "
                           "contact alone either way. Its strikes are not yet energy-consistent: with it on, a location "
                           "holds only if the run's energy balance closes within 1 % (else indeterminate, rule "
                           "thread_contact_energy; docs/structures.md).")

    @model_validator(mode="after")
    def _friction_order(self):
        if self.mu_kinetic > self.mu_static:
            raise ValueError(f"mu_kinetic must be <= mu_static ({self.mu_static}). Got {self.mu_kinetic} instead")
        return self


# ---------------------------------------------------------------------------- target
#: Kind of value of a contact shape's key (:data:`multibody.shapes.base.VALUES`) -> its checked type.
SHAPE_VALUE_TYPES = {
    "positive": Positive,
    "positive_vector3": Annotated[list[Positive], Field(min_length=3, max_length=3)],
    "vector3": Vector3,
    "file": RelativeFile,
}


def _model_class_name(kind: str) -> str:
    return "".join(part.capitalize() for part in kind.split("_"))


def _shape_model(shape) -> type[Strict]:
    """The case schema of one contact shape (:mod:`multibody.shapes`): its ``kind`` and its keys,
    each checked as its kind of value and described as the shape describes it."""
    fields = {"kind": (Literal[shape.NAME], ...)}
    for key in shape.KEYS:
        default = ... if key.default is None else (list(key.default) if isinstance(key.default, tuple) else key.default)
        fields[key.name] = (SHAPE_VALUE_TYPES[key.value], Field(default, description=key.description))
    return create_model(_model_class_name(shape.NAME), __base__=Strict, __module__=__name__, **fields)


#: Shape kind -> its schema, one per shape file of multibody/shapes.
SHAPE_MODELS = {name: _shape_model(shape) for name, shape in CONTACT_SHAPES.items()}
Shape = Annotated[Union[tuple(SHAPE_MODELS.values())], Field(discriminator="kind")]


class Body(Strict):
    name: ItemName = Field(description="Body name; joints name it as parent or child.")
    mass: Positive = Field(description="(kg)")
    center_of_mass: Vector3 | None = Field(None, description="CoM, target frame (m); default: shapes' centroid.")
    inertia: Annotated[list[Vector3], Field(min_length=3, max_length=3)] | None = Field(
        None, description="Inertia about the CoM, target-frame axes (kg m^2); default: uniform density over the shapes.")
    shapes: Annotated[list[Shape], Field(min_length=1)]
    mass_properties_from: RelativeFile | None = Field(
        None, description="perception.json written by 'riskassess perceive' (path relative to the case file, in its "
                          "folder or below): mass, "
                          "center_of_mass and inertia are taken from its estimates (then leave those three keys out).")

    @field_validator("inertia")
    @classmethod
    def _physical_inertia(cls, j):
        return j if j is None else check_physical_inertia(j)


#: A dimension of a cross-section (m): a cut through a spacecraft member. The widest rocket bodies in
#: orbit are about 4-5 m across; 20 m bounds every member while the section formulas (fourth powers of
#: the dimensions) stay far from float overflow.
SectionLength = Annotated[float, Field(gt=0, le=20.0)]


def _section_model(shape) -> type[Strict]:
    """The case schema of one cross-section shape (:mod:`structures.section_shapes`): its ``kind`` and
    its dimensions, each a :data:`SectionLength` described as the shape describes it."""
    fields = {"kind": (Literal[shape.NAME], ...)}
    fields.update({name: (SectionLength, Field(description=text)) for name, text in shape.DIMENSIONS.items()})
    return create_model(_model_class_name(shape.NAME), __base__=Strict, __module__=__name__, **fields)


#: Section kind -> its schema, one per shape file of structures/section_shapes.
SECTION_MODELS = {name: _section_model(shape) for name, shape in SHAPES.items()}
Section = Annotated[Union[tuple(SECTION_MODELS.values())], Field(discriminator="kind")]


def section_properties(spec):
    """Section properties (the plug-in of :mod:`structures.section_shapes` named by ``kind``) from a case
    section table (raises ValueError for impossible dimensions).

    Parameters
    ----------
    spec : Section
        A validated ``section`` table: ``kind`` and the shape's dimensions (m).

    Returns
    -------
    structures.section_base.SectionProperties
    """
    params = spec.model_dump()
    return SHAPES[params.pop("kind")].properties(**params)


class Member(Strict):
    """The structural member behind a clamped joint: its compliance becomes the joint's springs."""

    length: SectionLength = Field(description="Member length from the joint to the body it carries (m).")
    section: Section = Field(description="The member's cross-section (a circular_tube: its torsion constant is known).")
    modulus: Positive = Field(description="Young's modulus E (Pa).")
    shear_modulus: Positive = Field(description="Shear modulus G (Pa).")
    beam_axis: Vector3 = Field(description="Direction of the member, target frame (-): along one of the joint's "
                                           "axes h1, h2, h3.")
    source: Text = Field(description="Where the values come from (a drawing, an FE model, an assumption and why): "
                                     "the joint's loads rest on them.")

    @field_validator("section")
    @classmethod
    def _torsion_known(cls, section):
        if section_properties(section).torsion_constant is None:
            raise ValueError(f"a member's section must give its torsion constant; '{section.kind}' does not "
                             f"(use circular_tube)")
        return section


class RotationModes(Strict):
    """The structure's own modes about a joint's locked rotation axes (each axis alone, the others rigid), e.g. a
    solar array's torsion (about h1, along the array) and in-plane bending (about h3) lumped at its root: those
    axes carry the structure's compliance, the translations and the axes not named keep the automatic penalty."""

    h1_hz: Positive | None = Field(None, description="Mode about h1 (Hz); omitted: the automatic penalty.")
    h2_hz: Positive | None = Field(None, description="Mode about h2 (Hz), clamped joints only (a revolute joint's h2 "
                                                     "is its hinge spring); omitted: the automatic penalty.")
    h3_hz: Positive | None = Field(None, description="Mode about h3 (Hz); omitted: the automatic penalty.")
    damping_ratio: Annotated[float, Field(ge=0, le=1)] = Field(
        0.02, description="The structure's damping on these axes, fraction of critical (-).")
    source: Text = Field(description="Where the frequencies come from (an FE model, a test, an analogue and why): "
                                     "the joint's loads rest on them.")

    @model_validator(mode="after")
    def _some_axis(self):
        if self.h1_hz is None and self.h2_hz is None and self.h3_hz is None:
            raise ValueError("rotation_modes names no axis; give h1_hz, h2_hz or h3_hz")
        return self

    def frequencies_hz(self) -> np.ndarray:
        """(3,) float: the modes about h1, h2, h3 (Hz), NaN where the axis keeps the automatic penalty."""
        return np.array([np.nan if f is None else f for f in (self.h1_hz, self.h2_hz, self.h3_hz)])


class Joint(Strict):
    name: ItemName = Field(description="Joint name; weak locations name it.")
    kind: Literal["revolute", "clamped"] = Field(description="Hinge with torsional spring-damper, or clamped.")
    parent: str = Field(description="Name of the parent body.")
    child: str = Field(description="Name of the child (appendage) body.")
    position: Vector3 = Field(description="Joint point, target frame (m).")
    axis: Vector3 = Field([0.0, 0.0, 1.0], description="Hinge axis h2, target frame (-).")
    torsional_stiffness: NonNegative = Field(0.0, description="About the hinge axis (N m/rad).")
    torsional_damping: NonNegative = Field(0.0, description="About the hinge axis (N m s/rad).")
    initial_angle: float = Field(0.0, description="Initial hinge angle about h2 (rad).")
    initial_rate: float = Field(0.0, description="Initial hinge rate about h2 (rad/s).")
    penalty_translational: Positive | None = Field(
        None, description="Penalty stiffness locking the joint point (N/m); default: tuned to the step.")
    penalty_rotational: Positive | None = Field(
        None, description="Penalty stiffness locking rotations (N m/rad); default: tuned to the step.")
    penalty_damping_ratio: Annotated[float, Field(ge=0, le=1)] = Field(
        0.05, description="Penalty damping, fraction of critical (-); with first_mode_hz, the structure's damping.")
    first_mode_hz: Positive | None = Field(
        None, description="The structure's own first mode on this joint (Hz), from its FE model or a test: the "
                          "penalty springs not given explicitly then carry the structure's compliance instead of a "
                          "stiffness tuned to the step (needs at least 20 steps per period).")
    member: Member | None = Field(
        None, description="The member behind a clamped joint (its section, length and moduli): its axial, shear, "
                          "torsion and bending compliance, lumped at the root, become the joint's six springs, so its "
                          "loads no longer rest on a penalty stiffness (docs/structures.md); penalty_damping_ratio is "
                          "then the member's damping. Not with first_mode_hz or the penalty keys.")
    load_filter_hz: Positive | None = Field(
        None, description="Cut-off (Hz) of the Butterworth low-pass this joint's loads are read through, "
                          "run every simulation step (structures.load_filter_order; overrides structures.load_filter_hz for this joint; "
                          "docs/structures.md, 'Loads through a stated low-pass filter').")
    rotation_modes: RotationModes | None = Field(
        None, description="The structure's own modes about the joint's locked rotation axes (Hz, each axis alone), "
                          "with their damping and source: those axes carry the structure's compliance (needs at least "
                          "20 steps per period), the translations keep the automatic penalty. Not with first_mode_hz, "
                          "member or penalty_rotational.")

    @model_validator(mode="after")
    def _revolute_fields(self):
        if np.linalg.norm(self.axis) == 0:
            raise ValueError("axis must be a non-zero vector")
        if self.kind == "clamped" and (self.torsional_stiffness or self.initial_angle or self.initial_rate):
            raise ValueError("a clamped joint takes no torsional_stiffness, initial_angle or initial_rate")
        if self.member is not None:
            if self.kind != "clamped":
                raise ValueError("'member' is for a clamped joint (a revolute joint's hinge axis is its spring)")
            given = [k for k in ("first_mode_hz", "penalty_translational", "penalty_rotational")
                     if getattr(self, k) is not None]
            if given:
                raise ValueError(f"'member' sets all six springs of the joint; remove {', '.join(given)}")
        if self.rotation_modes is not None:
            given = [k for k in ("first_mode_hz", "member", "penalty_rotational") if getattr(self, k) is not None]
            if given:
                raise ValueError(f"'rotation_modes' sets the joint's rotation springs; remove {', '.join(given)}")
            if self.kind == "revolute" and self.rotation_modes.h2_hz is not None:
                raise ValueError("rotation_modes.h2_hz: a revolute joint's h2 is its hinge spring "
                                 "(torsional_stiffness)")
        return self


class Target(Strict):
    position_lvlh: Vector3 = Field(description="Target-frame origin at t = 0, LVLH (m).")
    attitude_rotation_vector: Vector3 = Field([0.0, 0.0, 0.0], description="Target->LVLH rotation at t = 0 (rad).")
    velocity_lvlh: Vector3 = Field([0.0, 0.0, 0.0], description="Velocity of the target-frame origin, LVLH (m/s).")
    angular_velocity: Vector3 = Field([0.0, 0.0, 0.0], description="Rigid tumble of the whole target, target frame (rad/s).")
    bodies: Annotated[list[Body], Field(min_length=1)]
    joints: list[Joint] = []

    @field_validator("bodies", "joints")
    @classmethod
    def _unique(cls, items, info):
        return unique_names(items, {"bodies": "body", "joints": "joint"}[info.field_name])

    @model_validator(mode="after")
    def _joint_tree(self):
        names = [b.name for b in self.bodies]
        children = []
        for j in self.joints:
            for role in ("parent", "child"):
                if getattr(j, role) not in names:
                    raise ValueError(f"joint '{j.name}': {role} '{getattr(j, role)}' is not a body; bodies are {names}")
            if j.parent == j.child:
                raise ValueError(f"joint '{j.name}' joins body '{j.parent}' to itself")
            children.append(j.child)
        if len(set(children)) != len(children):
            raise ValueError("each body can be the child of at most one joint")
        roots = [n for n in names if n not in children]
        if len(roots) != 1:
            raise ValueError(f"the joints must form one tree with a single root body. Roots found: {roots}")
        return self


# ---------------------------------------------------------------------------- chaser
class Chaser(Strict):
    """The chaser simulated as a rigid body carrying the net on rods (a "netted pocket",
    Tang et al. 2023 Sec. 4.2.2): the net's rim nodes are mounted on it and the whole
    assembly flies at the target with the launch velocity."""
    mass: Positive = Field(description="Chaser mass (kg).")
    principal_inertia: Annotated[list[Positive], Field(min_length=3, max_length=3)] = Field(
        description="Principal moments of inertia about its CoM, axes parallel to LVLH at t = 0 (kg m^2).")
    standoff: Positive = Field(description="Distance from the chaser CoM back to the net plane along the launch direction (m).")
    mount_stiffness: Positive = Field(description="Stiffness of each rod holding a rim node (N/m).")
    mount_damping: NonNegative = Field(0.0, description="Damping of each rod (N s/m).")


# ---------------------------------------------------------------------------- perception
class Lidar(Strict):
    position_chaser: Vector3 = Field([0.0, 0.0, 0.0], description="Sensor origin relative to the chaser CoM, LVLH axes at t = 0 (m).")
    boresight_lvlh: Vector3 = Field(description="Sensor boresight (+x of the sensor frame), LVLH at t = 0 (-).")
    up_lvlh: Vector3 = Field([0.0, 0.0, 1.0], description="Sensor +z (elevation up), LVLH; made orthogonal to the boresight (-).")
    fov_azimuth: Annotated[float, Field(gt=0, le=2 * np.pi)] = Field(description="Full horizontal field of view (rad).")
    fov_elevation: Annotated[float, Field(gt=0, le=np.pi)] = Field(description="Full vertical field of view (rad).")
    resolution_azimuth: Positive = Field(description="Angle between rays, horizontal (rad).")
    resolution_elevation: Positive = Field(description="Angle between rays, vertical (rad).")
    range_noise: NonNegative = Field(description="Range noise 1 sigma (m), constant over range.")
    rate: Annotated[float, Field(gt=0, le=100)] = Field(description="Frames per second (Hz).")
    max_range: Positive = Field(200.0, description="Longest range returned (m).")
    pointing: Literal["target", "body"] = Field(
        "target", description="'target': a pan-tilt mount turns the boresight to the debris' last registered "
                              "position each frame (the chaser may spin after the collision); 'body': fixed to the "
                              "chaser along boresight_lvlh.")

    @model_validator(mode="after")
    def _grid_size(self):
        rays = (self.fov_azimuth / self.resolution_azimuth + 1) * (self.fov_elevation / self.resolution_elevation + 1)
        if rays > 5e6:
            raise ValueError(f"the ray grid has {rays:.3g} rays per frame; at most 5e6 are allowed "
                             f"(coarsen the resolution or narrow the field of view)")
        if abs(np.dot(self.boresight_lvlh, self.up_lvlh)) >= 0.999 * np.linalg.norm(self.boresight_lvlh) * np.linalg.norm(self.up_lvlh):
            raise ValueError("up_lvlh must not be parallel to boresight_lvlh")
        return self


class Registration(Strict):
    voxel: Positive = Field(0.03, description="Voxel size the scans are thinned to before ICP (m).")
    model_frames: Annotated[int, Field(ge=1)] = Field(30, description="Frames merged into the debris model before it is frozen (-).")
    max_correspondence: Positive = Field(0.1, description="ICP correspondence distance (m).")
    search_cpu_per_frame: Positive = Field(
        15.0, description="Largest CPU time of one frame's search for a lost debris track (s): a frame whose "
                          "search (over all attitudes, chain continuation, global retry) takes longer is not "
                          "registered. The default keeps every search measured on the featured debris (1-14 s at load 4-8).")
    search_cpu_per_run: Annotated[float, Field(ge=0)] = Field(
        300.0, description="Largest CPU time of all searches of a perceive run together (s); once spent, frames "
                           "of a lost track are not registered (their estimates then say 'not observable'). "
                           "0: no search at all.")
    reacquire_continuity_turn: Annotated[float, Field(gt=0, le=np.pi)] | None = Field(
        None, description="Largest turn (rad) between a re-acquired debris attitude after a lost track and the "
                          "attitude propagated from the last registered rates; candidates beyond it are dropped, "
                          "a search from the propagated attitude is added (issue 26). None: off.")
    reacquire_chain_missed_frames: Annotated[int, Field(ge=0)] = Field(
        0, description="Consecutive frames a candidate pose chain after a lost debris track may fail and still go "
                       "on, predicted across the gap (-); the failed frames stay failed (issue 26). 0: a chain "
                       "ends at its first failed frame.")
    reacquire_grow_map: bool = Field(
        False, description="After a lost debris track's re-acquisition is confirmed, the confirmed frames and every "
                           "later frame tracked from the motion prediction that passes its checks add the surface "
                           "the map lacks (model-free tracking; issue 26). False: the map stays as built in the "
                           "observation.")
    map_second_pass: bool = Field(
        False, description="Model-free tracking: once the observation's map is built, every observation frame is "
                           "registered again to it from its own pose, the map kept as built "
                           "(perception.scan_to_map.registered_again; issue 26, percep21: not adopted). False: "
                           "the online pass's poses.")
    after_frames_scan_to_scan: bool = Field(
        False, description="Model-free tracking: the frames of the free flight after the collision are posed again, "
                           "each by point-to-plane ICP to the 4 observation scans that share most of its surface "
                           "(each at its online pose), the 4 poses averaged with their information, instead of "
                           "registered to the map fused from the observation, whose view-dependent bias they "
                           "otherwise carry (perception.scan_to_scan.scan_to_scan_poses; issue 26, percep22-24). "
                           "Their attitude errors inherited from shared partner scans (the partners' pose scatter, "
                           "correlated between frames that share partners) are propagated into the after fit's "
                           "covariance and so into C's and the principal moments' 1-sigma (percep24). "
                           "False: the poses registered to the map.")

    @model_validator(mode="after")
    def _budget(self):
        if self.search_cpu_per_frame > self.search_cpu_per_run > 0:
            raise ValueError(f"search_cpu_per_frame ({self.search_cpu_per_frame} s) must not exceed "
                             f"search_cpu_per_run ({self.search_cpu_per_run} s)")
        return self


class Bend(Strict):
    """One shape of the real target turned about a hinge line, against the drawings (a bent array)."""
    shape: Annotated[int, Field(ge=0)] = Field(description="Index (from 0) of the bent shape in target.bodies[0].shapes (-).")
    hinge_point: Vector3 = Field(description="A point of the hinge line, target frame (m).")
    hinge_axis: Vector3 = Field(description="Hinge line direction, target frame (-); any non-zero length.")
    angle: Annotated[float, Field(ge=-np.pi, le=np.pi)] = Field(description="Turn of the shape about the hinge, "
                                                                             "right-handed about hinge_axis (rad).")

    @model_validator(mode="after")
    def _axis(self):
        if np.linalg.norm(self.hinge_axis) == 0:
            raise ValueError("hinge_axis must be a non-zero vector")
        return self


class TruthDamage(Strict):
    """How the real target, which the LiDAR scans and the collision run simulates, differs from the
    target of [target], which is the model given to the tracker (perception.model = 'known'). The
    real body's mass properties follow from the model's: uniform density over the shapes, the stated
    mass spread over their volumes; a missing shape takes its mass away, a bent shape moves its own."""
    description: Text = Field("", description="What the damage stands for (free text).")
    missing_shapes: list[Annotated[int, Field(ge=0)]] = Field(
        [], description="Indices (from 0) of shapes of target.bodies[0].shapes the real target has lost (-).")
    bends: list[Bend] = Field([], description="Shapes of the real target turned about a hinge line.")
    center_of_mass_shift: Vector3 = Field(
        [0.0, 0.0, 0.0], description="Real CoM minus the one the shapes give, target frame (m): mass moved inside the "
                                     "body (e.g. propellant); the inertia about the CoM is kept.")


class Perception(Strict):
    observation_time: Positive = Field(description="LiDAR tracking of the free tumble before the chaser moves in (s).")
    hold_distance: Positive = Field(10.0, description="Chaser CoM to debris CoM while it observes, back along the launch direction (m).")
    seed: Annotated[int, Field(ge=0)] = Field(0, description="Seed of the range noise (-).")
    model: Literal["known", "none"] = Field(
        "known", description="'known': each scan is registered to the debris mesh of [target] (a catalogued "
                             "shape); 'none': no mesh, scan-to-map registration to a map built from the scans "
                             "(perception/scan_to_map.py); the body frame is then the first scan's.")
    lidar: Lidar
    registration: Registration = Registration()
    truth_damage: TruthDamage | None = Field(
        None, description="Optional: the scanned (real) target differs from the model of [target] "
                          "(riskassess/cases/truth_damage.py).")


# ---------------------------------------------------------------------------- structures
ValueOrRange = Union[Positive, Annotated[list[Positive], Field(min_length=2, max_length=2)]]
class Material(Strict):
    modulus: Positive | None = Field(None, description="Young's modulus (Pa); informational, stresses do not need it.")
    ultimate_normal: ValueOrRange = Field(description="Ultimate normal stress (Pa), a value or [low, high].")
    ultimate_shear: ValueOrRange = Field(description="Ultimate shear stress (Pa), a value or [low, high].")


class WeakLocationSpec(Strict):
    name: ItemName = Field(description="Weak-location name, used in the results.")
    joint: str = Field(description="Joint whose reaction loads this location (its name in target.joints).")
    offset: Vector3 = Field([0.0, 0.0, 0.0], description="Cut point minus joint point, target frame (m), on the child side.")
    beam_axis: Vector3 = Field([1.0, 0.0, 0.0], description="Section axis 1 (along the member, normal to the cut), target frame (-).")
    width_axis: Vector3 = Field([0.0, 1.0, 0.0], description="Section axis 2, target frame (-); made normal to beam_axis.")
    section: Section | None = Field(None, description="Cross-section at the cut; needs 'material'.")
    material: Material | None = None
    allowable_moment: ValueOrRange | None = Field(
        None, description="Allowable moment (N m), a value or [low, high], against the resultant of 'moment_axes'.")
    moment_axes: list[Literal["h1", "h2", "h3"]] | None = Field(
        None, description="Joint-frame moment components judged by allowable_moment; default: all but the hinge "
                          "axis h2 of a revolute joint (carried by its spring), all three for a clamped joint.")
    allowable_force: ValueOrRange | None = Field(None, description="Allowable resultant joint force (N), value or [low, high].")
    structural_mode_hz: ValueOrRange | None = Field(
        None, description="First mode of the structure this location belongs to (Hz), a value or [low, high]: the "
                          "judged loads are the joint's (stiff, automatic-penalty) reaction passed through that mode, "
                          "and a range is judged by the envelope over it (docs/structures.md, 'Are the judged peaks "
                          "converged?'); omitted: the reaction as recorded. Not with the joint's own first_mode_hz "
                          "(the compliance would count twice).")
    structural_damping_ratio: Annotated[float, Field(ge=0, lt=1)] = Field(
        0.02, description="Damping of that mode, fraction of critical (-); low damping reads higher loads.")

    @field_validator("allowable_moment", "allowable_force")
    @classmethod
    def _ordered_range(cls, v):
        if isinstance(v, list) and v[0] > v[1]:
            raise ValueError(f"a range is [low, high] with low <= high. Got {v} instead")
        return v

    @model_validator(mode="after")
    def _mode_range(self):
        if isinstance(self.structural_mode_hz, list) and self.structural_mode_hz[0] > self.structural_mode_hz[1]:
            raise ValueError(f"structural_mode_hz is [low, high] with low <= high. Got {self.structural_mode_hz} instead")
        return self

    @model_validator(mode="after")
    def _criteria(self):
        if (self.section is None) != (self.material is None):
            raise ValueError("'section' and 'material' come together (stresses need both)")
        if self.section is None and self.allowable_moment is None and self.allowable_force is None:
            raise ValueError("give at least one criterion: section + material, allowable_moment or allowable_force")
        b, w = np.asarray(self.beam_axis, float), np.asarray(self.width_axis, float)
        if np.linalg.norm(b) == 0 or np.linalg.norm(np.cross(b, w)) < 1e-6 * np.linalg.norm(b) * np.linalg.norm(w):
            raise ValueError("beam_axis must be non-zero and width_axis not parallel to it")
        return self


class Structures(Strict):
    skip_initial: NonNegative = Field(
        0.0, description="Loads before this time are not judged (s); the seed paper omits about 0.25 s of "
                         "initial impact loads that have no time to propagate.")
    release: Literal["low", "nominal", "high", "never"] = Field(
        "low", description="Which value of a range allowable releases a failed joint during the run "
                           "('low': conservative, most debris), or 'never' to judge without releasing.")
    thread_pass_through: Literal["bound", "ignore"] = Field(
        "bound", description="Net threads that pass through a part (contact acts on nodes only): 'bound' keeps a "
                             "location's 'holds' only if its margin absorbs twice the passing threads' tension at "
                             "their crossings (otherwise indeterminate; docs/structures.md); 'ignore' judges the "
                             "node-contact loads alone, as the seed paper's model, and reports the threads without "
                             "judging them.")
    weak_locations: Annotated[list[WeakLocationSpec], Field(min_length=1)]
    load_filter_order: Literal[2, 4] = Field(
        4, description="Order of the joints' Butterworth load filters (load_filter_hz): 4 takes a penalty mode 4x "
                       "above the cut-off down by 256, 2 by 16 (docs/structures.md).")
    load_filter_hz: Positive | None = Field(
        None, description="Cut-off (Hz) of a Butterworth low-pass (load_filter_order) run on every joint's loads at every "
                          "simulation step (before the output's decimation): the verdict and the release judge the "
                          "filtered loads, recorded beside the raw ones. A penalty joint's own spring modes "
                          "(15-1500 Hz) are numerical; give a cut-off above the structure's physical content and well "
                          "below them (docs/structures.md, 'Loads through a stated low-pass filter'); a joint's own "
                          "load_filter_hz overrides it. Omitted: the raw penalty loads are judged.")
    twin: bool = Field(
        False, description="Run the case a second time with the launch speed x (1 + 1e-7) and label each judged peak "
                           "deterministic (both runs' peaks so far agree within 5 % up to it) or chaotic (one draw of "
                           "the capture's late strikes); a location that holds on a chaotic peak is indeterminate "
                           "(docs/structures.md). Doubles the run time unless the run already shows debris.")
    window: Literal["fixed", "capture"] = Field(
        "capture", description="The judged window (default 'capture' for coupled runs, 'fixed' for sequential ones): "
                             "'fixed' judges 0..simulation.end_time, a statement that nothing after it can load the "
                             "target (for example the net closed or in tow by then; the report names the window); "
                             "'capture' judges the capture "
                             "until it is over (the net's kinetic energy relative to the debris' main body, its "
                             "rigid motion with that body removed, below its threshold (capture_energy_J, else "
                             "capture_energy_fraction of it at launch) and no judged running peak rising, both for "
                             "capture_hold_s) and stops the run there; simulation.end_time is then "
                             "the cap, and a run that reaches it before the capture is over cannot say a location "
                             "holds (indeterminate, rule capture_not_over; docs/structures.md, 'The whole capture as "
                             "the judged window'). Coupled runs only.")
    capture_energy_J: Positive | None = Field(
        None, description="With window = 'capture': the net's kinetic energy relative to the debris (J) below which "
                          "its relative motion counts as died out; default capture_energy_fraction of that energy at "
                          "launch.")
    capture_energy_fraction: Annotated[float, Field(gt=0, le=1)] = Field(
        CAPTURE_ENERGY_FRACTION, description="With window = 'capture' and no capture_energy_J: the share (-) of the "
                                             "net's kinetic energy relative to the debris at launch below which its "
                                             "relative motion counts as died out; the default is argued from "
                                             "measured envisat_small runs in docs/structures.md.")
    capture_hold_s: Positive | None = Field(
        None, description="With window = 'capture': how long (s) the relative energy must stay below its threshold "
                          f"with no judged running peak rising; default {CAPTURE_HOLD_TRAVEL_M:g} m of net travel at "
                          "launch.velocity (one pass of the wrapped net past the body at every speed run on "
                          "envisat_small).")

    @field_validator("weak_locations")
    @classmethod
    def _unique(cls, items):
        return unique_names(items, "weak location")


class MonteCarlo(Strict):
    uncertain: Annotated[list[Text], Field(min_length=1)] = Field(
        description="Uncertain inputs of 'riskassess assess --monte-carlo N', each KEY=DIST(params) with DIST one "
                    "of uniform(low,high), normal(mean,std), lognormal(median,sigma_log), triangular(low,mode,high), "
                    "in the key's SI unit (e.g. \"contact.mu_kinetic=uniform(0.1,0.19)\"); --uncertain on the "
                    "command line adds to them and replaces one of the same key.")

    @field_validator("uncertain")
    @classmethod
    def _grammar(cls, items):
        keys = [parse_uncertain(text)[0] for text in items]   # ValueError naming the entry
        if len(set(keys)) != len(keys):
            raise ValueError("each key appears once")
        return items


class Case(Strict):
    kind: Literal["impact"] = Field("impact", description=KIND_NOTE)
    name: CaseName = Field(description="Case name; default output folder runs/<name>.")
    description: Text = ""
    simulation: Simulation
    orbit: Annotated[Union[CircularOrbit, NoOrbit], Field(discriminator="kind")]
    net: Net
    bullets: Bullets
    launch: Launch
    contact: Contact
    target: Target
    structures: Structures | None = None
    chaser: Chaser | None = None
    perception: Perception | None = None
    monte_carlo: MonteCarlo | None = None

    @model_validator(mode="after")
    def _weak_location_joints(self):
        if self.structures is None:
            return self
        joints = [j.name for j in self.target.joints]
        for loc in self.structures.weak_locations:
            if loc.joint not in joints:
                raise ValueError(f"structures: weak location '{loc.name}': joint '{loc.joint}' is not in "
                                 f"target.joints {joints}")
            if loc.structural_mode_hz is not None:
                self._check_structural_mode(loc)
        return self

    def _check_structural_mode(self, loc):
        """A location read through its structure's mode: the joint stays stiff (its own first_mode_hz
        would count the compliance twice) and the samples resolve the mode."""
        joint = next(j for j in self.target.joints if j.name == loc.joint)
        if joint.member is not None:
            raise ValueError(f"structures: weak location '{loc.name}': structural_mode_hz reads the loads of joint "
                             f"'{joint.name}' through a mode, but that joint already has its member's compliance in "
                             f"the dynamics; give the structure's compliance in one place")
        if joint.first_mode_hz is not None:
            raise ValueError(f"structures: weak location '{loc.name}': structural_mode_hz reads the loads of joint "
                             f"'{joint.name}' through a mode, but that joint already has first_mode_hz = "
                             f"{joint.first_mode_hz:g} Hz in the dynamics; give the structure's mode in one place")
        if joint.rotation_modes is not None:
            raise ValueError(f"structures: weak location '{loc.name}': structural_mode_hz reads the loads of joint "
                             f"'{joint.name}' through a mode, but that joint already has rotation_modes in the "
                             f"dynamics; give the structure's mode in one place")
        high = max(np.atleast_1d(loc.structural_mode_hz))
        if self.simulation.output_rate < SAMPLES_PER_MODE_PERIOD * high:
            raise ValueError(f"structures: weak location '{loc.name}': structural_mode_hz up to {high:g} Hz needs "
                             f"simulation.output_rate >= {SAMPLES_PER_MODE_PERIOD * high:g} Hz "
                             f"({SAMPLES_PER_MODE_PERIOD} samples per period); got {self.simulation.output_rate:g} Hz")
        steps_per_sample = 1.0 / (self.simulation.output_rate * self.simulation.step)
        if abs(steps_per_sample - round(steps_per_sample)) > 1e-6 * steps_per_sample:
            raise ValueError(f"structures: weak location '{loc.name}': structural_mode_hz filters samples taken at a "
                             f"fixed interval, so 1 / simulation.output_rate must be a whole number of steps; got "
                             f"{steps_per_sample:g} steps per sample")

    @model_validator(mode="after")
    def _truth_damage_shapes(self):
        damage = self.perception.truth_damage if self.perception is not None else None
        if damage is None:
            return self
        count = len(self.target.bodies[0].shapes)
        bent = [b.shape for b in damage.bends]
        for key, indices in (("missing_shapes", damage.missing_shapes), ("bends[].shape", bent)):
            for index in indices:
                if index >= count:
                    raise ValueError(f"perception.truth_damage.{key}: shape {index} does not exist; "
                                     f"target.bodies[0] has shapes 0 to {count - 1}")
        if len(set(damage.missing_shapes)) == count:
            raise ValueError("perception.truth_damage.missing_shapes: removes every shape of target.bodies[0]; "
                             "at least one must remain")
        if set(damage.missing_shapes) & set(bent):
            raise ValueError(f"perception.truth_damage: shapes {sorted(set(damage.missing_shapes) & set(bent))} are "
                             "both missing and bent")
        if len(set(bent)) != len(bent):
            raise ValueError("perception.truth_damage.bends: a shape is bent at most once")
        return self

    @model_validator(mode="after")
    def _load_filters(self):
        """Every load filter's cut-off within 1/10 of the step's Nyquist frequency (the discrete filter follows the
        analogue one there) and sampled SAMPLES_PER_MODE_PERIOD (20) times per period by the output, as a modal reading."""
        default = self.structures.load_filter_hz if self.structures is not None else None
        for joint in self.target.joints:
            cutoff = joint.load_filter_hz or default
            if cutoff is None:
                continue
            highest = NYQUIST_FRACTION * 0.5 / self.simulation.step
            if cutoff > highest:
                raise ValueError(f"joint '{joint.name}': a load filter at {cutoff:g} Hz needs simulation.step <= "
                                 f"{NYQUIST_FRACTION * 0.5 / cutoff:g} s (cut-off within 1/10 of the step's Nyquist "
                                 f"frequency); got {self.simulation.step:g} s")
            if self.simulation.output_rate < SAMPLES_PER_MODE_PERIOD * cutoff:
                raise ValueError(f"joint '{joint.name}': a load filter at {cutoff:g} Hz needs simulation.output_rate "
                                 f">= {SAMPLES_PER_MODE_PERIOD * cutoff:g} Hz ({SAMPLES_PER_MODE_PERIOD} samples per "
                                 f"period); got {self.simulation.output_rate:g} Hz")
        return self

    @model_validator(mode="after")
    def _twin_coupled(self):
        if self.structures is not None and self.structures.twin and self.simulation.coupling == "sequential":
            raise ValueError("structures.twin checks the peaks of a coupled run; a sequential run (the seed paper's "
                             "method) drives the debris with recorded loads: use coupling = 'coupled' or twin = false")
        return self

    @model_validator(mode="before")
    @classmethod
    def _default_window_by_coupling(cls, data):
        # A hold seen over part of a coupled capture is not a hold (docs/structures.md, "The whole capture as the
        # judged window"), so coupled runs judge the capture unless the case says otherwise; the sequential method
        # (the seed paper's) judges its recorded history, which 'capture' cannot follow.
        if isinstance(data, dict) and isinstance(data.get("structures"), dict) and "window" not in data["structures"]:
            simulation = data.get("simulation")
            coupling = simulation.get("coupling", "coupled") if isinstance(simulation, dict) else "coupled"
            data = {**data, "structures": {**data["structures"],
                                           "window": "fixed" if coupling == "sequential" else "capture"}}
        return data

    @model_validator(mode="after")
    def _capture_window_coupled(self):
        if self.structures is not None and self.structures.window == "capture" and self.simulation.coupling == "sequential":
            raise ValueError("structures.window = 'capture' follows the net's motion relative to the debris; a "
                             "sequential run (the seed paper's method) has the net against a fixed wall: use "
                             "coupling = 'coupled' or window = 'fixed'")
        return self

    @model_validator(mode="after")
    def _closing_coupled_kernel(self):
        if self.net.closing is None:
            return self
        sim = self.simulation
        if sim.coupling == "sequential":
            raise ValueError("net.closing closes the net around free debris; a sequential run (the seed paper's "
                             "method) has the net against a fixed wall: use coupling = 'coupled' or remove [net.closing]")
        if sim.net_integration != "kernel" or sim.integrator != "VelocityVerlet":
            raise ValueError("net.closing reels the loop in inside the compiled kernel: it needs "
                             "simulation.net_integration = 'kernel' and integrator = 'VelocityVerlet'")
        if self.net.nodes_per_side < 4:
            raise ValueError(f"net.closing laces two perimeter nodes per side: nodes_per_side must be >= 4. "
                             f"Got {self.net.nodes_per_side} instead")
        return self

    @model_validator(mode="after")
    def _tether_coupled_kernel(self):
        if self.net.tether is None:
            return self
        sim = self.simulation
        if sim.coupling == "sequential":
            raise ValueError("net.tether ties the net to the chaser while it wraps free debris; a sequential run (the "
                             "seed paper's method) has the net against a fixed wall: use coupling = 'coupled' or "
                             "remove [net.tether]")
        if sim.net_integration != "kernel" or sim.integrator != "VelocityVerlet":
            raise ValueError("net.tether's force is evaluated inside the compiled kernel's net step: it needs "
                             "simulation.net_integration = 'kernel' and integrator = 'VelocityVerlet'")
        if self.chaser is not None:
            raise ValueError("net.tether's chaser holds station at a fixed anchor; [chaser] (a free chaser body "
                             "holding the net's rim) is not combined with it: remove one")
        return self

    @model_validator(mode="after")
    def _sequential_without_chaser(self):
        if self.simulation.coupling == "sequential" and self.chaser is not None:
            raise ValueError("simulation.coupling = 'sequential' (the seed paper's method, the net launched free "
                             "against a fixed target) takes no [chaser]; remove it or use coupling = 'coupled'")
        return self


# ---------------------------------------------------------------------------- loading
def _all_subclasses(model: type) -> list[type]:
    return [sub for direct in model.__subclasses__() for sub in [direct, *_all_subclasses(direct)]]


def _discriminator_tags() -> set:
    """The ``kind`` values that tag the members of a discriminated union (orbit, shape and
    section kinds): models whose ``kind`` admits exactly one value."""
    kinds = [get_args(model.model_fields["kind"].annotation)
             for model in _all_subclasses(Strict) if "kind" in model.model_fields]
    return {values[0] for values in kinds if len(values) == 1}


#: Tags pydantic puts in an error's location for the member of a plain union that failed
#: (``allowable_moment.constrained-float``); they name types, not keys.
_UNION_TAG = re.compile(r"constrained-\w+|(list|dict|nullable|function-\w+)\[.*\]")
#: Longest rendering of a rejected value in a message (characters).
MAX_SHOWN = 120


def _format_location(loc) -> str:
    parts, tag = [], False
    for item in loc:
        if isinstance(item, str) and _UNION_TAG.fullmatch(item):
            continue
        if isinstance(item, int):
            parts[-1] = f"{parts[-1]}[{item}]" if parts else f"[{item}]"
        elif item in _discriminator_tags() and not tag:
            tag = True  # a discriminator tag adds nothing for the user (a key after it may share its name)
            continue
        else:
            parts.append(str(item))
        tag = False
    return ".".join(parts) or "(top level)"


def format_validation_error(path: Path, error: ValidationError) -> str:
    """scikit-learn-style messages, one per problem: ``file: key.path: message. Got X instead.``

    Parameters
    ----------
    path : Path
        The case file, named in every line.
    error : pydantic.ValidationError
        The validation error of that file's content.

    Returns
    -------
    str
        One line per problem.
    """
    lines = []
    for e in error.errors():
        where = _format_location(e["loc"])
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            msg = "unknown key (check spelling; see 'riskassess schema')"
        elif "input" in e and e["type"] not in ("missing",) and not _is_table(e["input"]) \
                and "Got " not in msg:
            shown = repr(e["input"])
            shown = shown if len(shown) <= MAX_SHOWN else shown[:MAX_SHOWN] + "..."
            msg = f"{msg}. Got {shown} instead"
        if where == "(top level)" and re.match(r"[\w.\[\]]+: ", msg):
            where, msg = msg.split(": ", 1)   # a whole-case check that names its key itself
        lines.append(f"{path}: {where}: {msg}")
    return "\n".join(lines)


def _is_table(value) -> bool:
    """A table or a list of tables: too long to repeat in a message, which names its key instead."""
    return isinstance(value, dict) or (isinstance(value, list) and any(isinstance(v, dict) for v in value))


def load_model(path: str | Path, model: type[BaseModel]):
    """Read the TOML file ``path`` into the pydantic ``model`` (a stage's own case schema, e.g.
    towing or approach); raise :class:`CaseError` naming the file, every bad key and what is allowed.

    Parameters
    ----------
    path : str or Path
        The case file (TOML).
    model : type of pydantic.BaseModel
        The schema to validate against.

    Returns
    -------
    pydantic.BaseModel
        An instance of ``model``.
    """
    path = Path(path)
    try:
        return model.model_validate(read_toml(path))
    except ValidationError as exc:
        raise CaseError(format_validation_error(path, exc)) from None


def load_case(path: str | Path) -> Case:
    """Read and validate a net-impact case file; raise :class:`CaseError` naming every problem.

    Parameters
    ----------
    path : str or Path
        The case file (TOML); mesh and perception files it names are relative to its folder.

    Returns
    -------
    Case
    """
    return validate_case(read_toml(path), path)


def validate_case(raw: dict, path: str | Path) -> Case:
    """Validate the parsed content of the case file ``path`` (mesh paths are relative to it);
    raise :class:`CaseError` naming every problem. Sweeps call it for every varied case.

    Parameters
    ----------
    raw : dict
        Parsed TOML content (not modified).
    path : str or Path
        The file the content belongs to: named in errors, its folder resolves referenced files.

    Returns
    -------
    Case
        The validated case (files, sections and the net's reach checked).
    """
    path = Path(path)
    raw, problems = _with_perceived_mass_properties(raw, path.parent)
    if problems:
        raise CaseError("\n".join(f"{path}: {p}" for p in problems))
    try:
        case = Case.model_validate(raw)
    except ValidationError as exc:
        raise CaseError(format_validation_error(path, exc)) from None
    problems = _check_files(case, path.parent) + _check_sections(case)
    if not problems:
        problems = _check_reach(case, path.parent)
    if problems:
        raise CaseError("\n".join(f"{path}: {p}" for p in problems))
    return case


#: perception.json keys -> body keys, for ``mass_properties_from``.
PERCEIVED_KEYS = {"mass_kg": "mass", "center_of_mass_target_m": "center_of_mass", "inertia_target_kg_m2": "inertia"}


def _with_perceived_mass_properties(raw: dict, base: Path) -> tuple[dict, list[str]]:
    """Fill the mass properties of bodies that name a perception result; problems name the key.
    Anything not shaped like a case (bodies not a list, a file name not a string) is left to the
    schema, which names it."""
    target = raw.get("target")
    bodies = target.get("bodies") if isinstance(target, dict) else None
    if not isinstance(bodies, list) or not any(_perceived_source(b) for b in bodies):
        return raw, []
    raw = copy.deepcopy(raw)
    problems = []
    for i, body in enumerate(raw["target"]["bodies"]):
        source = _perceived_source(body)
        if source:
            problem = _fill_perceived(body, source, base)
            if problem:
                problems.append(f"target.bodies[{i}].mass_properties_from: {problem}")
    return raw, problems


def _perceived_source(body) -> str | None:
    source = body.get("mass_properties_from") if isinstance(body, dict) else None
    return source if isinstance(source, str) and source else None


def _fill_perceived(body: dict, source: str, base: Path) -> str | None:
    """Copy the estimates of the perception result ``source`` into ``body``; the problem, or None."""
    given = [k for k in PERCEIVED_KEYS.values() if k in body]
    if given:
        return f"the mass properties come from '{source}'; remove {given} from this body"
    try:
        path = resolve_reference(base, source, JSON_FILE_LIMIT)
        answer = json.loads(decode_utf8(read_limited(path, JSON_FILE_LIMIT), path, "perception.json"))
    except ValueError as exc:   # JSONDecodeError is a ValueError
        return f"perception result {exc}" if str(exc).startswith("'") else f"'{source}' is not a perception.json ({exc})"
    except RecursionError:
        return f"'{source}' is not a perception.json (nested too deeply)"
    if not isinstance(answer, dict):
        return f"'{source}' is not a perception.json (a JSON object is expected)"
    missing = [k for k in PERCEIVED_KEYS if answer.get(k) is None]
    if missing:
        reason = answer.get("not_observable") or (
            "estimated without the debris mesh (perception.model = 'none'): the CoM and inertia are in the first "
            "scan's frame, not the target frame" if answer.get("perception_model") == "none" else
            "tracked without the debris mesh after the mesh was found not to match the scans (model_check): the CoM "
            "and inertia are in the first scan's frame, not the target frame" if answer.get("body_frame") == "first_scan"
            else "keys missing")
        return f"'{source}' has no estimate of {missing}: {reason}"
    for source_key, body_key in PERCEIVED_KEYS.items():
        body[body_key] = answer[source_key]
    return None


def _check_files(case: Case, base: Path) -> list[str]:
    """Every mesh file a shape names (its keys of kind "file") is a regular file below the case's
    folder, at most MESH_FILE_LIMIT bytes."""
    problems = []
    for i, body in enumerate(case.target.bodies):
        for k, shape in enumerate(body.shapes):
            for key in (key.name for key in CONTACT_SHAPES[shape.kind].KEYS if key.value == "file"):
                try:
                    resolve_reference(base, getattr(shape, key), MESH_FILE_LIMIT)
                except ValueError as exc:
                    problems.append(f"target.bodies[{i}].shapes[{k}].{key}: mesh file {exc}")
    return problems


def _check_sections(case: Case) -> list[str]:
    problems = []
    for i, loc in enumerate(case.structures.weak_locations if case.structures else []):
        if loc.section is not None:
            try:
                section_properties(loc.section)
            except (ValueError, ArithmeticError) as exc:
                problems.append(f"structures.weak_locations[{i}].section: {exc}")
    return problems


def _check_reach(case: Case, base: Path) -> list[str]:
    """Reject a net that cannot reach the target before any simulation starts."""
    try:
        points = target_vertices_lvlh(case, base)
    except Exception as exc:  # noqa: BLE001 - trimesh's many file parsers raise many types on a malformed file
        return [f"target.bodies: a mesh file cannot be read as a triangle mesh ({type(exc).__name__}: {exc})"]
    launch = case.launch
    d = np.asarray(launch.direction, float) / np.linalg.norm(launch.direction)
    net_center = target_points_lvlh(case, launch.aim_point) - launch.distance * d
    relative = points - net_center
    along = relative @ d
    lateral = np.linalg.norm(relative - np.outer(along, d), axis=1)
    half_diagonal = case.net.side_length / np.sqrt(2.0)
    problems = []
    ahead = along > 0
    if not ahead.any():
        return ["launch.direction: the whole target is behind the net; the net flies away from it"]
    if lateral[ahead].min() > half_diagonal:
        problems.append(f"launch.direction: the net's path misses the target by "
                        f"{lateral[ahead].min() - half_diagonal:.2f} m beyond its half-diagonal "
                        f"{half_diagonal:.2f} m; it cannot reach")
    gap = along.min()
    first_step = launch.velocity * case.simulation.step
    if 0 < gap <= first_step:
        problems.append(f"launch.distance: the net would touch the target within the first step "
                        f"({first_step:.2g} m of travel); start it farther than {launch.distance - gap + first_step:.3f} m")
    if gap <= 0:
        problems.append(f"launch.distance: the net plane starts {-gap:.2f} m inside the target; "
                        f"increase distance to more than {launch.distance - gap:.2f} m")
    elif gap > launch.velocity * case.simulation.end_time:
        problems.append(f"launch.distance: the net needs {gap / launch.velocity:.2f} s to reach the target but "
                        f"simulation.end_time is {case.simulation.end_time:g} s")
    return problems
