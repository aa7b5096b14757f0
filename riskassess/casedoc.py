"""Generate docs/case-format.md from the case models: ``python -m riskassess.casedoc > docs/case-format.md``."""
from __future__ import annotations

from pydantic import BaseModel

from riskassess import case as c

HEADER = """# Case file format

Case files are TOML. Every quantity is SI (m, kg, s, N, Pa, rad). Frames: **LVLH** (chaser-centred,
x radial, y along-track, z cross-track) and the **target frame** (the debris frame of the case; its
pose at t = 0 is `target.position_lvlh` and `target.attitude_rotation_vector`). Unknown keys,
wrong types, values out of range, joints naming missing bodies, missing mesh files and nets
that cannot reach the target are rejected on load, each error naming the file and the key path.
`riskassess schema` prints the same as JSON schema; `cases/envisat_net_impact.toml` is an annotated example.

This page is generated from `riskassess/case.py` (`python -m riskassess.casedoc`).
"""

SECTIONS = [
    ("[simulation]", c.Simulation), ('[orbit] kind = "circular"', c.CircularOrbit), ('[orbit] kind = "none"', c.NoOrbit),
    ("[net]", c.Net), ("[net.thread]", c.Thread), ("[bullets]", c.Bullets), ("[launch]", c.Launch),
    ("[contact]", c.Contact), ("[target]", c.Target), ("[[target.bodies]]", c.Body),
    ('shapes: kind = "box"', c.Box), ('shapes: kind = "cylinder"', c.Cylinder), ('shapes: kind = "sphere"', c.Sphere),
    ('shapes: kind = "mesh"', c.MeshFile), ("[[target.joints]]", c.Joint), ("[structures] (optional)", c.Structures),
    ("[[structures.weak_locations]]", c.WeakLocationSpec), ("material", c.Material),
    ('section: kind = "solid_rectangle"', c.SolidRectangle), ('section: kind = "hollow_rectangle"', c.HollowRectangle),
    ('section: kind = "thin_walled_box"', c.ThinWalledBox), ('section: kind = "circular_tube"', c.CircularTube),
    ('section: kind = "i_section"', c.ISection),
]


def model_table(model: type[BaseModel]) -> str:
    rows = ["| key | required | default | meaning |", "|---|---|---|---|"]
    for name, field in model.model_fields.items():
        if name == "kind":
            continue
        limits = "; ".join(str(m) for m in field.metadata)
        meaning = (field.description or "") + (f" ({limits})" if limits else "")
        default = "" if field.is_required() else repr(field.default)
        rows.append(f"| `{name}` | {'yes' if field.is_required() else ''} | {default} | {meaning} |")
    return "\n".join(rows)


def render() -> str:
    parts = [HEADER]
    for title, model in SECTIONS:
        parts.append(f"## {title}\n\n{model_table(model)}\n")
    return "\n".join(parts)


if __name__ == "__main__":
    print(render(), end="")
