"""``sensor_offset``: one measured channel reads a constant plus slowly drifting offset (measured-channel hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import ChannelEffect, FitSpec
from heavecomp.params.core import q


class SensorOffset(ChannelEffect):
    """y_meas(t) = y(t) + o + r t for one channel (``channel``: wob, stroke, pressure or heave;
    ``t`` from the start of the log): an absolute instead of a gauge pressure (o = p_atm), a WOB
    zero that drifts with temperature, a stroke sensor zeroed elsewhere.  Acts on the recorded
    channel, outside the stepper.  The offset is in the channel's SI unit (N, m, Pa, m).
    """

    name = "sensor_offset"
    fit = FitSpec(
        candidate=True,
        linear=True,
        # fitted only when it pays (the diagnosis then counts it in the parsimony penalty): most offsets
        # are constant (absolute vs gauge pressure, a zero set elsewhere)
        optional=("drift",),
        # units of the equation-error coefficients (``features``)
        feature_units={"offset": "unit of the channel", "drift": "unit of the channel/s"},
    )

    @dataclass(frozen=True)
    class Params:
        offset: float = q(0.0, "unit of the channel (N, m or Pa)", bounds=(-1e7, 1e7), symbol="o",
                          doc="constant offset of the reading at t = 0")
        drift: float = q(0.0, "unit of the channel per s", bounds=(-1e4, 1e4), symbol="r",
                         doc="rate at which the offset drifts")

    @classmethod
    def features(cls, sig, shape=None):
        """``sensors`` residual of the channel ``y`` [its unit]: ``offset`` 1 (coefficient o) and
        ``drift`` t [s] (coefficient r [unit/s]), the effect's own reading of a zero channel."""
        if not all(k in sig for k in ("t", "y")):
            return None
        t = np.asarray(sig["t"], dtype=float)
        zero = np.zeros(t.size)
        return {"offset": cls.apply(t, t, zero, 1.0, 0.0), "drift": cls.apply(t, t, zero, 0.0, 1.0)}

    @staticmethod
    def apply(t, tg, y, offset, drift):
        """The recorded channel at times ``t`` [s] from the true ``y`` on the grid ``tg``."""
        return np.interp(t, tg, y) + offset + drift * t

    @classmethod
    def null(cls, plant):
        return {"offset": 0.0, "drift": 0.0}


EFFECT = SensorOffset
