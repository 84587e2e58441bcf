"""``sensor_delay``: one measured channel lags the others (measured-channel hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import ChannelEffect, FitSpec
from heavecomp.params.core import q


class SensorDelay(ChannelEffect):
    """y_meas(t) = y(t - t_d) for one channel (the diagnosis fits which one: wob, stroke or
    pressure).  Acts on the recorded channel, outside the stepper."""

    name = "sensor_delay"
    fit = FitSpec(
        candidate=True,
        # units of the equation-error coefficients (``features``)
        feature_units={"sensor_delay": "-"},
        # delays t_d [s] searched by the equation-error fit
        feature_grid=(0.05, 0.1, 0.2, 0.5, 1.0, 2.0),
    )

    @dataclass(frozen=True)
    class Params:
        delay: float = q(0.2, "s", bounds=(0.0, 3.0), symbol="t_d", doc="transport delay of the lagging channel")

    @classmethod
    def features(cls, sig, shape=None):
        """``sensors`` residual of the channel ``y`` (measured minus what the other channels say it
        should read) [its unit]: ``sensor_delay`` y(t) - y(t + t_d) (coefficient 1 when the channel
        lags by t_d = ``shape``): y_meas(t) = y(t - t_d), so the residual is y_meas(t) - y_meas(t + t_d)."""
        if not all(k in sig for k in ("t", "y")):
            return None
        t, y = np.asarray(sig["t"], dtype=float), np.asarray(sig["y"], dtype=float)
        d = cls.Params().delay if shape is None else float(shape)
        return {"sensor_delay": y - cls.apply(t, t, y, -d)}

    @staticmethod
    def apply(t, tg, y, delay):
        """The delayed channel at times ``t`` from the model's ``y`` on the grid ``tg`` (linear interpolation)."""
        return np.interp(t - delay, tg, y)

    @classmethod
    def null(cls, plant):
        return {"delay": 0.0}


EFFECT = SensorDelay
