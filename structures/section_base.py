"""What every cross-section shape computes (:mod:`structures.section_shapes`): the section
properties a stress check needs, per unit load (SI, section frame: axis 1 along the beam, axes 2 and
3 in the section plane)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol


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
    torsion_constant: float | None = None   # Saint-Venant J (m^4), where the shape gives it (member stiffness)


class SectionShape(Protocol):
    """The interface of a cross-section shape: a module of :mod:`structures.section_shapes` (one file
    each) defines

    Attributes
    ----------
    NAME : str                  The ``kind`` a case's ``section`` table gives.
    DIMENSIONS : dict           Dimension name -> meaning (m), in the order :meth:`properties` takes
                                them; the case schema is built from it (every dimension > 0 and <= 20 m).
    """

    NAME: str
    DIMENSIONS: dict[str, str]

    def properties(self, **dimensions) -> SectionProperties:
        """The section's properties from its dimensions.

        Parameters
        ----------
        **dimensions : float
            Its :attr:`DIMENSIONS` (m).

        Returns
        -------
        SectionProperties

        Raises
        ------
        ValueError
            Impossible dimensions (a wall thicker than half the section).
        """


def bending_properties(area, i2, i3, c2, c3, torsion, shear2, shear3, round_=False,
                       torsion_constant=None) -> SectionProperties:
    """Section properties from the area (m^2), second moments I2, I3 (m^4), extreme-fibre distances
    c2, c3 (m), and the peak shear stresses per unit torque (1/m^3) and per unit shear force along
    axes 2 and 3 (1/m^2); ``round_``: bending peaks combine as a resultant.

    Parameters
    ----------
    area : float
        Cross-section area (m^2).
    i2, i3 : float
        Second moments of area about section axes 2 and 3 (m^4).
    c2, c3 : float
        Distance of the extreme fibre from the neutral axis along section axes 2 and 3 (m).
    torsion : float
        Peak shear stress per unit torque (Pa per N m = 1/m^3).
    shear2, shear3 : float
        Peak transverse shear stress per unit shear force along axes 2 and 3 (Pa per N = 1/m^2).
    round_ : bool
        True for a circular section: the bending peaks combine as a resultant.
    torsion_constant : float or None
        Saint-Venant torsion constant J (m^4), the twist stiffness GJ per unit length; None where the
        shape does not give it (a member's stiffness then cannot be derived from it).

    Returns
    -------
    SectionProperties
        Normal stress per unit moment is c3 / I2 about axis 2 and c2 / I3 about axis 3 (1/m^3).
    """
    return SectionProperties(area=area, second_moment_2=i2, second_moment_3=i3,
                             normal_per_axial=1.0 / area, normal_per_moment2=c3 / i2, normal_per_moment3=c2 / i3,
                             shear_per_torque=torsion, shear_per_force2=shear2, shear_per_force3=shear3,
                             round=round_, torsion_constant=torsion_constant)
