"""The case models described for people: docs/case-format.md and the report's input tables.

``python -m riskassess.cases.doc > docs/case-format.md`` regenerates the format page.
"""
from __future__ import annotations

import re
from typing import get_args

from pydantic import AfterValidator, BaseModel

from riskassess.cases import impact as c
from riskassess.cases import inputs as limits
from riskassess.cases.inputs import MEASURED_FILE_LIMIT

HEADER = """# Case file format

Case files are TOML. Every quantity is SI (m, kg, s, N, Pa, rad). Frames: **LVLH** (chaser-centred,
x radial, y along-track, z cross-track) and the **target frame** (the debris frame of the case; its
pose at t = 0 is `target.position_lvlh` and `target.attitude_rotation_vector`). Unknown keys,
wrong types, values out of range, joints naming missing bodies, missing mesh files and nets
that cannot reach the target are rejected on load, each error naming the file and the key path.
`riskassess schema` prints the same as JSON schema; `cases/envisat_net_impact.toml` is an annotated example.

This page is generated from `riskassess/cases/impact.py` (`python -m riskassess.cases.doc`).
"""

KINDS = """## Case kinds

Every case file starts with its kind: `kind = "impact"` (run, assess, perceive, sweep), `"towing"` (tow,
identify), `"approach"` or `"diagnosis"`; a diagnosis file adds its scenario: `scenario = "tumbling_rigid"`,
`"hinged_appendage"`, `"towing"` or `"impact"` (docs/diagnosis.md). Files written before the kind was explicit (no
`kind`; a diagnosis file with its scenario in `kind`) are read as before: the kind is told from their tables.
An unknown kind is refused with the list of kinds.
"""

REFUSED = f"""## What the checker refuses

Every case kind (impact, towing, diagnosis, approach; `riskassess validate` takes any of them) is checked
on load, before any work; each error names the file, the key and what is allowed.

- **Numbers**: NaN and infinities (`nan`, `inf` and the strings `"nan"`, `"inf"`), and any number beyond
  +-{limits.MAX_MAGNITUDE:g} (no physical input comes near it: the largest, the Earth's mu, is 3.986e14;
  larger values overflow the checks' arithmetic). Cross-section dimensions are at most 20 m.
- **Types are strict**: a number written as a string (`"0.2"`), a boolean as a string or a number
  (`"no"`, `0`), an integer key given a float (`nodes_per_side = 15.0`) are refused. A TOML integer is
  accepted where a float is expected (`mass = 350`).
- **Names**: the case `name` becomes the default output folder `runs/<name>`, so it is 1 to 64 letters,
  digits, `.`, `_` or `-`, starting with a letter or digit (`{limits.CASE_NAME_PATTERN}`); `"../x"`, an
  absolute path and `""` are refused. Body, joint and weak-location names follow the same rule but start
  with a letter (`{limits.ITEM_NAME_PATTERN}`), so a sweep key such as `target.joints[hinge]` never reads a
  name as an index. Each body, joint, weak location and (diagnosis) effect id appears once.
- **Text** (`description`, `reference.source`): at most {limits.MAX_TEXT} characters, no control characters
  other than newline and tab.
- **Files a case names** (a mesh `file`, `mass_properties_from`, a diagnosis case's `towing` or `impact`): a path
  relative to the case file, in its folder or below: no absolute path and no `..` component. The file must
  be a regular file (a directory, a device such as /dev/zero or a pipe is refused), at most
  {limits.MESH_FILE_LIMIT:,} bytes for a mesh, {limits.JSON_FILE_LIMIT:,} bytes for a perception.json and
  {limits.CASE_FILE_LIMIT:,} bytes for a towing case; the size is checked before reading. A symbolic link is
  followed and its target checked the same way. `riskassess diagnose` copies a towing case's towing file
  into its output folder, so the copies there load too.
- **The case file itself**: a regular file of at most {limits.CASE_FILE_LIMIT:,} bytes (the largest shipped
  case is about 9 kB), UTF-8 (otherwise the error names the file and the first bad byte), tables and
  arrays nested at most {limits.MAX_NESTING} levels deep (the shipped cases nest 5).
- **Measured data** (`riskassess diagnose --measured FILE`): a regular UTF-8 file of at most
  {MEASURED_FILE_LIMIT:,} bytes; a byte-order mark before `time` is accepted; every cell a finite number,
  empty or `nan` for a missing sample.
"""

SECTIONS = [
    ("[simulation]", c.Simulation), ('[orbit] kind = "circular"', c.CircularOrbit), ('[orbit] kind = "none"', c.NoOrbit),
    ("[net]", c.Net), ("[net.thread]", c.Thread), ("[net.closing] (optional)", c.Closing), ("[net.tether] (optional)", c.Tether), ("[bullets]", c.Bullets),
    ("[launch]", c.Launch),
    ("[contact]", c.Contact), ("[target]", c.Target), ("[[target.bodies]]", c.Body),
    *((f'shapes: kind = "{name}"', model) for name, model in c.SHAPE_MODELS.items()),
    ("[[target.joints]]", c.Joint), ("member (optional, in a clamped joint)", c.Member),
    ("rotation_modes (optional, in a joint)", c.RotationModes),
    ("[chaser] (optional)", c.Chaser),
    ("[perception] (optional; for riskassess perceive)", c.Perception), ("[perception.lidar]", c.Lidar),
    ("[perception.registration]", c.Registration), ("[perception.truth_damage] (optional)", c.TruthDamage),
    ("[[perception.truth_damage.bends]]", c.Bend), ("[structures] (optional)", c.Structures),
    ("[monte_carlo] (optional; for riskassess assess --monte-carlo)", c.MonteCarlo),
    ("[[structures.weak_locations]]", c.WeakLocationSpec), ("material", c.Material),
    *((f'section: kind = "{name}"', model) for name, model in c.SECTION_MODELS.items()),
]


