"""``com_offset``: the main body's centre of mass is not where the case puts it.

The true CoM is the case's plus an offset (target frame); the inertia about the CoM is kept.
The tracked point (target-frame origin, channels rel_x..z) then circles the CoM at the
tumble rate, and with an appendage the hinge's lever arm about the main CoM changes, which
changes the coupled motion of body and appendage. Towing: the debris' CoM moves against the
sub-tether attachments (given from the case's CoM), which changes the tethers' lever arms.
"""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.channels import REL
from riskassess.diagnosis.plants.plant import is_towing as plant_is_towing
from riskassess.diagnosis.plants.scenario import plant_of


class ComOffset(Effect):
    id = "com_offset"
    title = "main body centre of mass offset from its case value"
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    channels = REL + ("omega_x", "omega_y", "omega_z", "q_w", "hinge_angle", "hinge_rate")

    def not_applicable(self, case, channels):
        """A rigid body's CoM offset is seen only in rel_x..z; otherwise as the base class.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case.
        channels : sequence of str
            Measured channel names.
        """
        if case.kind == "tumbling_rigid" and not set(REL) & set(channels):
            return "a rigid body's CoM is seen only in its position: needs rel_x..z"
        return super().not_applicable(case, channels)

    def parameter_specs(self, case, channels=None):
        """Offsets along the target (debris) frame's x, y, z (m), bounded by the main body's radius of gyration.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; its main body's mass (kg) and inertia (kg m^2) size the bounds.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        plant = plant_of(case)
        size = float(np.sqrt(np.trace(plant.inertia_main) / plant.mass_main))   # radius of gyration (m)
        return [Parameter(f"offset_{a}", "m", f"CoM offset along target {a}", 0.1 * size, -size, size) for a in "xyz"]

    def starts(self, specs):
        """One start: no offset.

        Parameters
        ----------
        specs : list of Parameter
            The three offsets (m).

        Returns
        -------
        starts : list of (m,) float
            [(0, 0, 0)] (m).
        """
        return [np.zeros(3)]

    def modify_plant(self, plant, values):
        """The plant with its main-body CoM moved by the offset (inertia about the CoM kept).

        Parameters
        ----------
        plant : Plant or TowingPlant
            Nominal plant; towing: the debris CoM moves against the sub-tether attachments.
        values : (m,) float
            (offset_x, offset_y, offset_z): true CoM minus the case's CoM (m), B (towing: D, the debris frame).

        Returns
        -------
        plant : Plant or TowingPlant
            ``origin_main`` and ``hinge_main`` less the offset (B), or ``com_offset`` plus it (D).
        """
        shift = np.asarray(values, float)
        if plant_is_towing(plant):   # the sub-tether attachments are given from the case's CoM
            return plant.replace(com_offset=plant.com_offset + shift)
        return plant.replace(origin_main=plant.origin_main - shift, hinge_main=plant.hinge_main - shift)


EFFECT = ComOffset()
