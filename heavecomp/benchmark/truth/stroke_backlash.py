"""stroke_backlash (outside every name), as generated: the stroke transducer reads through a play
of width b (backlash)."""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw


def backlash(y, width):
    """``y`` read through a play of total width ``width`` (the reading moves only once the play is
    taken up), starting centred."""
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
    """The stroke transducer reads through a play of ``width`` [m]."""
    out = dict(cols)
    out["stroke"] = backlash(cols["stroke"], width)
    return out


def draw(rng, setting):
    """b 2-5 cm; its size is b, at most 0.3 m."""
    return Draw({"width": rng.uniform(0.02, 0.05)}, "width", 0.3)


LAW = TruthLaw("stroke_backlash", "sensors", draw, output=stroke_backlash, named=False)
