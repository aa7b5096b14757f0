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


import numpy as np

from structures.section_base import SectionProperties


def section_stresses(section: SectionProperties, force_section, moment_section) -> dict:
    """Peak stresses (Pa) over the section for internal loads given per sample, section frame.

    Parameters
    ----------
    section : SectionProperties
        Per-unit-load peak stresses of the cross-section (:mod:`structures.section_shapes`).
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
