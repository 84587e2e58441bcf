"""Corrupted logs for the validation's category "no confident verdict on corrupted data" and the fuzz run.

Pure functions on a run's arrays: each takes the time ``t`` [s] and the columns (contract names, SI)
and returns new arrays with one corruption a rig log meets, plus a description.  Nothing here reads or
writes files or knows the diagnosis; :func:`corrupt` draws one class's size from ``rng``.

Classes (issue 21; :mod:`heavecomp.diagnosis.quality` answers each):

==============  ===========================================================  =========================
class           what the logger did                                          an honest answer
==============  ===========================================================  =========================
``frozen``      a channel holds its last value from some time on (a stuck    refused (> 20 % frozen)
                sensor or logger)                                            or warned, confidence low
``spike``       one sample of a channel is a wild value (1e9 N, a bit flip)  warned, confidence low
``time_scale``  the time column at the wrong scale (x0.5, x2)                warned, confidence low
``clock_skew``  one channel's clock offset by seconds                        warned, confidence low
``torn``        the last row cut mid-number (a file copied while written)   the row dropped and named
``non_finite``  a cell reads inf (``1e400``)                                 refused naming the column
``setpoint``    the WOB in another unit than declared (kN as tonnes: x9.81)  refused or warned
``magnitude``   a channel impossible for the rig (stroke in cm as m,         refused naming the column
                pressure below vacuum)
==============  ===========================================================  =========================

``expect`` in each description says which answer counts: ``"refuse"`` (exit 2 naming ``column``),
``"low"`` (a verdict with confidence ``low`` and a warning naming ``column``), ``"refuse_or_low"``,
``"dropped"`` (a warning naming the last row; the verdict is the clean run's).
"""

from __future__ import annotations

import math

import numpy as np

CLASSES = ("frozen", "spike", "time_scale", "clock_skew", "torn", "non_finite", "setpoint", "magnitude")
OUTPUTS = ("stroke", "pressure", "wob")


def _copy(cols):
    return {k: np.array(v, dtype=float, copy=True) for k, v in cols.items()}


def frozen(t, cols, channel, start):
    """``channel`` holds its value at ``start`` [s] to the end of the run.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    start : float [s]
        Time from the run's first sample at which the channel freezes.
    """
    out = _copy(cols)
    i = int(np.searchsorted(t, t[0] + start))
    out[channel][i:] = out[channel][i]
    frac = 1.0 - i / t.size
    return np.array(t, dtype=float), out, {"class": "frozen", "column": channel, "start_s": float(start),
                                           "fraction": frac, "expect": "refuse" if channel == "heave" or frac > 0.2
                                           else "refuse_or_low"}


def spike(t, cols, channel, index, value):
    """Sample ``index`` of ``channel`` replaced by ``value``.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    index : int
        Row of the replaced sample.
    value : float [unit of the column, SI]
        The wild value written there.
    """
    out = _copy(cols)
    out[channel][index] = value
    return np.array(t, dtype=float), out, {"class": "spike", "column": channel, "row": int(index), "value": float(value),
                                           "expect": "refuse_or_low"}


def time_scale(t, cols, factor):
    """The time column multiplied by ``factor`` (every sample kept).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    factor : float [-]
        Scale of the elapsed time (0.5 halves it, 2 doubles it).
    """
    t = np.asarray(t, dtype=float)
    return t[0] + (t - t[0]) * factor, _copy(cols), {"class": "time_scale", "column": "t", "factor": float(factor),
                                                     "expect": "refuse_or_low"}


def clock_skew(t, cols, channel, lag):
    """``channel`` read ``lag`` [s] late (its clock behind: y(t) is the value at t - lag); the ends where one
    side has no data are cut.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    lag : float [s]
        How late the channel is read; negative reads it early.
    """
    t = np.asarray(t, dtype=float)
    out = _copy(cols)
    shifted = np.interp(t - lag, t, out[channel])
    keep = (t - lag >= t[0]) & (t - lag <= t[-1])
    out[channel] = shifted
    return t[keep], {k: v[keep] for k, v in out.items()}, {"class": "clock_skew", "column": channel, "lag_s": float(lag),
                                                         "expect": "refuse_or_low"}


def torn_cell(value, keep):
    """The text of ``value`` cut after ``keep`` characters (as a file cut mid-write): a number again.

    Parameters
    ----------
    value : float [any]
        The intact number.
    keep : int
        Characters of its ``repr`` kept (at least one, never the whole text).
    """
    s = repr(float(value))
    cut = s[:max(1, min(keep, len(s) - 1))].rstrip(".eE+-")
    return float(cut) if cut not in ("", "-") else 0.0


def torn(t, cols, channel, keep):
    """The last value of ``channel`` cut to its first ``keep`` characters (the last row torn).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    keep : int
        Characters kept of the last value's text (:func:`torn_cell`).
    """
    out = _copy(cols)
    was = float(out[channel][-1])
    out[channel][-1] = torn_cell(was, keep)
    harmless = abs(out[channel][-1] - was) <= 1e-3 * max(abs(was), 1e-12)
    return np.array(t, dtype=float), out, {"class": "torn", "column": channel, "row": int(t.size - 1),
                                           "was": was, "now": float(out[channel][-1]),
                                           "expect": "clean" if harmless else "dropped"}


def non_finite(t, cols, channel, index, value=math.inf):
    """Sample ``index`` of ``channel`` non-finite (``1e400`` reads as inf).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    index : int
        Row of the replaced sample.
    value : float
        The non-finite value written there (default ``inf``).
    """
    out = _copy(cols)
    out[channel][index] = value
    return np.array(t, dtype=float), out, {"class": "non_finite", "column": channel, "row": int(index),
                                           "expect": "refuse"}


