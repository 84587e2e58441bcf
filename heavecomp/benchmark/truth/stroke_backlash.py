"""stroke_backlash (outside every name), as generated: the stroke transducer reads through a play
of width b (backlash)."""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw


def backlash(y, width):
    """``y`` read through a play of total width ``width`` (the reading moves only once the play is
    taken up), starting centred.

    Parameters
    ----------
    y : numpy.ndarray
        The true signal [its unit].
    width : float
        Total width of the play [the unit of ``y``].

    Returns
    -------
    numpy.ndarray
        The reading through the play [the unit of ``y``].
    """
    out = np.empty_like(y)
    r = y[0]
    half = 0.5 * width
    for i, v in enumerate(y):
        if v > r + half:
            r = v - half
        elif v < r - half:
            r = v + half
        out[i] = r
    return out


def stroke_backlash(t, cols, width):
    """The stroke transducer reads through a play of ``width`` [m].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    width : float [m]
        Total width of the play.

    Returns
    -------
    dict
        ``cols`` with ``stroke`` read through the play (a new dict).
    """
    out = dict(cols)
    out["stroke"] = backlash(cols["stroke"], width)
    return out


def draw(rng, setting):
    """b 2-5 cm; its size is b, at most 0.3 m.

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
    return Draw({"width": rng.uniform(0.02, 0.05)}, "width", 0.3)


LAW = TruthLaw("stroke_backlash", "sensors", draw, output=stroke_backlash, named=False)
