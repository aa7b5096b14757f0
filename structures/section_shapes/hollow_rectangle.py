"""Cross-section ``hollow_rectangle``: its properties and the formulas they come from (:func:`hollow_rectangle`)."""
from __future__ import annotations

from structures.section_base import SectionProperties, bending_properties

#: The name a case gives (``section = { kind = "hollow_rectangle", ... }``).
NAME = "hollow_rectangle"
#: Its dimensions (m), in the order :func:`properties` takes them, with their meaning.
DIMENSIONS = {
    "width": "Outer extent along section axis 2 (m).",
    "height": "Outer extent along section axis 3 (m).",
    "wall": "Uniform wall thickness (m).",
}


def hollow_rectangle(width: float, height: float, wall: float) -> SectionProperties:
    """Rectangular tube of uniform wall thickness: exact area and second moments (outer minus
    inner rectangle); torsion by Bredt, tau = T / (2 A_m t), A_m enclosed by the wall's
    midline; transverse shear V Q / (I 2t) at the neutral axis.

    Parameters
    ----------
    width : float
        Outer extent along section axis 2 (m).
    height : float
        Outer extent along section axis 3 (m).
    wall : float
        Uniform wall thickness (m), below half the smaller side.

    Returns
    -------
    SectionProperties
        Per-unit-load peak stresses, section frame.

    Raises
    ------
    ValueError
        For a wall that is not > 0 and < half the smaller side.
    """
    b, h, t = width, height, wall
    if not 0.0 < 2.0 * t < min(b, h):
        raise ValueError(f"hollow_rectangle: wall must be > 0 and < half the smaller side ({min(b, h) / 2:g} m). "
                         f"Got {t:g} instead")
    bi, hi = b - 2.0 * t, h - 2.0 * t
    area = b * h - bi * hi
    i2 = (b * h**3 - bi * hi**3) / 12.0
    i3 = (h * b**3 - hi * bi**3) / 12.0
    enclosed = (b - t) * (h - t)
    # first moment of the half section above the neutral axis, for shear along each axis
    q3 = b * h**2 / 8.0 - bi * hi**2 / 8.0
    q2 = h * b**2 / 8.0 - hi * bi**2 / 8.0
    return bending_properties(area, i2, i3, b / 2.0, h / 2.0, 1.0 / (2.0 * enclosed * t),
                    q2 / (i3 * 2.0 * t), q3 / (i2 * 2.0 * t))


#: The shape's section properties from its dimensions (m); ValueError for impossible ones.
properties = hollow_rectangle
