"""``sensor_delay``: one measured channel lags the others (measured-channel hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class SensorDelay(Effect):
    """y_meas(t) = y(t - t_d) for one channel (the diagnosis fits which one: wob, stroke or
    pressure).  Acts on the recorded channel, outside the stepper."""

    name = "sensor_delay"
    candidate = True
    hook = "channel"
    kind = "output"

    @dataclass(frozen=True)
    class Params:
        delay: float = q(0.2, "s", bounds=(0.0, 3.0), symbol="t_d", doc="transport delay of the lagging channel")

    @staticmethod
    def apply(t, tg, y, delay):
        """The delayed channel at times ``t`` from the model's ``y`` on the grid ``tg`` (linear interpolation)."""
        return np.interp(t - delay, tg, y)


EFFECT = SensorDelay
