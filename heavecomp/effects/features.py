"""Building blocks of the seal-friction effects' equation-error features (issue 12 item 3).

An effect's :meth:`~heavecomp.effects.base.Effect.features` returns regressor columns built from
measured signals only (``sig``: ``t`` [s], ``x`` [m], ``v`` [m/s], ``a`` [m/s^2], ``dwell`` [s],
``p`` [Pa] where the plant has one).  Friction features are plant-independent: the CMC, the 1-DOF
axis (EMPS) and the O-ring seal rig use the same columns.  The few signal operations they share
(a first-order lag, the rest that preceded a breakaway, the time at rest) are written here once.
"""

from __future__ import annotations

import functools

import numpy as np


def first_order_lag(t, x, tau: float, y0: float = 0.0) -> np.ndarray:
    """y with dy/dt = (x - y) / tau, x held over each sample interval (exact step).

    Parameters
    ----------
    t : array, s
        Sample times (strictly increasing, uniform or not).
    x : array
        Input at the same samples.
    tau : float, s
        Time constant.
    y0 : float
        State before the first sample.

    Returns
    -------
    ndarray
        ``y[i]`` is the state when ``x[i]`` is sampled (before ``x[i]`` acts), so ``y`` lags ``x``.
    """
    x = np.asarray(x, dtype=float)
    dt = np.diff(np.asarray(t, dtype=float))
    if dt.size and np.ptp(dt) <= 1e-9 * abs(float(dt.mean())):
        # uniform sampling: the same recursion, y[i+1] = d y[i] + (1 - d) x[i], as a linear filter
        from scipy.signal import lfilter

        d = float(np.exp(-dt.mean() / tau))
        return lfilter([0.0, 1.0 - d], [1.0, -d], x, zi=[float(y0)])[0]
    return compiled(_lag_steps)(x, np.exp(-dt / tau), float(y0))


def _lag_steps(x, decay, y0):
    """y[i + 1] = x[i] + (y[i] - x[i]) decay[i] from y[0] = ``y0``: a first-order lag, x held over each step
    (run :func:`compiled`)."""
    y = np.empty(x.size)
    yk = y0
    for i in range(x.size):
        y[i] = yk
        if i < decay.size:
            yk = x[i] + (yk - x[i]) * decay[i]
    return y


def euler_affine(c0, c1, dt, max_h, y0):
    """y with dy/dt = c0[k] + c1[k] y over the k-th interval ``dt[k]`` [s] (coefficients held): explicit
    Euler steps, ceil(dt[k] / ``max_h``) equal ones per interval, from y[0] = ``y0``; y has dt.size + 1
    samples (run :func:`compiled`).  An effect whose state rate is affine in its state builds ``c0``
    and ``c1`` from its own ``rates`` (:meth:`heavecomp.effects.gas_thermal.GasThermal.features`).

    Parameters
    ----------
    c0, c1 : numpy.ndarray
        The rate's constant [unit/s] and its coefficient of y [1/s] over each interval.
    dt : numpy.ndarray [s]
        The intervals.
    max_h : float [s]
        Longest Euler step.
    y0 : float
        y at the start.
    """
    y = np.empty(dt.size + 1)
    yk = y0
    y[0] = yk
    for k in range(dt.size):
        sub = max(1, int(np.ceil(dt[k] / max_h)))
        h = dt[k] / sub
        for _ in range(sub):
            yk = yk + h * (c0[k] + c1[k] * yk)
        y[k + 1] = yk
    return y


@functools.cache
def compiled(fn):
    """``fn``, a sample-by-sample loop of this module over float arrays, compiled by numba on first use
    (cached on disk): the same source at machine speed.  The equation-error features run these loops
    over every sample of a log, several times per diagnosis (a 600 s log at 50 Hz: 30 000 samples, ~2 us
    each in the interpreter).  numba's own disk cache, checked against this file, is enough here: the
    loops call nothing from another file (the steppers, which inline physics from many files, need the
    keyed folders of :mod:`heavecomp.simulate.cache`, a layer above this one).

    Parameters
    ----------
    fn : callable
        A loop of this module (:func:`_lag_steps`, :func:`euler_affine`).
    """
    from numba import njit

    return njit(cache=True)(fn)


def rest_durations(t, still) -> tuple[np.ndarray, np.ndarray]:
    """Time at rest so far (0 while moving) and the duration of the last rest, held while moving
    (0 before the first rest) [s]; ``still`` is a boolean array (at rest).  A rest that ends at sample
    i lasted t[i] - t[start].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    still : numpy.ndarray of bool
        At rest, per sample.
    """
    t = np.asarray(t, dtype=float)
    still = np.asarray(still, dtype=bool)
    before = np.r_[False, still[:-1]]
    start = np.maximum.accumulate(np.where(still & ~before, t, -np.inf))  # start of the current/last rest
    so_far = np.where(still, t - start, 0.0)
    ends = ~still & before                                                 # first moving sample after a rest
    idx = np.maximum.accumulate(np.where(ends, np.arange(t.size), -1))     # the last such sample so far
    last = np.where(idx >= 0, (t - start)[np.maximum(idx, 0)], 0.0)
    return so_far, np.where(still, so_far, last)


