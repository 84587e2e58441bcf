"""Signal laws shared by the truth laws that act on a logged channel."""

from __future__ import annotations

import numpy as np


def first_order_lag(t, y, tau):
    """Causal first-order lag of ``y`` sampled at ``t`` (uniform) [s], time constant ``tau`` [s],
    starting settled at ``y[0]``."""
    from scipy.signal import lfilter

    a = np.exp(-(t[1] - t[0]) / tau)
    return lfilter([1 - a], [1, -a], y - y[0]) + y[0]
