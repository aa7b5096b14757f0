"""``sensor_time_delay``: every channel is time-tagged late by a constant delay.

.. math:: y_{measured}(t) = y(\\max(t - \\Delta, 0))

(before the delay has elapsed the sensor repeats the initial state).
"""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.effects.base import Effect, Parameter


def delayed_times(times, delay):
    """Times (s) at which the true state is read for samples tagged ``times`` (s)."""
    return np.maximum(np.asarray(times, float) - delay, 0.0)


class SensorTimeDelay(Effect):
    id = "sensor_time_delay"
    title = "constant time delay of the measurements"
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")

    def parameter_specs(self, case, channels=None):
        return [Parameter("delay", "s", "measurement delay", 0.2, 0.0, 5.0)]

    def sample_times(self, times, values):
        return delayed_times(times, values[0])


EFFECT = SensorTimeDelay()
