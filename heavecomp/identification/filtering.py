"""Signal conditioning for inverse-model identification.

The identification of Gautier's IDIM-LS method (used for the EMPS benchmark):
the position is low-passed with a zero-phase (forward-backward) Butterworth
filter and differentiated by central differences; then **both** sides of the
regression (the measured force and every regressor column) pass through the
same decimation low-pass ("parallel filtering"), so that any filtering of the
force is matched on the model side and the high-frequency part neither side
can explain is removed.
"""

from __future__ import annotations

import numpy as np

from heavecomp.errors import ParameterError
from heavecomp.signals import butterworth_zero_phase


def derivatives(q, fs: float, cutoff: float, order: int = 4):
    """Filtered position, velocity and acceleration by central differences.

    Parameters
    ----------
    q : array [m]
        Measured position sampled at ``fs``.
    fs : float [Hz]
        Sampling rate.
    cutoff : float [Hz]
        Cut-off of the zero-phase Butterworth low-pass on the position.
    order : int
        Butterworth order.

    Returns
    -------
    q_f, dq, ddq : ndarray
        [m], [m/s], [m/s^2] at the input rate.
    """
    q_f = butterworth_zero_phase(q, fs, cutoff, order)
    h = 1.0 / fs
    dq = np.gradient(q_f, h)
    ddq = np.gradient(dq, h)
    return q_f, dq, ddq


def parallel_decimate(x, factor: int) -> np.ndarray:
    """Decimation low-pass (Chebyshev I, order 8, cut-off 0.8 fs/(2 factor), zero phase)
    then keep every ``factor``-th sample, starting at sample 0.

    Applied column by column to the force and to every regressor.  ``factor`` = 1
    returns the input unchanged.

    Parameters
    ----------
    x : array
        Signal or regressor matrix (one column per regressor), decimated along axis 0.
    factor : int
        Decimation factor (>= 1).
    """
    import scipy.signal as ss

    factor = int(factor)
    if factor < 1:
        raise ParameterError(f"decimate must be a positive integer, got {factor}")
    x = np.asarray(x, dtype=float)
    if factor == 1:
        return x.copy()
    return ss.decimate(x, factor, ftype="iir", zero_phase=True, axis=0)
