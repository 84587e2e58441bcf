"""Signal laws shared by the truth laws that act on a logged channel."""

from __future__ import annotations

import numpy as np


def first_order_lag(t, y, tau):
    """Causal first-order lag of ``y`` sampled at ``t`` (uniform) [s], time constant ``tau`` [s],
    starting settled at ``y[0]``.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Uniform sample times.
    y : numpy.ndarray
        The signal [any unit].
    tau : float [s]
        Time constant.

    Returns
    -------
    numpy.ndarray
        The lagged signal [the unit of ``y``].
    """
    from scipy.signal import lfilter

    a = np.exp(-(t[1] - t[0]) / tau)
    return lfilter([1 - a], [1, -a], y - y[0]) + y[0]
