"""The diagnosis' effect-aware replay: thin wrappers over the foundation stepper.

The stepper is :func:`heavecomp.simulate._kernel.advance_fx`, the same compiled
exact stick-slip RK4 with event location that :func:`heavecomp.simulate.simulate`
runs (velocity reversal, stick, breakaway, bit lift-off and touchdown, the end of
the fade-in as a step boundary), with the effect terms of
:mod:`heavecomp.effects.terms` switched on by the effect-parameter vector ``EP``
(extra states: gas temperature ratio ``theta``, friction memories ``w`` and ``E``,
dwell time at rest ``tau``).  With every effect off (``EP = 0``) a run is
:func:`heavecomp.simulate.simulate` bit for bit (``tests/test_diagnosis_stepper.py``).

Equations (paper A section 4 / cmc-reference.md with the effect terms,
:func:`heavecomp.effects.terms.plant_fx`)::

    p_gas = gas_pressure_fx(s, theta)          p = p_gas - line_drop(v)
    T_ds  = tension(...) + string_damping_fx(dz_h + v - v_b)
    M_c (ddz_h + dv) = p A - F_f - M_c g - T_ds + u
    F_f   = J(|v|, p, w, E) sign(v) + K(v),   static limit J(0, p, w, E) + dwell_gain(tau)
"""

from __future__ import annotations

import math
import time

import numpy as np

from heavecomp.effects import terms as _terms
from heavecomp.simulate import _kernel as K, excitation
from heavecomp.simulate.core import drive, plant_eigen_rate
from heavecomp.simulate.layout import CHANNELS as _SIM_CHANNELS
from heavecomp.simulate.layout import FX_CHANNELS, NSTATS, SLIDING, STUCK
from heavecomp.friction.laws import FrictionLaw
from heavecomp.plants.cmc import plant_vector

#: recorded channels (columns of the output array): simulate()'s channels, then the gas
#: pressure before the line drop and the gas temperature ratio
CHANNELS = _SIM_CHANNELS + FX_CHANNELS
NCH = len(CHANNELS)
advance_fx = K.advance_fx


def initial_state(FP, EP) -> np.ndarray:
    """State of :func:`heavecomp.simulate._kernel.advance_fx` at rest at the operating point:
    s = v = y_b = v_b = 0, theta = 1, w = 0, E = F_S - F_C, tau = 0."""
    X0 = np.zeros(8)
    X0[4] = 1.0
    X0[6] = FP[0] - FP[1]
    return X0


def smooth_fx(code, FP, EP) -> bool:
    """True when neither the friction law nor an effect has a part that jumps with sign(v):
    the stepper then integrates one smooth system, as :func:`heavecomp.simulate.simulate` does."""
    law = object.__new__(FrictionLaw)  # the law's own rule, from its code and parameters
    law.code, law.FP = int(code), np.asarray(FP, dtype=float)
    return not (law.has_stiction or _terms.adds_stiction(EP))


def _vectors(FP, PP, EP):
    return (np.asarray(FP, dtype=float), np.asarray(PP, dtype=float), np.asarray(EP, dtype=float))


