"""Beam cross-sections at weak locations: section properties and the stress each load causes.

Euler-Bernoulli beam theory, as in the seed paper (Cuadrat-Grzybowski & Gill 2024, Sec. 2.5).
Section frame: axis 1 along the beam (normal of the cut), axes 2 and 3 in the section plane.
``width`` is the extent along axis 2, ``height`` along axis 3. Loads are the internal
force ``(N, V2, V3)`` (N) and moment ``(T, M2, M3)`` (N m) in that frame.

Each section gives, per unit load, the largest stress that load component causes anywhere
in the section (Pa per N or per N m): ``normal_per_axial``, ``normal_per_moment2`` (bending
about axis 2, fibres at +-height/2), ``normal_per_moment3``, ``shear_per_torque`` and
``shear_per_force2/3`` (transverse shear at the neutral axis). Formulas: Roark's Formulas
for Stress and Strain (8th ed., Tables 9.1 and 10.1, thin-walled closed sections by Bredt,
open sections as sums of thin rectangles); each class states its own.

Combining them (:func:`section_stresses`) takes the peaks as coincident, which is exact for
the normal stress of rectangular and I sections (the corner fibre carries both bending
peaks) and conservative for the rest; the circular tube combines its bending moments as a
resultant, since its extreme fibre lies along the resultant moment.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SectionProperties:
    """Properties a stress check needs (SI)."""

    area: float                 # (m^2)
    second_moment_2: float      # I about axis 2 (m^4)
    second_moment_3: float      # I about axis 3 (m^4)
    normal_per_axial: float     # (1/m^2)
    normal_per_moment2: float   # (1/m^3)
    normal_per_moment3: float   # (1/m^3)
    shear_per_torque: float     # (1/m^3)
    shear_per_force2: float     # (1/m^2)
    shear_per_force3: float     # (1/m^2)
    round: bool = False         # bending peaks combine as a resultant (circular tube)


def _bending(area, i2, i3, c2, c3, torsion, shear2, shear3, round_=False) -> SectionProperties:
    return SectionProperties(area=area, second_moment_2=i2, second_moment_3=i3,
                             normal_per_axial=1.0 / area, normal_per_moment2=c3 / i2, normal_per_moment3=c2 / i3,
                             shear_per_torque=torsion, shear_per_force2=shear2, shear_per_force3=shear3,
                             round=round_)


def solid_rectangle(width: float, height: float) -> SectionProperties:
    """Solid b x h rectangle. Torsion: tau_max = T (3a + 1.8b) / (a^2 b^2) with a >= b
    (Roark Table 10.1 case 4, within 4 % of the exact series); transverse shear 1.5 V / A."""
    b, h = width, height
    a, c = max(b, h), min(b, h)
    area = b * h
    return _bending(area, b * h**3 / 12.0, h * b**3 / 12.0, b / 2.0, h / 2.0,
                    (3.0 * a + 1.8 * c) / (a**2 * c**2), 1.5 / area, 1.5 / area)


def hollow_rectangle(width: float, height: float, wall: float) -> SectionProperties:
    """Rectangular tube of uniform wall thickness: exact area and second moments (outer minus
    inner rectangle); torsion by Bredt, tau = T / (2 A_m t), A_m enclosed by the wall's
    midline; transverse shear V Q / (I 2t) at the neutral axis."""
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
    return _bending(area, i2, i3, b / 2.0, h / 2.0, 1.0 / (2.0 * enclosed * t),
                    q2 / (i3 * 2.0 * t), q3 / (i2 * 2.0 * t))


def thin_walled_box(width: float, height: float, flange_thickness: float, web_thickness: float) -> SectionProperties:
    """Thin-walled box: flanges (the walls along axis 2, thickness t_f) and webs (along
    axis 3, t_w), dimensions to the wall midlines, thin-wall approximations (Roark Table 10.1
    case 16 for torsion: tau = T / (2 A_m t) at the thinner wall)."""
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
    return _bending(area, i2, i3, b / 2.0 + tw / 2.0, h / 2.0 + tf / 2.0, 1.0 / (2.0 * enclosed * min(tf, tw)),
                    q2 / (i3 * 2.0 * tf), q3 / (i2 * 2.0 * tw))


def circular_tube(outer_diameter: float, wall: float) -> SectionProperties:
    """Circular tube (a solid shaft when wall = outer_diameter / 2): exact A, I and polar
    J = 2 I; torsion T r / J; transverse shear V Q / (I (D - d)) with Q = (D^3 - d^3) / 12,
    which gives 2 V / A for thin tubes and 4 V / (3 A) for solid shafts."""
    d_out, t = outer_diameter, wall
    if not 0.0 < t <= d_out / 2.0:
        raise ValueError(f"circular_tube: wall must be in (0, outer_diameter/2 = {d_out / 2:g} m]. Got {t:g} instead")
    d_in = d_out - 2.0 * t
    area = math.pi * (d_out**2 - d_in**2) / 4.0
    i = math.pi * (d_out**4 - d_in**4) / 64.0
    shear = ((d_out**3 - d_in**3) / 12.0) / (i * (d_out - d_in))
    return _bending(area, i, i, d_out / 2.0, d_out / 2.0, (d_out / 2.0) / (2.0 * i), shear, shear, round_=True)


def i_section(height: float, flange_width: float, flange_thickness: float, web_thickness: float) -> SectionProperties:
    """I-section, web along axis 3 (strong bending about axis 2). Exact A and I; torsion of
    an open section, tau = T t_max / J with J = sum b t^3 / 3; transverse shear along the
    web V Q / (I t_w) at the neutral axis, across the flanges V Q / (I 2 t_f)."""
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
    return _bending(area, i2, i3, b / 2.0, h / 2.0, max(tf, tw) / torsion_constant,
                    q2 / (i3 * 2.0 * tf), q3 / (i2 * tw))


SECTIONS = {
    "solid_rectangle": solid_rectangle,
    "hollow_rectangle": hollow_rectangle,
    "thin_walled_box": thin_walled_box,
    "circular_tube": circular_tube,
    "i_section": i_section,
}


def section_stresses(section: SectionProperties, force_section, moment_section) -> dict:
    """Peak stresses (Pa) over the section for internal loads given per sample, section frame.

    Parameters
    ----------
    force_section, moment_section : (k, 3) array
        Internal force (N, V2, V3) (N) and moment (T, M2, M3) (N m) per sample.

    Returns
    -------
    dict of (k,) arrays: ``axial``, ``bending`` (both axes), ``normal`` (axial + bending),
    ``torsion``, ``transverse_shear``, ``shear`` (torsion + transverse), ``von_mises``
    (from the peak normal and shear stresses, taken as coincident: conservative).
    """
    f = np.atleast_2d(np.asarray(force_section, float))
    m = np.atleast_2d(np.asarray(moment_section, float))
    s = section
    axial = np.abs(f[:, 0]) * s.normal_per_axial
    if s.round:
        bending = np.hypot(m[:, 1], m[:, 2]) * s.normal_per_moment2
        transverse = np.hypot(f[:, 1], f[:, 2]) * s.shear_per_force2
    else:
        bending = np.abs(m[:, 1]) * s.normal_per_moment2 + np.abs(m[:, 2]) * s.normal_per_moment3
        transverse = np.maximum(np.abs(f[:, 1]) * s.shear_per_force2, np.abs(f[:, 2]) * s.shear_per_force3)
    torsion = np.abs(m[:, 0]) * s.shear_per_torque
    normal = axial + bending
    shear = torsion + transverse
    return {"axial": axial, "bending": bending, "normal": normal, "torsion": torsion,
            "transverse_shear": transverse, "shear": shear, "von_mises": np.sqrt(normal**2 + 3.0 * shear**2)}
