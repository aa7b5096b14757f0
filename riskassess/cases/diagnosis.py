"""Case files of `riskassess diagnose`: a scenario the tool simulates and compares with measured data.

One TOML file, validated on load (:func:`load_diagnosis_case`) into one of the scenario models
picked by the top-level ``kind``:

* ``"tumbling_rigid"``: one rigid debris body tumbling freely (torque-free nominal).
* ``"hinged_appendage"``: a main body and an appendage on a revolute hinge with a torsional
  spring-damper, released from an initial hinge angle and rate; no external load in the nominal.
* ``"towing"``: post-capture towing, the lower-order tethered model (:mod:`multibody.towing`) of a
  towing case file that the diagnosis case names (``towing = "zenit2_towing.toml"``, relative to
  the diagnosis case; its tethers, masses, thrust law and initial state are the nominal model).
* ``"impact"``: the net capture, the coupled Exudyn impact simulation of an impact case file that
  the diagnosis case names (``impact = "envisat_small.toml"``); the record is the debris main
  body's motion after the capture, its times from the impact case's t = 0 (the launch).

Frames: **target frame** = the main body's reference frame; the main body frame has the same
axes and its origin at the main body's CoM. **LVLH** is chaser-centred (x radial, y along-track,
z orbit normal); it rotates at the orbit's mean motion about z. The inertial frame used by the
dynamics is LVLH at t = 0. Time 0 is the epoch of the initial state; measured times use it.
"""
from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal, Optional, Union, get_args

import numpy as np
from pydantic import Field, PrivateAttr, RootModel, ValidationError, ValidationInfo, field_validator, model_validator

from riskassess.cases import impact
from riskassess.cases.impact import (CaseError, NonNegative, NoOrbit, Positive, Strict, Vector3, check_physical_inertia,
                                    format_validation_error, load_model, read_toml)
from riskassess.cases.inputs import CASE_FILE_LIMIT, CaseName, RelativeFile, Text, resolve_reference, unique_names
from riskassess.cases.towing import TowingCase

Matrix3 = Annotated[list[Vector3], Field(min_length=3, max_length=3)]


class MainBody(Strict):
    mass: Positive = Field(description="Mass of the (main) body (kg).")
    center_of_mass: Vector3 = Field([0.0, 0.0, 0.0], description="CoM, target frame (m).")
    inertia: Matrix3 = Field(description="Inertia about the CoM, target-frame axes (kg m^2).")

    @field_validator("inertia")
    @classmethod
    def _physical(cls, j):
        return check_physical_inertia(j)


class Appendage(Strict):
    mass: Positive = Field(description="Mass of the appendage (kg).")
    com_offset_from_hinge: Vector3 = Field(
        description="Appendage CoM minus hinge point at zero hinge angle, target frame (m).")
    inertia: Matrix3 = Field(description="Inertia about the appendage CoM at zero hinge angle, target-frame axes (kg m^2).")

    @field_validator("inertia")
    @classmethod
    def _physical(cls, j):
        return check_physical_inertia(j)


class Hinge(Strict):
    position: Vector3 = Field(description="Hinge point, target frame (m).")
    axis: Vector3 = Field(description="Hinge axis, target frame (-); normalised on load. The hinge angle is the "
                                      "appendage's rotation about it relative to the main body.")
    torsional_stiffness: NonNegative = Field(0.0, description="Linear torsional spring about the axis (N m/rad); "
                                                              "rest at zero hinge angle.")
    torsional_damping: NonNegative = Field(0.0, description="Viscous torsional damping about the axis (N m s/rad).")
    initial_angle: float = Field(0.0, description="Hinge angle at t = 0 (rad).")
    initial_rate: float = Field(0.0, description="Hinge rate at t = 0 (rad/s).")

    @field_validator("axis")
    @classmethod
    def _nonzero(cls, v):
        if np.linalg.norm(v) == 0:
            raise ValueError("axis must be a non-zero vector")
        return v


