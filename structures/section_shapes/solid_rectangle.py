"""Cross-section ``solid_rectangle``: its properties and the formulas they come from (:func:`solid_rectangle`)."""
from __future__ import annotations

from structures.section_base import SectionProperties, bending_properties

#: The name a case gives (``section = { kind = "solid_rectangle", ... }``).
NAME = "solid_rectangle"
#: Its dimensions (m), in the order :func:`properties` takes them, with their meaning.
DIMENSIONS = {
    "width": "Extent along section axis 2 (m).",
    "height": "Extent along section axis 3 (m).",
}


def solid_rectangle(width: float, height: float) -> SectionProperties:
    """Solid b x h rectangle. Torsion: tau_max = T (3a + 1.8b) / (a^2 b^2) with a >= b
    (Roark Table 10.1 case 4, within 4 % of the exact series); transverse shear 1.5 V / A.

    Parameters
    ----------
    width : float
        Extent along section axis 2 (m).
    height : float
        Extent along section axis 3 (m).

    Returns
    -------
    SectionProperties
        Per-unit-load peak stresses, section frame.
    """
    b, h = width, height
    a, c = max(b, h), min(b, h)
    area = b * h
    return bending_properties(area, b * h**3 / 12.0, h * b**3 / 12.0, b / 2.0, h / 2.0,
                    (3.0 * a + 1.8 * c) / (a**2 * c**2), 1.5 / area, 1.5 / area)


#: The shape's section properties from its dimensions (m); ValueError for impossible ones.
properties = solid_rectangle