def scaled(t, cols, channel, factor, cls="setpoint"):
    """``channel`` multiplied by ``factor`` (a unit declared wrongly: kN as tonnes is x9.81).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    factor : float [-]
        Multiplier of the column.
    cls : str
        Class named in the description (``"setpoint"`` or ``"magnitude"``).
    """
    out = _copy(cols)
    out[channel] = out[channel] * factor
    return np.array(t, dtype=float), out, {"class": cls, "column": channel, "factor": float(factor),
                                           "expect": "refuse_or_low"}


def offset(t, cols, channel, value, cls="magnitude"):
    """``value`` added to ``channel`` (e.g. a pressure that reads below vacuum).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    channel : str
        Name of the corrupted column (a key of ``cols``).
    value : float [unit of the column, SI]
        Added to every sample (e.g. [Pa] for the pressure).
    cls : str
        Class named in the description.
    """
    out = _copy(cols)
    out[channel] = out[channel] + value
    return np.array(t, dtype=float), out, {"class": cls, "column": channel, "offset": float(value),
                                           "expect": "refuse"}


def quantised(t, cols, channel, step, hum=0.0, hum_frequency=0.02, hum_phase=0.0):
    """``channel`` read on a grid of ``step`` (a coarse logger or display resolution) with a mains hum
    aliased to ``hum_frequency`` added before the rounding (issue 30's held-back set: a pressure on a
    0.25 bar grid with hum aliased to 0.02 Hz).  Not a class of :data:`CLASSES` (a reading artefact the
    diagnosis reads, not a corrupt log): the honest answer is the sensors component, or the artefact
    reported with the noise floor corrected.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units (with their noise); not modified.
    channel : str
        Name of the quantised column.
    step : float [unit of the channel]
        Grid step of the reading.
    hum : float [unit of the channel]
        Amplitude of the aliased hum.
    hum_frequency : float [Hz]
        Frequency the hum aliases to.
    hum_phase : float [rad]
        Its phase at the first sample.
    """
    out = _copy(cols)
    tt = np.asarray(t, dtype=float)
    y = out[channel] + hum * np.sin(2.0 * np.pi * hum_frequency * (tt - tt[0]) + hum_phase)
    out[channel] = np.round(y / step) * step
    return tt, out, {"class": "quantised", "column": channel, "step": float(step), "hum": float(hum),
                     "hum_frequency": float(hum_frequency), "expect": "sensors"}


def corrupt(kind, t, cols, rng, params):
    """One corruption of class ``kind`` (:data:`CLASSES`) with its size drawn from ``rng``; sizes are
    clearly corrupt, not borderline (the borderline is the quality checks' business).

    Returns ``(t, columns, description)``; ``description["expect"]`` is the honest answer (module table).

    Parameters
    ----------
    kind : str
        Corruption class, one of :data:`CLASSES`.
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict of str to numpy.ndarray
        The run's columns by contract name, SI units; not modified (the result is a copy).
    rng : numpy.random.Generator
        Draws the channel and the size.
    params : heavecomp.params.CMCParams
        The rig's parameters (the pressure offset of ``magnitude`` goes below vacuum from its ``p0`` [Pa]).
    """
    t = np.asarray(t, dtype=float)
    n = t.size
    T = float(t[-1] - t[0])
    if kind == "frozen":
        ch = str(rng.choice(("heave",) + OUTPUTS))
        return frozen(t, cols, ch, float(rng.uniform(0.2, 0.75)) * T)
    if kind == "spike":
        ch = str(rng.choice(("heave",) + OUTPUTS))
        y = np.asarray(cols[ch], dtype=float)
        big = {"heave": 1e3, "stroke": 1e3, "pressure": 1e12, "wob": 1e9}[ch]
        value = float(rng.choice([big, -big, np.nanmedian(y) + 50.0 * (np.nanmax(y) - np.nanmin(y))]))
        return spike(t, cols, ch, int(rng.integers(n // 10, n - n // 10)), value)
    if kind == "time_scale":
        return time_scale(t, cols, float(rng.choice([0.5, 2.0])))
    if kind == "clock_skew":
        ch = str(rng.choice(("heave", "stroke", "pressure")))
        return clock_skew(t, cols, ch, float(rng.choice([-1, 1]) * rng.uniform(4.0, 8.0)))
    if kind == "torn":
        ch = str(rng.choice(OUTPUTS))
        digits = len(repr(float(cols[ch][-1])).split(".")[0].lstrip("-"))
        return torn(t, cols, ch, int(rng.integers(1, max(2, digits))))
    if kind == "non_finite":
        ch = str(rng.choice(("heave",) + OUTPUTS))
        return non_finite(t, cols, ch, int(rng.integers(1, n - 1)), float(rng.choice([math.inf, -math.inf])))
    if kind == "setpoint":
        return scaled(t, cols, "wob", float(rng.choice([9.81, 1 / 9.81, 4.448, 2.5])))
    if kind == "magnitude":
        which = int(rng.integers(3))
        if which == 0:
            return _expect(scaled(t, cols, "stroke", 100.0, "magnitude"), "refuse")
        if which == 1:
            return offset(t, cols, "pressure", -(params.p0 + 3e5))
        return _expect(scaled(t, cols, "heave", 50.0, "magnitude"), "refuse")
    raise ValueError(f"unknown corruption {kind!r}")


def _expect(res, expect):
    t, cols, d = res
    return t, cols, dict(d, expect=expect)