class InitialState(Strict):
    attitude_rotation_vector: Vector3 = Field([0.0, 0.0, 0.0], description="Target->LVLH rotation at t = 0 (rad).")
    angular_velocity: Vector3 = Field(description="Inertial angular velocity of the main body at t = 0, target "
                                                  "frame (rad/s).")
    position_lvlh: Vector3 = Field([0.0, 0.0, 0.0], description="Target-frame origin relative to the chaser at "
                                                                "t = 0, LVLH (m).")
    velocity_lvlh: Vector3 = Field([0.0, 0.0, 0.0], description="Velocity of the debris' centre of mass (all "
                                                                "bodies) relative to the chaser at t = 0, LVLH (m/s).")


class CircularOrbit(impact.CircularOrbit):
    """The impact case's circular orbit, placed in inertial space (the diagnosis models gravity
    gradient and J2, which depend on where the orbit lies)."""

    inclination: Annotated[float, Field(ge=0, le=np.pi)] = Field(0.0, description="Orbit inclination (rad).")
    argument_of_latitude: float = Field(0.0, description="Chaser's argument of latitude at t = 0 (rad), from the "
                                                         "ascending node (right ascension of the node 0).")


Orbit = Annotated[Union[CircularOrbit, NoOrbit], Field(discriminator="kind")]


class Uncertain(Strict):
    """1-sigma prior uncertainties of nominal parameters; the fit estimates every parameter given
    here (a Gaussian prior centred on the case value), 0 or absent = known exactly."""
    attitude: NonNegative = Field(0.0, description="Initial attitude, per axis (rad).")
    angular_velocity: NonNegative = Field(0.0, description="Initial angular velocity, per axis (rad/s).")
    position: NonNegative = Field(0.0, description="Initial position, per axis (m).")
    velocity: NonNegative = Field(0.0, description="Initial velocity, per axis (m/s).")
    hinge_angle: NonNegative = Field(0.0, description="Initial hinge angle (rad).")
    hinge_rate: NonNegative = Field(0.0, description="Initial hinge rate (rad/s).")
    torsional_stiffness: NonNegative = Field(0.0, description="Hinge torsional stiffness (N m/rad).")
    torsional_damping: NonNegative = Field(0.0, description="Hinge torsional damping (N m s/rad).")


class EffectEntry(Strict):
    id: str = Field(description="Effect id from the catalog (docs/diagnosis.md).")
    parameters: dict[str, float] = Field(description="Physical parameters by name, SI units (see the catalog).")


class Diagnosis(Strict):
    holdout_fraction: Annotated[float, Field(gt=0.05, lt=0.8)] = Field(
        0.3, description="Last fraction of the record kept out of the fit and used to score predictions (-).")
    decisive_delta_bic: Positive = Field(
        10.0, description="BIC difference that counts as decisive evidence (-); Kass & Raftery 1995: > 10 very strong.")
    adequate_rms: Annotated[float, Field(gt=1.0)] = Field(
        1.25, description="A model explains a channel when its residual RMS is below this multiple of the noise (-).")


class _ScenarioBase(Strict):
    name: CaseName = Field(description="Case name; default output folder runs/<name>-diagnosis.")
    description: Text = ""
    main_body: MainBody
    initial: InitialState
    orbit: Orbit = NoOrbit(kind="none")
    uncertain: Uncertain = Uncertain()
    diagnosis: Diagnosis = Diagnosis()
    effects: list[EffectEntry] = Field([], description="Effects switched on in this model (an extended case).")

    @field_validator("effects")
    @classmethod
    def _unique(cls, effects):
        return unique_names(effects, "effect", "id")

    @model_validator(mode="after")
    def _known_effects(self, info: ValidationInfo):
        return _check_effects(self, info)


