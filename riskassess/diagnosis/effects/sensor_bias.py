"""``sensor_bias``: constant offsets on the measured rates, hinge angle and positions.

.. math:: y_{measured} = y + b_y

One bias per measured channel among omega_x..z, hinge_angle, hinge_rate, rel_x..z and
tether_tension (an attitude quaternion has no additive bias).
"""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.channels import OMEGA, REL, UNITS

#: Channels that may carry a bias, with a typical bias size (their units): a MEMS gyro's
#: 1e-3 rad/s, an encoder's 0.01 rad, a relative-navigation 0.05 m, a load cell's 1 N.
BIASED = {**{c: 1e-3 for c in OMEGA}, "hinge_angle": 0.01, "hinge_rate": 1e-3, **{c: 0.05 for c in REL},
          "tether_tension": 1.0}


class SensorBias(Effect):
    id = "sensor_bias"
    title = "constant sensor biases"
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    channels = tuple(BIASED)
    #: the parameter set follows the measured channels; a case may give any subset
    partial_parameters = True
    #: the measured channels are linear in the biases (the fit reuses their Jacobian columns)
    linear = True

    def parameter_specs(self, case, channels=None):
        """One bias ``bias_<channel>`` per measured channel that may carry one, in that channel's unit.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; hinge channels only for a hinged appendage, tension only for towing.
        channels : sequence of str, optional
            Measured channel names; None: every channel of ``BIASED``.
        """
        present = [c for c in BIASED if channels is None or c in channels]
        if case.kind != "hinged_appendage":
            present = [c for c in present if not c.startswith("hinge")]
        return [Parameter(f"bias_{c}", UNITS[c], f"bias of {c}", BIASED[c], -1000 * BIASED[c], 1000 * BIASED[c])
                for c in present if c != "tether_tension" or case.kind == "towing"]

    def starts(self, specs):
        """One start: no bias.

        Parameters
        ----------
        specs : list of Parameter
            The biases.

        Returns
        -------
        starts : list of (m,) float
            Zeros (channel units).
        """
        return [np.zeros(len(specs))]

    def measure(self, outputs, values, names):
        """Each channel plus its bias.

        Parameters
        ----------
        outputs : dict of str to (k,) float
            Simulated channels (units of :mod:`riskassess.diagnosis.plants.channels`).
        values : (m,) float
            The biases (channel units: rad/s, rad, m, N).
        names : sequence of str, length m
            ``bias_<channel>``: which channel each bias is added to.

        Returns
        -------
        outputs : dict of str to (k,) float
            A copy with the biases added.
        """
        out = dict(outputs)
        for name, value in zip(names, values):
            channel = name.removeprefix("bias_")
            if channel in out:
                out[channel] = out[channel] + value
        return out


EFFECT = SensorBias()