def run_fx(code, FP, PP, EP, hs, h, n_steps, out_every=1, *, u_active=0.0, progress=None, chunk_steps=100_000):
    """Run the effect-aware stepper from rest at the operating point.

    Parameters
    ----------
    code : int
        Friction law code (:mod:`heavecomp.friction.laws`).
    FP, PP, EP : ndarray
        Friction, plant and effect parameter vectors.
    hs : HeaveSamples
        Heave samples spaced ``h/2``.
    h : float [s]
        RK4 step.

    Returns
    -------
    ndarray (n_out, len(CHANNELS))
    """
    FP, PP, EP = _vectors(FP, PP, EP)
    out = np.empty((n_steps // out_every + 1, NCH))
    state = initial_state(FP, EP)
    mode_dir = np.array([float(STUCK), 1.0])
    stats = np.zeros(NSTATS)
    smooth = smooth_fx(code, FP, EP)

    def step(t0, n, Z, DZ, DDZ, pos):
        return advance_fx(state, mode_dir, t0, n, h, int(code), FP, PP, EP, smooth, float(u_active), 0.5 * h,
                          Z, DZ, DDZ, out, int(out_every), int(pos), stats)

    pos = drive(step, hs, h, n_steps, out_every, progress=progress, chunk_steps=chunk_steps)
    return out[:pos]


def replay_dt(params, rate: float | None = None) -> float:
    """RK4 step of the diagnosis [s]: h * lambda_max <= 0.25 and at most 10 ms (a divisor of the
    output interval 1/rate when ``rate`` is given).

    Fixed here (not the simulator's default step, which may trade accuracy for speed): replay,
    candidates and the withheld-effect generator must all integrate on a step whose error is far
    below the measurement noise, or the discretisation error itself shows up as a gap.
    ``lambda_max`` is :func:`heavecomp.simulate.core.plant_eigen_rate`.
    """
    h = min(0.01, 0.25 / plant_eigen_rate(params))
    if rate:
        interval = 1.0 / rate
        h = interval / math.ceil(interval / h - 1e-9)
    return h


def simulate_fx(params, duration, EP=None, *, rate=50.0, heave=None, dt=None):
    """Convenience: simulate ``params`` with effects ``EP`` (default none) for ``duration`` [s].

    Returns a dict channel -> array sampled at ``rate`` [Hz].
    """
    h = dt if dt is not None else replay_dt(params, rate)
    out_every = max(1, int(round(1.0 / (rate * h))))
    n_steps = int(math.ceil(duration / h - 1e-9))
    if heave is None:
        hs = excitation.make_heave(params.heave, n_steps * h, 0.5 * h, params.base_dir,
                                     measurement=params.extra.get("measurement"))
    else:
        hs = excitation.from_series(heave[0], heave[1], n_steps * h, 0.5 * h)
    law = FrictionLaw.from_params(params.friction)
    t0 = time.perf_counter()
    data = run_fx(law.code, law.FP, plant_vector(params), _terms.zero_ep() if EP is None else EP, hs, h, n_steps,
                  out_every)
    res = {c: data[:, i] for i, c in enumerate(CHANNELS)}
    res["wall_time"] = time.perf_counter() - t0
    return res


def run_segments(code, FP, PP, EP, hs, h, bounds, starts, n_out):
    """Multiple-shooting replay: segment k covers grid steps ``bounds[k]`` = (i0, i1) and starts
    from the state ``starts[k]`` = (s, v, y_b, v_b, stuck) estimated from the measurement
    (``None``: rest at the operating point).  Memory states restart from their steady values
    at that velocity (theta = 1, w = |v|, E = (F_S - F_C) e^{-|v|/v_S}, tau = 0).

    Returns the output rows on the stepper grid (row i at t = i h), shape (n_out, NCH).
    """
    FP, PP, EP = _vectors(FP, PP, EP)
    smooth = smooth_fx(code, FP, EP)
    stats = np.zeros(NSTATS)
    out = np.empty((n_out, NCH))
    for (i0, i1), st in zip(bounds, starts):
        if i0 >= n_out - 1:
            break
        i1 = min(i1, n_out - 1)
        X0 = initial_state(FP, EP)
        mode_dir = np.array([float(STUCK), 1.0])
        if st is not None:
            s, v, yb, vb, stuck = st
            X0[0], X0[2], X0[3] = s, yb, vb
            if not stuck:
                X0[1] = v
                mode_dir[:] = (float(SLIDING), 1.0 if v > 0 else -1.0)
            X0[5] = abs(X0[1])
            X0[6] = (FP[0] - FP[1]) * math.exp(-abs(X0[1]) / FP[2]) if FP[2] > 0 else 0.0
        advance_fx(X0, mode_dir, i0 * h, i1 - i0, h, int(code), FP, PP, EP, smooth, 0.0, 0.5 * h, hs.z, hs.dz,
                   hs.ddz, out[i0:], 1, 0, stats)
    return out