def _check_effects(case, info: ValidationInfo):
    """Every ``[[effects]]`` entry names a catalog effect that applies and gives its parameters.

    The catalog (effect id -> :class:`riskassess.diagnosis.effects.base.Effect`) comes in the
    validation context (``effect_catalog``), given by the diagnosis package's loader
    (:func:`riskassess.diagnosis.cases.load_diagnosis_case`): the schema sits below the effects and
    does not import them. Effects without a catalog to check them against are refused."""
    if not case.effects:
        return case
    CATALOG = (info.context or {}).get("effect_catalog")
    if CATALOG is None:
        raise ValueError("effects: no effect catalog to check them against (load the case with "
                         "riskassess.diagnosis.cases.load_diagnosis_case)")
    for k, entry in enumerate(case.effects):
        if entry.id not in CATALOG:
            raise ValueError(f"effects[{k}].id: '{entry.id}' is not in the catalog {sorted(CATALOG)}")
        if case.kind not in CATALOG[entry.id].scenarios:
            raise ValueError(f"effects[{k}].id: '{entry.id}' does not apply to the '{case.kind}' scenario")
        names = [p.name for p in CATALOG[entry.id].parameter_specs(case)]
        unknown = sorted(set(entry.parameters) - set(names))
        missing = [] if getattr(CATALOG[entry.id], "partial_parameters", False) else \
            sorted(set(names) - set(entry.parameters))
        if unknown or missing:
            raise ValueError(f"effects[{k}] ({entry.id}).parameters: expected {names}; unknown {unknown}, "
                             f"missing {missing}")
    return case


class TumblingRigidCase(_ScenarioBase):
    kind: Literal["tumbling_rigid"]


class HingedAppendageCase(_ScenarioBase):
    kind: Literal["hinged_appendage"]
    appendage: Appendage
    hinge: Hinge


class TowingUncertain(Strict):
    """1-sigma priors of the towing scenario's nominal parameters (the debris' initial state); 0 or
    absent = known exactly."""
    attitude: NonNegative = Field(0.0, description="Initial debris attitude, per axis of the debris frame (rad).")
    angular_velocity: NonNegative = Field(0.0, description="Initial debris angular velocity, per axis (rad/s).")
    position: NonNegative = Field(0.0, description="Initial debris position relative to the chaser, per LVLH axis (m).")
    velocity: NonNegative = Field(0.0, description="Initial debris velocity relative to the chaser, per LVLH axis (m/s).")


class TowingInitial(Strict):
    """The debris' state at the record's t = 0 where it differs from the towing case's (an extended
    case written by the diagnosis carries the fitted values). LVLH: the chaser's, at t = 0."""
    attitude_change: Vector3 = Field([0.0, 0.0, 0.0], description="Rotation vector composed after the towing case's "
                                                                   "debris attitude, debris frame (rad).")
    angular_velocity: Optional[Vector3] = Field(None, description="Debris inertial angular velocity, debris frame "
                                                                  "(rad/s); default: the towing case's spin.")
    position_lvlh: Optional[Vector3] = Field(None, description="Debris target-frame origin (its CoM in the towing "
                                                               "case) minus the chaser CoM, LVLH axes (m).")
    velocity_lvlh: Optional[Vector3] = Field(None, description="Debris CoM velocity minus the chaser's (inertial "
                                                               "derivative), LVLH axes (m/s).")


class TowingDiagnosisCase(Strict):
    """Post-capture towing: the lower-order model of the towing case ``towing`` is the nominal."""
    kind: Literal["towing"]
    name: CaseName = Field(description="Case name; default output folder runs/<name>-diagnosis.")
    description: Text = ""
    towing: RelativeFile = Field(description="Towing case file (riskassess/cases/towing.py), relative to this file, in "
                                             "its folder or below: tethers, masses, thrust law, attitude control and "
                                             "the state at the record's t = 0.")
    fit_step: Annotated[float, Field(gt=0, le=0.05)] = Field(
        0.02, description="Step of the fit's towing runs (s); the identification's step (docs/towing.md: within 2 % "
                          "of the paper's RMSE scales at 20 ms).")
    initial: TowingInitial = TowingInitial()
    uncertain: TowingUncertain = TowingUncertain()
    diagnosis: Diagnosis = Diagnosis()
    effects: list[EffectEntry] = Field([], description="Effects switched on in this model (an extended case).")
    _towing_case: object = PrivateAttr(None)

    @field_validator("effects")
    @classmethod
    def _unique(cls, effects):
        return unique_names(effects, "effect", "id")

    @model_validator(mode="after")
    def _load_towing(self, info: ValidationInfo):
        base = Path((info.context or {}).get("case_dir", "."))
        try:
            path = resolve_reference(base, self.towing, CASE_FILE_LIMIT)
        except ValueError as exc:
            raise ValueError(f"towing: towing case {exc}") from None
        try:
            self._towing_case = load_model(path, TowingCase)
        except CaseError as exc:
            raise ValueError(f"towing: the towing case cannot be loaded: {exc}") from None
        return _check_effects(self, info)

    @property
    def towing_case(self):
        """The validated :class:`riskassess.cases.towing.TowingCase`."""
        return self._towing_case


