"""What every cross-section shape computes (:mod:`structures.section_shapes`): the section
properties a stress check needs, per unit load (SI, section frame: axis 1 along the beam, axes 2 and
3 in the section plane)."""
from __future__ import annotations

from dataclasses import dataclass


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


def bending_properties(area, i2, i3, c2, c3, torsion, shear2, shear3, round_=False) -> SectionProperties:
    """Section properties from the area (m^2), second moments I2, I3 (m^4), extreme-fibre distances
    c2, c3 (m), and the peak shear stresses per unit torque (1/m^3) and per unit shear force along
    axes 2 and 3 (1/m^2); ``round_``: bending peaks combine as a resultant."""
    return SectionProperties(area=area, second_moment_2=i2, second_moment_3=i3,
                             normal_per_axial=1.0 / area, normal_per_moment2=c3 / i2, normal_per_moment3=c2 / i3,
                             shear_per_torque=torsion, shear_per_force2=shear2, shear_per_force3=shear3,
                             round=round_)
