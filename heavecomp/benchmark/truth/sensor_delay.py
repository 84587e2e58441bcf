"""sensor_delay, as generated: one channel read through a first-order sensor lag (causal IIR).

The candidate (fitted, :mod:`heavecomp.effects`) is a pure transport delay.
"""

from __future__ import annotations

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.benchmark.truth.filters import first_order_lag


def lagged(t, cols, channel, lag_time):
    """``channel`` read through a first-order lag of ``lag_time`` [s]."""
    out = dict(cols)
    out[channel] = first_order_lag(t, cols[channel], lag_time)
    return out


def draw(rng, setting):
    """One of wob, stroke, pressure lags by 0.3-1 s; its size is the lag, at most 2 s."""
    ch = ("wob", "stroke", "pressure")[int(rng.integers(3))]
    return Draw({"channel": ch, "lag_time": rng.uniform(0.3, 1.0)}, "lag_time", 2.0)


LAW = TruthLaw("sensor_delay", "sensors", draw, output=lagged)
