"""Cross-section ``thin_walled_box``: its properties and the formulas they come from (:func:`thin_walled_box`)."""
from __future__ import annotations

from structures.section_base import SectionProperties, bending_properties

#: The name a case gives (``section = { kind = "thin_walled_box", ... }``).
NAME = "thin_walled_box"
#: Its dimensions (m), in the order :func:`properties` takes them, with their meaning.
DIMENSIONS = {
    "width": "Midline extent along section axis 2 (m).",
    "height": "Midline extent along section axis 3 (m).",
    "flange_thickness": "Thickness of the two walls along axis 2 (m).",
    "web_thickness": "Thickness of the two walls along axis 3 (m).",
}


def thin_walled_box(width: float, height: float, flange_thickness: float, web_thickness: float) -> SectionProperties:
    """Thin-walled box: flanges (the walls along axis 2, thickness t_f) and webs (along
    axis 3, t_w), dimensions to the wall midlines, thin-wall approximations (Roark Table 10.1
    case 16 for torsion: tau = T / (2 A_m t) at the thinner wall).

    Parameters
    ----------
    width : float
        Midline extent along section axis 2 (m).
    height : float
        Midline extent along section axis 3 (m).
    flange_thickness : float
        Thickness t_f of the two walls along axis 2 (m), in (0, height / 2).
    web_thickness : float
        Thickness t_w of the two walls along axis 3 (m), in (0, width / 2).

    Returns
    -------
    SectionProperties
        Per-unit-load peak stresses, section frame.

    Raises
    ------
    ValueError
        For wall thicknesses outside those ranges.
    """
    b, h, tf, tw = width, height, flange_thickness, web_thickness
    if not (0.0 < tf < h / 2.0 and 0.0 < tw < b / 2.0):
        raise ValueError("thin_walled_box: flange_thickness must be in (0, height/2) and web_thickness in "
                         f"(0, width/2). Got {tf:g} and {tw:g} instead")
    area = 2.0 * b * tf + 2.0 * h * tw
    i2 = 2.0 * b * tf * (h / 2.0) ** 2 + 2.0 * tw * h**3 / 12.0
    i3 = 2.0 * h * tw * (b / 2.0) ** 2 + 2.0 * tf * b**3 / 12.0
    enclosed = b * h
    q3 = b * tf * h / 2.0 + 2.0 * tw * (h / 2.0) ** 2 / 2.0    # shear along axis 3: carried by the webs
    q2 = h * tw * b / 2.0 + 2.0 * tf * (b / 2.0) ** 2 / 2.0    # shear along axis 2: carried by the flanges
    return bending_properties(area, i2, i3, b / 2.0 + tw / 2.0, h / 2.0 + tf / 2.0, 1.0 / (2.0 * enclosed * min(tf, tw)),
                    q2 / (i3 * 2.0 * tf), q3 / (i2 * 2.0 * tw))


#: The shape's section properties from its dimensions (m); ValueError for impossible ones.
properties = thin_walled_box