def dwell_time(t, v, dead_band: float) -> np.ndarray:
    """Time at rest so far [s]: grows while |v| <= ``dead_band`` [m/s], 0 while sliding.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    v : numpy.ndarray [m/s]
        Stroke velocity.
    dead_band : float [m/s]
        Speed at or under which the stroke counts as at rest.
    """
    return rest_durations(t, np.abs(np.asarray(v, dtype=float)) <= dead_band)[0]


def breakaway_dwell(t, dwell, window: float) -> np.ndarray:
    """The length [s] of the rest that preceded the current sliding phase, during the first
    ``window`` [s] of that phase (0 elsewhere and while at rest).

    ``dwell`` is the time at rest so far (:func:`dwell_time`): a sliding sample has dwell 0, and the
    rest before it ended at the last sample with dwell > 0.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    dwell : numpy.ndarray [s]
        Time at rest so far (:func:`dwell_time`).
    window : float [s]
        Length of the start of each sliding phase that carries the preceding rest's length.
    """
    t = np.asarray(t, dtype=float)
    dwell = np.asarray(dwell, dtype=float)
    out = np.zeros(t.size)
    last_rest, t_break = 0.0, None
    for i in range(t.size):
        if dwell[i] > 0.0:
            last_rest, t_break = dwell[i], None
            continue
        if t_break is None:
            t_break = t[i]
        if last_rest > 0.0 and t[i] - t_break < window:
            out[i] = last_rest
    return out


def need(sig: dict, *names) -> bool:
    """True when every signal of ``names`` is in ``sig``.

    Parameters
    ----------
    sig : dict
        Signals by name.
    *names : str
        Signal names needed.
    """
    return all(n in sig for n in names)


def distance_lag(x, u, length: float, y0: float = 0.0) -> np.ndarray:
    """y with dy/dx_s = (u - y) / ``length`` over the sliding distance x_s (the path |dx| travelled):
    a first-order lag in distance, not in time (Dahl's memory), u held over each sample interval.

    Parameters
    ----------
    x : array, m
        Position of the sliding element at each sample.
    u : array
        Input at the same samples (e.g. sign(v)).
    length : float, m
        Relaxation length.
    y0 : float
        State before the first sample.

    Returns
    -------
    ndarray
        ``y[i]`` is the state when ``u[i]`` is sampled (before ``u[i]`` acts), so ``y`` lags ``u``;
        at rest (no distance travelled) it holds.
    """
    return compiled(_lag_steps)(np.asarray(u, dtype=float),
                                np.exp(-np.abs(np.diff(np.asarray(x, dtype=float))) / length), float(y0))


def _bouc_wen_steps(e, zy, n, m):
    """z over the stretch samples ``e`` from z = 0: dz = de - (|de| z |z|^(n-1) + de |z|^n) / (2 z_y^n),
    ``m`` equal explicit sub-steps per sample interval (run :func:`compiled`; the Bouc-Wen rate of
    :meth:`heavecomp.effects.string_hysteresis.StringHysteresis.string_rates`, which a test pins it to)."""
    z = np.empty(e.size)
    zk = 0.0
    if e.size:
        z[0] = zk
    for k in range(e.size - 1):
        d = (e[k + 1] - e[k]) / m
        for _ in range(m):
            u = zk / zy
            au = abs(u)
            zk = zk + d - 0.5 * (abs(d) * u * max(au, 1e-12) ** (n - 1.0) + d * au ** n)
        z[k + 1] = zk
    return z


def hysteretic_displacement(e, zy: float, exponent: float = 1.0) -> np.ndarray:
    """The Bouc-Wen displacement z [m] over a stretch history ``e`` [m], from z = 0 at the first sample:
    the rate is homogeneous of degree one in the stretch rate, so time drops out and z is integrated in
    the stretch, in equal explicit sub-steps of at most z_y / 20 per sample interval.

    Parameters
    ----------
    e : array, m
        Stretch samples.
    zy : float, m
        Yield displacement z_y.
    exponent : float
        Bouc-Wen exponent n.
    """
    e = np.asarray(e, dtype=float)
    step = float(np.max(np.abs(np.diff(e)), initial=0.0))
    m = int(min(max(np.ceil(step / (zy / 20.0)), 1), 200))
    return compiled(_bouc_wen_steps)(e, float(zy), float(exponent), m)
