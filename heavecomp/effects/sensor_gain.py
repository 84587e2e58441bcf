"""``sensor_gain``: one measured channel reads a fixed factor off (measured-channel hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import ChannelEffect, FitSpec
from heavecomp.params.core import q


class SensorGain(ChannelEffect):
    """y_meas = g y for one channel (``channel``: wob, stroke, pressure or heave): a calibration
    error, a wrong unit factor, or a sign flip (g = -1, a load cell or a transducer wired the
    other way).  The parameter is ``factor`` (not ``gain``: its unit differs from dwell_stiction's
    ``gain``, and the report's units go by parameter name).  Acts on the recorded channel, outside the stepper; the diagnosis fits which channel.
    """

    name = "sensor_gain"
    fit = FitSpec(
        candidate=True,
        linear=True,
        # units of the equation-error coefficients (``features``)
        feature_units={"sensor_gain": "-"},
    )

    @dataclass(frozen=True)
    class Params:
        factor: float = q(1.0, "-", bounds=(-2.0, 2.0), symbol="g",
                        doc="factor the channel reads (1: right; -1: sign flipped)")

    @classmethod
    def features(cls, sig, shape=None):
        """``sensors`` residual of the channel ``y`` [its unit]: ``sensor_gain`` y (coefficient
        1 - 1/g): y_meas = g y, so y_meas - y = (1 - 1/g) y_meas."""
        if "y" not in sig:
            return None
        return {"sensor_gain": np.asarray(sig["y"], dtype=float)}

    @staticmethod
    def apply(t, tg, y, factor):
        """The recorded channel at times ``t`` from the true ``y`` on the grid ``tg``."""
        return factor * np.interp(t, tg, y)

    @classmethod
    def null(cls, plant):
        return {"factor": 1.0}


EFFECT = SensorGain