class ImpactFit(Strict):
    """How the impact scenario compares the record with the coupled simulation (docs/diagnosis.md,
    "Impact scenario")."""
    window: Annotated[float, Field(gt=0, le=10.0)] = Field(
        0.5, description="Length of the windows over which the record and the simulation are averaged (s): the "
                         "fit compares window means of the main body's CoM velocity and body rates.")
    ensemble: Annotated[int, Field(ge=2, le=16)] = Field(
        4, description="Runs of the nominal model with the launch speed perturbed by +-k x 'perturbation' "
                       "(k = 1, 2, ...): their spread is the model's chaotic run-to-run error, added to the noise.")
    perturbation: Annotated[float, Field(gt=0, le=1e-3)] = Field(
        1e-7, description="Relative launch-speed perturbation of the ensemble runs (-).")
    grid: Annotated[int, Field(ge=3, le=15)] = Field(
        5, description="Simulations per effect on the first pass over its parameter range (-); three more refine it.")


class ImpactDiagnosisCase(Strict):
    """The net capture: the coupled impact simulation of the impact case ``impact`` is the nominal."""
    kind: Literal["impact"]
    name: CaseName = Field(description="Case name; default output folder runs/<name>-diagnosis.")
    description: Text = ""
    impact: RelativeFile = Field(description="Impact case file (riskassess/cases/impact.py), relative to this file, in "
                                             "its folder or below: net, launch, contact law and debris.")
    fit: ImpactFit = ImpactFit()
    diagnosis: Diagnosis = Diagnosis()
    effects: list[EffectEntry] = Field([], description="Impact-model effects set in this model (an extended case): "
                                                       "their parameters replace the impact case's values.")
    _impact_case: object = PrivateAttr(None)
    _impact_path: object = PrivateAttr(None)

    @field_validator("effects")
    @classmethod
    def _unique(cls, effects):
        return unique_names(effects, "effect", "id")

    @model_validator(mode="after")
    def _load_impact(self, info: ValidationInfo):
        base = Path((info.context or {}).get("case_dir", "."))
        try:
            path = resolve_reference(base, self.impact, CASE_FILE_LIMIT)
        except ValueError as exc:
            raise ValueError(f"impact: impact case {exc}") from None
        try:
            self._impact_case = impact.load_case(path)
        except CaseError as exc:
            raise ValueError(f"impact: the impact case cannot be loaded: {exc}") from None
        if self._impact_case.simulation.coupling != "coupled":
            raise ValueError("impact: the diagnosis simulates the net and the debris together; the impact case "
                             "needs simulation.coupling = 'coupled'")
        self._impact_path = path
        return _check_effects(self, info)

    @property
    def impact_case(self):
        """The validated :class:`riskassess.cases.impact.Case`."""
        return self._impact_case

    @property
    def impact_path(self) -> Path:
        """The impact case file's path."""
        return self._impact_path


DiagnosisCase = Union[TumblingRigidCase, HingedAppendageCase, TowingDiagnosisCase, ImpactDiagnosisCase]


#: The scenario kinds, as a file names them in ``scenario`` (or, written before case kinds, in ``kind``).
SCENARIOS = tuple(get_args(model.model_fields["kind"].annotation)[0] for model in get_args(DiagnosisCase))