#: Symbols a unit in a field description may be built from (SI only, see the header).
UNIT_SYMBOLS = {"m", "kg", "s", "N", "J", "Pa", "rad", "Hz", "-"}


def _is_unit(text: str) -> bool:
    tokens = [t.split("^")[0] for t in re.split(r"[ /]", text.strip()) if t]
    return bool(tokens) and all(t in UNIT_SYMBOLS for t in tokens)


def field_unit(field) -> str:
    """The SI unit a field's description states in parentheses, e.g. 'N m/rad'; '' if none.

    Parameters
    ----------
    field : pydantic.fields.FieldInfo
        A case-model field; its ``description`` is searched.

    Returns
    -------
    str
        The first parenthesised group built only of :data:`UNIT_SYMBOLS`, or ''.
    """
    for group in re.findall(r"\(([^()]*)\)", field.description or ""):
        if _is_unit(group):
            return group
    return ""


def _models_in(annotation) -> list[type[BaseModel]]:
    """The case models an annotation can hold (through lists, unions and Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in get_args(annotation) for m in _models_in(arg)]


def key_unit(key: str) -> str:
    """The unit of a case key such as 'launch.velocity' or 'target.joints[hinge].torsional_damping'.

    Parameters
    ----------
    key : str
        Dotted path into an impact case (:class:`~riskassess.cases.impact.Case`); list selectors
        ``[...]`` are ignored.

    Returns
    -------
    str
        The SI unit of the field (:func:`field_unit`); '' for an unknown key or a field without unit.
    """
    models, field = [c.Case], None
    for part in re.sub(r"\[[^\]]*\]", "", key).split("."):
        field = next((m.model_fields[part] for m in models if part in m.model_fields), None)
        if field is None:
            return ""
        models = _models_in(field.annotation)
    return field_unit(field) if field is not None else ""


def _format_leaf(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list) and value and all(isinstance(v, (int, float)) for v in value):
        return "[" + ", ".join(_format_leaf(float(v)) for v in value) + "]"
    if isinstance(value, list) and value and all(isinstance(v, list) for v in value):
        return "[" + ", ".join(_format_leaf(v) for v in value) + "]"
    return str(value)


def _compact_model(model: BaseModel) -> str:
    """One-line description of a small nested model (a shape, a section, a material)."""
    parts = []
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        if value is None or name == "kind":
            continue
        unit = field_unit(field)
        parts.append(f"{name} {_format_leaf(value)}{' ' + unit if unit and unit != '-' else ''}")
    kind = getattr(model, "kind", None)
    return (f"{kind}: " if kind else "") + ", ".join(parts)


#: Nested models shown as one line each in input tables (they are details of their parent).
COMPACT = (*c.SHAPE_MODELS.values(), *c.SECTION_MODELS.values(), c.Material)


def input_rows(model: BaseModel, prefix: str = "") -> list[tuple[str, str, str, str]]:
    """Every input of a validated case as rows (key path, value, unit, meaning), in file order.

    List items are keyed by their ``name`` where they have one (``target.bodies[solar_array]``);
    shapes, sections and materials are one row each.

    Parameters
    ----------
    model : pydantic.BaseModel
        A validated case or one of its tables.
    prefix : str
        Key path of ``model`` in the case, ending in '.' (``""`` for the case itself).

    Returns
    -------
    list of (str, str, str, str)
        Key path, formatted value, SI unit ('' if none) and the field's description.
    """
    rows = []
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        key = f"{prefix}{name}"
        if value is None or (name == "name" and prefix.endswith("].")):  # the key already names the item
            continue
        if isinstance(value, COMPACT):
            rows.append((key, _compact_model(value), "", field.description or ""))
        elif isinstance(value, BaseModel):
            rows += input_rows(value, key + ".")
        elif isinstance(value, list) and value and isinstance(value[0], BaseModel):
            for k, item in enumerate(value):
                label = f"{key}[{getattr(item, 'name', k)}]"
                rows += ([(label, _compact_model(item), "", field.description or "")] if isinstance(item, COMPACT)
                         else input_rows(item, label + "."))
        else:
            rows.append((key, _format_leaf(value), field_unit(field), field.description or ""))
    return rows


def model_table(model: type[BaseModel]) -> str:
    """The keys of one case model as a Markdown table (key, required, default, meaning with limits).

    Parameters
    ----------
    model : type of pydantic.BaseModel
        A case-model class; its ``kind`` field is left out.

    Returns
    -------
    str
        Markdown table, one row per field.
    """
    rows = ["| key | required | default | meaning |", "|---|---|---|---|"]
    for name, field in model.model_fields.items():
        if name == "kind":
            continue
        limits = "; ".join(str(m) for m in field.metadata if not isinstance(m, AfterValidator))
        meaning = (field.description or "") + (f" ({limits})" if limits else "")
        default = "" if field.is_required() else repr(field.default)
        rows.append(f"| `{name}` | {'yes' if field.is_required() else ''} | {default} | {meaning} |")
    return "\n".join(rows)


def render() -> str:
    parts = [HEADER, KINDS, REFUSED]
    for title, model in SECTIONS:
        parts.append(f"## {title}\n\n{model_table(model)}\n")
    return "\n".join(parts)


if __name__ == "__main__":
    print(render(), end="")
