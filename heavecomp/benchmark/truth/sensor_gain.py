"""sensor_gain, as generated: y_m = g LP(y), a channel's calibration factor g behind its own 5 Hz
first-order bandwidth; variant ``sign_flip``: a stroke transducer mounted the wrong way round
(g = -1).

The candidate (fitted, :mod:`heavecomp.effects`) is a pure factor.
"""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.benchmark.truth.filters import first_order_lag


def sensor_gain(t, cols, channel, gain, bandwidth=5.0):
    """y_m = g LP(y): the channel's calibration factor g behind its own first-order bandwidth [Hz].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    channel : str
        The misreading channel.
    gain : float [-]
        Calibration factor g (1: right; -1: sign flip).
    bandwidth : float [Hz]
        Bandwidth of the sensor's first-order lag.

    Returns
    -------
    dict
        ``cols`` with ``channel`` read as g LP(y) (a new dict).
    """
    out = dict(cols)
    out[channel] = gain * first_order_lag(t, cols[channel], 1.0 / (2 * np.pi * bandwidth))
    return out


def misread(t, cols, channel, gain_error, bandwidth):
    """``channel`` read with the factor 1 + ``gain_error`` [-] behind ``bandwidth`` [Hz].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    channel : str
        The misreading channel.
    gain_error : float [-]
        Relative error of the calibration factor (g = 1 + ``gain_error``).
    bandwidth : float [Hz]
        Bandwidth of the sensor's first-order lag.

    Returns
    -------
    dict
        ``cols`` with ``channel`` misread (a new dict).
    """
    return sensor_gain(t, cols, channel, 1.0 + gain_error, bandwidth)


def draw(rng, setting):
    """The variant's channel (default wob) off by +-5-12 %; its size is the gain error, at most 50 %.
    ``sign_flip``: the stroke read with g = -1 (no size knob).

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads ``variant`` (the channel, ``sign_flip``, or None for
        ``wob``).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    if setting.variant == "sign_flip":
        return Draw({"channel": "stroke", "gain_error": -2.0, "bandwidth": 5.0})
    ch = setting.variant or "wob"
    return Draw({"channel": ch, "gain_error": float(rng.choice([-1, 1]) * rng.uniform(0.05, 0.12)),
                 "bandwidth": 5.0}, "gain_error", 0.5)


LAW = TruthLaw("sensor_gain", "sensors", draw, output=misread, variants=("wob", "stroke", "pressure", "sign_flip"))