class DiagnosisCaseFile(RootModel):
    root: Annotated[DiagnosisCase, Field(discriminator="kind")]

    @classmethod
    def model_json_schema(cls, *args, **kwargs) -> dict:
        """The schema of the file as written today: ``kind = "diagnosis"`` and the scenario in
        ``scenario`` (the models discriminate on ``kind``, see :func:`scenario_form`)."""
        schema = super().model_json_schema(*args, **kwargs)
        for ref in schema["oneOf"]:
            model = schema["$defs"][ref["$ref"].rsplit("/", 1)[1]]
            scenario = model["properties"].pop("kind")
            model["properties"] = {"kind": {"const": "diagnosis", "title": "Kind", "type": "string"},
                                   "scenario": {**scenario, "title": "Scenario"}, **model["properties"]}
            model["required"] = ["kind", "scenario"] + [k for k in model["required"] if k != "kind"]
        schema["discriminator"]["propertyName"] = "scenario"
        return schema


def scenario_form(raw: dict) -> dict:
    """The file's content with its scenario as the ``kind`` the scenario models discriminate on: a
    file says ``kind = "diagnosis"`` and ``scenario = "towing"``; files written before case kinds
    were explicit say ``kind = "towing"`` (the scenario) and are read as they are.

    Parameters
    ----------
    raw : dict
        Parsed TOML of a diagnosis case file (not modified).

    Returns
    -------
    dict
        A copy with ``kind`` = the scenario and no ``scenario`` key; ``raw`` itself when it has no
        ``kind = "diagnosis"``.
    """
    if raw.get("kind") != "diagnosis":
        return raw
    raw = dict(raw)
    del raw["kind"]
    if "scenario" in raw:
        raw["kind"] = raw.pop("scenario")
    return raw


def diagnosis_case_from_dict(raw: dict, case_dir=".", effect_catalog=None) -> DiagnosisCase:
    """Validate parsed case content; file references (``towing``) are relative to ``case_dir``;
    ``[[effects]]`` are checked against ``effect_catalog`` (id -> effect; required when there are any).

    Parameters
    ----------
    raw : dict
        Parsed TOML of a diagnosis case file.
    case_dir : str or Path
        Folder of the case file; referenced files are resolved against it.
    effect_catalog : dict or None
        Effect id -> effect (:mod:`riskassess.diagnosis`), for ``[[effects]]``.

    Returns
    -------
    DiagnosisCase
        The scenario model (tumbling_rigid, hinged_appendage, towing or impact).

    Raises
    ------
    pydantic.ValidationError
        For content that does not fit the schema.
    """
    context = {"case_dir": str(case_dir), "effect_catalog": effect_catalog}
    return DiagnosisCaseFile.model_validate(scenario_form(raw), context=context).root


def load_diagnosis_case(path, effect_catalog=None) -> DiagnosisCase:
    """Read and validate a diagnosis case; :class:`~riskassess.cases.impact.CaseError` names file and key.
    ``effect_catalog``: as in :func:`diagnosis_case_from_dict`.

    Parameters
    ----------
    path : str or Path
        The case file (TOML).
    effect_catalog : dict or None
        Effect id -> effect, for the case's ``[[effects]]``.

    Returns
    -------
    DiagnosisCase
    """
    path = Path(path)
    try:
        return diagnosis_case_from_dict(read_toml(path), path.parent, effect_catalog)
    except ValidationError as exc:
        raise CaseError(format_validation_error(path, exc)) from None


# ---------------------------------------------------------------------------- writing
def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, str):
        import json

        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def toml_text(data: dict, prefix: str = "") -> str:
    """TOML text of a case dictionary (scalars and lists, tables, arrays of tables); enough for the
    case files, which hold nothing else.

    Parameters
    ----------
    data : dict
        The case content: scalars, lists of scalars, tables (dict) and arrays of tables (list of dict).
    prefix : str
        Dotted key path of ``data`` inside the file (``""`` at the top level), for table headers.

    Returns
    -------
    str
        TOML text, without a trailing newline.
    """
    lines = [f"{k} = {_toml_value(v)}" for k, v in data.items()
             if not isinstance(v, dict) and not (isinstance(v, list) and v and isinstance(v[0], dict))]
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            lines += ["", f"[{name}]", toml_text(value, f"{name}.")]
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for item in value:
                lines += ["", f"[[{name}]]", toml_text(item, f"{name}.")]
    return "\n".join(line for line in lines if line is not None).strip("\n")
