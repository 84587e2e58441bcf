"""sensor_delay, as generated: one channel read through a first-order sensor lag (causal IIR).

The candidate (fitted, :mod:`heavecomp.effects`) is a pure transport delay.
"""

from __future__ import annotations

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.benchmark.truth.filters import first_order_lag


def lagged(t, cols, channel, lag_time):
    """``channel`` read through a first-order lag of ``lag_time`` [s].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    channel : str
        The lagging channel (``wob``, ``stroke`` or ``pressure``).
    lag_time : float [s]
        Time constant of the sensor's first-order lag.

    Returns
    -------
    dict
        ``cols`` with ``channel`` lagged (a new dict).
    """
    out = dict(cols)
    out[channel] = first_order_lag(t, cols[channel], lag_time)
    return out


def draw(rng, setting):
    """One of wob, stroke, pressure lags by 0.3-1 s; its size is the lag, at most 2 s.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads none of it (the signature every draw shares).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    ch = ("wob", "stroke", "pressure")[int(rng.integers(3))]
    return Draw({"channel": ch, "lag_time": rng.uniform(0.3, 1.0)}, "lag_time", 2.0)


LAW = TruthLaw("sensor_delay", "sensors", draw, output=lagged)
