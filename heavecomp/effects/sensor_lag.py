"""``sensor_lag``: a channel read through a sensor with its own dynamics (a factor, a first-order lag, a delay).

A sensor has a bandwidth: a transducer, its amplifier or the logger's filter reads the channel through a
low-pass.  ``sensor_gain`` (a factor) and ``sensor_delay`` (a pure delay) are memoryless or pure shifts; a
first-order lag both attenuates and shifts the phase, by different amounts at different frequencies, so in
a mixed sea neither of them reads it right.  This effect is the generic linear reading of one channel:

    tau dy_l/dt = y - y_l,   y_meas(t) = g y_l(t - t_d)

with ``factor`` g [-], ``time_constant`` tau [s] (0: no lag) and ``delay`` t_d [s] (negative: the log's time
stamps come late; the calibration fits it down to minus one log sample, where a continuous lag and a logger's
discrete filter of the same tau differ by half a sample).  It is a calibration
of a reading, kept apart from the plant (like ``sensor_gain``); it is not a diagnosis candidate and not in
the registry's library composition: the calibrated model writes it
(:func:`heavecomp.diagnosis.calibrate.reading_dynamics`) when a reading verdict's channel is read better
with its dynamics.

Where it acts.  The factor and the delay are undone on the log (:meth:`SensorLag.undo_reading`: exactly, as
``sensor_gain`` and ``sensor_delay`` are); the lag is **not**: inverting it is a differentiator that
amplifies the log's noise.  It is read on the model side instead: every replay of the diagnosis reads its
prediction of the channel through the lag (:meth:`SensorLag.lag`, ``model_side``), so the corrected log and
the lagged prediction are compared.  ``measure`` is the whole reading (simulating what the rig records).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import ChannelEffect
from heavecomp.errors import ParameterError
from heavecomp.params.core import q


def first_order_lag(tg, y, time_constant):
    """The first-order lag ``tau dy_l/dt = y - y_l`` of ``y`` on the grid ``tg``, started at rest
    (``y_l(tg[0]) = y[0]``), exact for ``y`` linear between its samples (first-order hold: no half-step
    delay of its own, so a coarse log's grid reads it as a fine one does).

    Parameters
    ----------
    tg : numpy.ndarray [s]
        Increasing times of the samples.
    y : numpy.ndarray [unit of the channel]
        The input series.
    time_constant : float [s]
        The lag's time constant tau (0: the input itself).
    """
    y = np.asarray(y, dtype=float)
    if time_constant <= 0.0 or y.size < 2:
        return y.copy()
    r = np.diff(np.asarray(tg, dtype=float)) / time_constant
    e = np.exp(-r)
    b0 = 1.0 - (-np.expm1(-r)) / r  # y1 = e y0 + b0 x1 + b1 x0, b0 + b1 = 1 - e
    b1 = (1.0 - e) - b0
    if np.ptp(r) <= 1e-9 * r[0] and np.all(np.isfinite(y)):  # a uniform grid: the same recursion as a filter
        from scipy.signal import lfilter

        return lfilter([b0[0], b1[0]], [1.0, -e[0]], y, zi=[(1.0 - b0[0]) * y[0]])[0]
    out = np.empty_like(y)
    acc = float(y[0])
    out[0] = acc
    for i in range(1, y.size):  # the recursion on a non-uniform grid: O(n)
        acc = e[i - 1] * acc + b0[i - 1] * y[i] + b1[i - 1] * y[i - 1]
        out[i] = acc
    return out


class SensorLag(ChannelEffect):
    """y_meas(t) = g y_l(t - t_d), tau dy_l/dt = y - y_l, for one channel (module docstring)."""

    name = "sensor_lag"
    #: the lag is read on the model side (the replay's prediction read through it), never undone on a log
    model_side = True
    #: a file may leave the delay out (0)
    optional = ("delay",)
    #: the controllers' finite-state model reads the factor (the static map) and leaves these out
    dynamic_params = ("time_constant", "delay")

    @dataclass(frozen=True)
    class Params:
        factor: float = q(1.0, "-", bounds=(-2.0, 2.0), symbol="g", doc="factor the channel reads (-1: sign flipped)")
        time_constant: float = q(0.0, "s", bounds=(0.0, 10.0), symbol="tau",
                                 doc="time constant of the sensor's first-order lag (0: none)")
        delay: float = q(0.0, "s", bounds=(-1.0, 3.0), symbol="t_d",
                         doc="transport delay after the lag (negative, by up to a log sample: the log's time "
                             "stamps come late, e.g. a sample-and-hold stamped at the end of its interval)")

    def __init__(self, channel: str = "wob", **values):
        """A lagged reading of ``channel`` (``wob``, ``stroke`` or ``pressure``).

        Parameters
        ----------
        channel : str
            The channel read through the sensor; ``heave`` (the model's input) is refused.
        **values : float
            ``factor`` [-], ``time_constant`` [s], ``delay`` [s].
        """
        if channel == "heave":  # the heave is the replay's input: no prediction of it to read through a lag
            raise ParameterError("effect sensor_lag: channel 'heave' is the model's input, which has no prediction "
                                 "to read through a lag; channels: wob, stroke, pressure")
        super().__init__(channel=channel, **values)

    @classmethod
    def null(cls, plant):
        return {"factor": 1.0, "time_constant": 0.0, "delay": 0.0}

    def lag(self, t, tg, y):
        """The model-side part: the channel ``y`` on the grid ``tg`` through the lag, at times ``t``.

        Parameters
        ----------
        t : numpy.ndarray [s]
            Times of the output.
        tg : numpy.ndarray [s]
            The grid of ``y``.
        y : numpy.ndarray [unit of the channel]
            The true channel (the model's prediction).
        """
        tg = np.asarray(tg, dtype=float)
        return np.interp(np.asarray(t, dtype=float), tg, first_order_lag(tg, y, float(self.values["time_constant"])))

    def read_back(self, t, y_lagged):
        """The recorded channel from the lagged one at times ``t``: ``g y_l(t - t_d)`` (the log-side part,
        :meth:`undo_reading`'s inverse).

        Parameters
        ----------
        t : numpy.ndarray [s]
            Times of ``y_lagged``.
        y_lagged : numpy.ndarray [unit of the channel]
            The channel through the lag (:meth:`lag`).
        """
        t = np.asarray(t, dtype=float)
        return float(self.values["factor"]) * np.interp(t - float(self.values["delay"]), t, y_lagged)

    def undo_reading(self, t, y, cols=None):
        """The log-side correction: the lagged channel ``y_l(t) = y_meas(t + t_d) / g`` from the reading
        ``y`` (its last t_d seconds unknown: NaN); the lag is read on the model side.

        Parameters
        ----------
        t : numpy.ndarray [s]
            Times of the reading.
        y : numpy.ndarray [unit of the channel]
            The reading.
        cols : dict, optional
            The log's channels (unused).
        """
        g = float(self.values["factor"])
        if abs(g) < 1e-12:
            raise ParameterError(f"effect {self.name} on {self.channel}: a reading factor of 0 cannot be undone")
        t = np.asarray(t, dtype=float)
        return np.interp(t + float(self.values["delay"]), t, np.asarray(y, dtype=float), right=np.nan) / g

    def measure(self, t, tg, y, motion=None):
        """The recorded channel at times ``t`` from the true ``y`` on the grid ``tg``: lag, delay, factor."""
        t = np.asarray(t, dtype=float)
        tg = np.asarray(tg, dtype=float)
        yl = first_order_lag(tg, y, float(self.values["time_constant"]))
        return float(self.values["factor"]) * np.interp(t - float(self.values["delay"]), tg, yl)


EFFECT = SensorLag
