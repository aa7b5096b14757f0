"""``thrust_misalignment``: the tug's thrust is tilted from its nominal axis, so it pushes sideways
and turns the tug about its CoM.

.. math::
    \\mathbf F = F\\,\\mathbf R_y(\\beta)\\mathbf R_x(\\alpha)\\,\\hat{\\mathbf e},\\qquad
    \\boldsymbol\\tau = \\mathbf r_n \\times \\mathbf F

(tug body frame; e the nominal thrust direction, r_n the nozzle position from the tug's CoM).
Applies to the towing scenario (``multibody/towing.py``), not yet available to this stage.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from diagnosis.dynamics import axis_rotation, cross
from diagnosis.effects.base import Effect, Parameter


@njit(cache=True)
def misaligned_thrust(thrust, direction_body, nozzle_body, tilt_x, tilt_y):
    """Thrust force (N) and torque about the CoM (N m), tug body frame, for tilts (rad) about x and y."""
    tilt = axis_rotation(np.array([0.0, 1.0, 0.0]), tilt_y) @ axis_rotation(np.array([1.0, 0.0, 0.0]), tilt_x)
    force = thrust * (tilt @ direction_body)
    return force, cross(nozzle_body, force)


class ThrustMisalignment(Effect):
    id = "thrust_misalignment"
    title = "tilted tug thrust (side force and torque)"
    scenarios = ("towing",)
    channels = ("tether_tension", "rel_x", "rel_y", "rel_z", "omega_x", "omega_y", "omega_z")

    def parameter_specs(self, case, channels=None):
        return [Parameter("tilt_x", "rad", "thrust tilt about the tug's x axis", 0.01, -0.3, 0.3),
                Parameter("tilt_y", "rad", "thrust tilt about the tug's y axis", 0.01, -0.3, 0.3)]


EFFECT = ThrustMisalignment()
