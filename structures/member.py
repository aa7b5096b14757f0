"""The compliance of the structural member behind a clamped joint, as the joint's six springs.

A clamped appendage (a boom, a dish bracket) is a beam of length ``L`` between its root (the joint
point, on the parent) and the body it carries. The multi-body model keeps the bodies rigid, so the
beam's compliance is lumped into the joint at the root, one spring per joint axis (beam frame:
axis 1 along the member):

- axial (translation along 1): ``E A / L``, exact for an axial load;
- transverse (translation along 2, 3): ``kappa G A / L``, the beam's shear compliance (``kappa`` =
  :data:`SHEAR_COEFFICIENT`);
- torsion (rotation about 1): ``G J / L``, exact for a torque;
- bending (rotation about 2, 3): ``3 E I / L``, so that a transverse force at the member's end
  deflects it by ``F L^3 / (3 E I)``, the cantilever's static tip deflection (Euler-Bernoulli; with
  the shear term, Timoshenko's).

The joint's moment is then the member's root bending moment (equilibrium of the rigid child), and
the joint rings at the member's first modes instead of at a penalty frequency tuned to the step:
no numerical parameter is left in the joint (docs/structures.md, "Are the judged peaks converged?").
The lumped spring is exact for a tip force on a member whose mass is small beside what it carries
(a dish bracket); for a member that is itself the moving mass (a boom), a rigid rod on ``3 E I / L``
puts the first bending mode below the uniform cantilever's (Rayleigh: ``m / 3`` instead of
``0.236 m`` of the member's own mass at the tip), i.e. a slightly softer structure, stated with the
figure where it is used. A tip moment turns the lumped member 3x less than the beam (``M L / (3EI)``
against ``M L / (E I)``): stiffer, which passes impulses with a higher peak.
"""
from __future__ import annotations

import numpy as np

from structures.section_base import SectionProperties

#: Timoshenko shear coefficient of a thin-walled circular tube (0.5; Cowper's 2 (1 + nu) / (4 + 3 nu)
#: gives 0.53 at nu = 0.3, 0.9 for a solid shaft): the lowest, i.e. the softest shear, of a round
#: section. The shear compliance of a slender member is ~1 % of its bending compliance at its end.
SHEAR_COEFFICIENT = 0.5


def member_stiffness_beam_frame(section: SectionProperties, length: float, modulus: float,
                                shear_modulus: float) -> np.ndarray:
    """The six springs of a member of ``length`` lumped at its root, beam frame.

    Parameters
    ----------
    section : SectionProperties
        The member's cross-section (axis 1 along the member); needs ``torsion_constant``.
    length : float
        Member length from the joint to the body it carries (m), > 0.
    modulus, shear_modulus : float
        Young's and shear moduli E, G (Pa), > 0.

    Returns
    -------
    (6,) float
        [axial, transverse 2, transverse 3] (N/m), then [torsion about 1, bending about 2, bending
        about 3] (N m/rad), beam frame.

    Raises
    ------
    ValueError
        A section without a torsion constant, or a non-positive length or modulus.
    """
    if section.torsion_constant is None:
        raise ValueError("a member's stiffness needs the section's torsion constant; the section shape does not "
                         "give one (circular_tube does)")
    if not (length > 0 and modulus > 0 and shear_modulus > 0):
        raise ValueError(f"a member needs length, modulus and shear_modulus > 0; got {length}, {modulus}, "
                         f"{shear_modulus}")
    e, g, a = modulus, shear_modulus, section.area
    return np.array([e * a / length,
                     SHEAR_COEFFICIENT * g * a / length,
                     SHEAR_COEFFICIENT * g * a / length,
                     g * section.torsion_constant / length,
                     3.0 * e * section.second_moment_2 / length,
                     3.0 * e * section.second_moment_3 / length])


def member_stiffness_joint_frame(section: SectionProperties, length: float, modulus: float, shear_modulus: float,
                                 beam_axis_joint) -> np.ndarray:
    """:func:`member_stiffness_beam_frame` on the joint's axes: the member must run along one of them.

    The section's axes 2 and 3 follow the joint's remaining axes in cyclic order (h1 -> h2, h3; h2 ->
    h3, h1; h3 -> h1, h2); for a round section (``I2 = I3``) the order does not matter.

    Parameters
    ----------
    section : SectionProperties
        The member's cross-section.
    length : float
        Member length (m).
    modulus, shear_modulus : float
        E, G (Pa).
    beam_axis_joint : (3,) float
        The member's direction in the joint frame (h1, h2, h3 components, any length and sign).

    Returns
    -------
    (6,) float
        Springs on [x, y, z] (N/m) and [rot h1, rot h2, rot h3] (N m/rad), joint frame.

    Raises
    ------
    ValueError
        A member not along a joint axis (within 1e-6 rad), or a section the member cannot use.
    """
    axis = np.asarray(beam_axis_joint, float)
    axis = axis / np.linalg.norm(axis)
    along = int(np.argmax(np.abs(axis)))
    if 1.0 - abs(axis[along]) > 1e-6:
        raise ValueError(f"a member must run along one of its joint's axes h1, h2, h3 (the springs are diagonal in "
                         f"the joint frame); its direction in the joint frame is {np.round(axis, 6).tolist()}")
    if not section.round and along != 0:
        raise ValueError("a member of a non-round section must run along h1 (its section axes 2 and 3 are then "
                         "h2 and h3)")
    beam = member_stiffness_beam_frame(section, length, modulus, shear_modulus)
    order = [(along + k) % 3 for k in range(3)]         # joint axis of beam axes 1, 2, 3
    out = np.empty(6)
    out[order] = beam[:3]
    out[[3 + i for i in order]] = beam[3:]
    return out
