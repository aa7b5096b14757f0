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
from riskassess.diagnosis.channels import REL
from riskassess.diagnosis.plant import is_towing as plant_is_towing
from riskassess.diagnosis.scenario import plant_of


class ComOffset(Effect):
    id = "com_offset"
    title = "main body centre of mass offset from its case value"
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    channels = REL + ("omega_x", "omega_y", "omega_z", "q_w", "hinge_angle", "hinge_rate")

    def not_applicable(self, case, channels):
        if case.kind == "tumbling_rigid" and not set(REL) & set(channels):
            return "a rigid body's CoM is seen only in its position: needs rel_x..z"
        return super().not_applicable(case, channels)

    def parameter_specs(self, case, channels=None):
        plant = plant_of(case)
        size = float(np.sqrt(np.trace(plant.inertia_main) / plant.mass_main))   # radius of gyration (m)
        return [Parameter(f"offset_{a}", "m", f"CoM offset along target {a}", 0.1 * size, -size, size) for a in "xyz"]

    def starts(self, specs):
        return [np.zeros(3)]

    def modify_plant(self, plant, values):
        shift = np.asarray(values, float)
        if plant_is_towing(plant):   # the sub-tether attachments are given from the case's CoM
            return plant.replace(com_offset=plant.com_offset + shift)
        return plant.replace(origin_main=plant.origin_main - shift, hinge_main=plant.hinge_main - shift)


EFFECT = ComOffset()
