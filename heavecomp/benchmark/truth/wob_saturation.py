"""wob_saturation (outside every name), as generated: the WOB load cell clips at W_max."""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw


def wob_saturation(t, cols, w_max):
    """The WOB load cell clips at ``w_max`` [N].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    w_max : float [N]
        The load cell's largest reading.

    Returns
    -------
    dict
        ``cols`` with ``wob`` clipped at ``w_max`` (a new dict).
    """
    out = dict(cols)
    out["wob"] = np.minimum(cols["wob"], w_max)
    return out


def draw(rng, setting):
    """W_max 0.6-1.2 standard deviations above the clean run's mean WOB; no size knob.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads the clean run's WOB ``base['wob']`` [N] (the clip sits above
        its mean).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    w = setting.base["wob"]
    return Draw({"w_max": float(np.mean(w) + rng.uniform(0.6, 1.2) * np.std(w))})


LAW = TruthLaw("wob_saturation", "sensors", draw, output=wob_saturation, named=False)
