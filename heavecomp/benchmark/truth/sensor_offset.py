"""sensor_offset, as generated: y_m = y + b, constant (an absolute pressure sensor logged as gauge,
variant ``absolute_pressure``; a stroke zero, variant ``stroke``) or a warm-up zero drift
b (1 - exp(-t/T_b)) of the WOB (default)."""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw


def sensor_offset(t, cols, channel, offset, drift_time=0.0):
    """y_m = y + b (constant, drift_time = 0) or y + b (1 - exp(-t/T_b)) (warm-up zero drift).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    channel : str
        The offset channel.
    offset : float [SI]
        Offset b in the channel's unit ([Pa], [m] or [N]).
    drift_time : float [s]
        Warm-up time constant T_b; 0 or less: a constant offset.

    Returns
    -------
    dict
        ``cols`` with ``channel`` offset (a new dict).
    """
    out = dict(cols)
    shape = 1.0 if drift_time <= 0 else 1.0 - np.exp(-(t - t[0]) / drift_time)
    out[channel] = cols[channel] + offset * shape
    return out


def draw(rng, setting):
    """``absolute_pressure``: + 99-103 kPa (no size knob); ``stroke``: +-2-5 cm, at most 0.5 m;
    else a WOB drift of +-2-6 kN over T_b 60-300 s, at most 40 kN.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads ``variant`` (``absolute_pressure``, ``stroke``, else a WOB
        drift).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    if setting.variant == "absolute_pressure":  # an absolute sensor logged as gauge: + local air pressure
        return Draw({"channel": "pressure", "offset": rng.uniform(99e3, 103e3), "drift_time": 0.0})
    if setting.variant == "stroke":
        return Draw({"channel": "stroke", "offset": float(rng.choice([-1, 1]) * rng.uniform(0.02, 0.05)),
                     "drift_time": 0.0}, "offset", 0.5)
    return Draw({"channel": "wob", "offset": float(rng.choice([-1, 1]) * rng.uniform(2e3, 6e3)),
                 "drift_time": rng.uniform(60.0, 300.0)}, "offset", 40e3)


LAW = TruthLaw("sensor_offset", "sensors", draw, output=sensor_offset,
               variants=("wob_drift", "stroke", "absolute_pressure"))
