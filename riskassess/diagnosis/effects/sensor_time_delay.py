"""``sensor_time_delay``: every channel is time-tagged late by a constant delay.

.. math:: y_{measured}(t) = y(\\max(t - \\Delta, 0))

(before the delay has elapsed the sensor repeats the initial state).
"""
from __future__ import annotations

import numpy as np

from riskassess.diagnosis.effects.base import Effect, Parameter


def delayed_times(times, delay):
    """Times (s) at which the true state is read for samples tagged ``times`` (s).

    Parameters
    ----------
    times : (k,) float
        Sample time tags (s).
    delay : float
        Measurement delay (s), >= 0.

    Returns
    -------
    times : (k,) float
        max(times - delay, 0) (s).
    """
    return np.maximum(np.asarray(times, float) - delay, 0.0)


class SensorTimeDelay(Effect):
    id = "sensor_time_delay"
    title = "constant time delay of the measurements"
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")

    def parameter_specs(self, case, channels=None):
        """The delay (s), 0 to 5 s.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; not read.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        return [Parameter("delay", "s", "measurement delay", 0.2, 0.0, 5.0)]

    def sample_times(self, times, values):
        """The tags shifted back by the delay.

        Parameters
        ----------
        times : (k,) float
            Sample time tags (s).
        values : (1,) float
            [delay (s)].

        Returns
        -------
        times : (k,) float
            :func:`delayed_times` (s).
        """
        return delayed_times(times, values[0])


EFFECT = SensorTimeDelay()
