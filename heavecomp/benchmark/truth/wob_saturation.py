"""wob_saturation (outside every name), as generated: the WOB load cell clips at W_max."""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw


def wob_saturation(t, cols, w_max):
    """The WOB load cell clips at ``w_max`` [N]."""
    out = dict(cols)
    out["wob"] = np.minimum(cols["wob"], w_max)
    return out


def draw(rng, setting):
    """W_max 0.6-1.2 standard deviations above the clean run's mean WOB; no size knob."""
    w = setting.base["wob"]
    return Draw({"w_max": float(np.mean(w) + rng.uniform(0.6, 1.2) * np.std(w))})


LAW = TruthLaw("wob_saturation", "sensors", draw, output=wob_saturation, named=False)
