"""Cross-section ``i_section``: its properties and the formulas they come from (:func:`i_section`)."""
from __future__ import annotations

from structures.section_base import SectionProperties, bending_properties

#: The name a case gives (``section = { kind = "i_section", ... }``).
NAME = "i_section"
#: Its dimensions (m), in the order :func:`properties` takes them, with their meaning.
DIMENSIONS = {
    "height": "Overall depth along section axis 3, the web direction (m).",
    "flange_width": "Flange extent along section axis 2 (m).",
    "flange_thickness": "(m)",
    "web_thickness": "(m)",
}


def i_section(height: float, flange_width: float, flange_thickness: float, web_thickness: float) -> SectionProperties:
    """I-section, web along axis 3 (strong bending about axis 2). Exact A and I; torsion of
    an open section, tau = T t_max / J with J = sum b t^3 / 3; transverse shear along the
    web V Q / (I t_w) at the neutral axis, across the flanges V Q / (I 2 t_f).

    Parameters
    ----------
    height : float
        Overall depth along section axis 3, the web direction (m).
    flange_width : float
        Flange extent along section axis 2 (m).
    flange_thickness : float
        Thickness of each flange (m); 2 flange_thickness < height.
    web_thickness : float
        Thickness of the web (m); at most flange_width.

    Returns
    -------
    SectionProperties
        Per-unit-load peak stresses, section frame.

    Raises
    ------
    ValueError
        For flanges or a web that do not fit.
    """
    h, b, tf, tw = height, flange_width, flange_thickness, web_thickness
    if not (0.0 < 2.0 * tf < h and 0.0 < tw <= b):
        raise ValueError("i_section: need 0 < 2 flange_thickness < height and 0 < web_thickness <= flange_width. "
                         f"Got flange_thickness {tf:g}, web_thickness {tw:g} instead")
    hw = h - 2.0 * tf
    area = 2.0 * b * tf + hw * tw
    i2 = (b * h**3 - (b - tw) * hw**3) / 12.0
    i3 = 2.0 * tf * b**3 / 12.0 + hw * tw**3 / 12.0
    torsion_constant = (2.0 * b * tf**3 + hw * tw**3) / 3.0
    q3 = b * tf * (h - tf) / 2.0 + tw * (hw / 2.0) ** 2 / 2.0
    q2 = 2.0 * tf * (b / 2.0) ** 2 / 2.0 + hw * (tw / 2.0) ** 2 / 2.0
    return bending_properties(area, i2, i3, b / 2.0, h / 2.0, max(tf, tw) / torsion_constant,
                    q2 / (i3 * 2.0 * tf), q3 / (i2 * tw))


#: The shape's section properties from its dimensions (m); ValueError for impossible ones.
properties = i_section
