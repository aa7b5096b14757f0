"""Cross-section ``circular_tube``: its properties and the formulas they come from (:func:`circular_tube`)."""
from __future__ import annotations

import math

from structures.section_base import SectionProperties, bending_properties

#: The name a case gives (``section = { kind = "circular_tube", ... }``).
NAME = "circular_tube"
#: Its dimensions (m), in the order :func:`properties` takes them, with their meaning.
DIMENSIONS = {
    "outer_diameter": "(m)",
    "wall": "Wall thickness (m); outer_diameter / 2 for a solid shaft.",
}


def circular_tube(outer_diameter: float, wall: float) -> SectionProperties:
    """Circular tube (a solid shaft when wall = outer_diameter / 2): exact A, I and polar
    J = 2 I; torsion T r / J; transverse shear V Q / (I (D - d)) with Q = (D^3 - d^3) / 12,
    which gives 2 V / A for thin tubes and 4 V / (3 A) for solid shafts.

    Parameters
    ----------
    outer_diameter : float
        Outer diameter D (m).
    wall : float
        Wall thickness (m), in (0, D / 2].

    Returns
    -------
    SectionProperties
        Per-unit-load peak stresses, section frame (bending combined as a resultant).

    Raises
    ------
    ValueError
        For a wall outside (0, D / 2].
    """
    d_out, t = outer_diameter, wall
    if not 0.0 < t <= d_out / 2.0:
        raise ValueError(f"circular_tube: wall must be in (0, outer_diameter/2 = {d_out / 2:g} m]. Got {t:g} instead")
    d_in = d_out - 2.0 * t
    area = math.pi * (d_out**2 - d_in**2) / 4.0
    i = math.pi * (d_out**4 - d_in**4) / 64.0
    shear = ((d_out**3 - d_in**3) / 12.0) / (i * (d_out - d_in))
    return bending_properties(area, i, i, d_out / 2.0, d_out / 2.0, (d_out / 2.0) / (2.0 * i), shear, shear, round_=True,
                              torsion_constant=2.0 * i)


#: The shape's section properties from its dimensions (m); ValueError for impossible ones.
properties = circular_tube
