"""Effect-aware exact stick-slip stepper for the CMC (numba).

The foundation stepper (:mod:`heavecomp.simulate._kernel`) has no effect
hooks; this one adds the terms of :mod:`heavecomp.effects.terms` (extra
states: gas temperature ratio ``theta``, friction memories ``w`` and ``E``,
and the dwell time at rest ``tau``).  The CMC equations are not restated: the
plant primitives (``tension``, ``wob``, ``heave_at``, ``friction_jump``,
``friction_cont``) are the foundation's compiled functions, and the effect
terms are compiled from their single source with
:func:`heavecomp.simulate._kernel._compile`.

Scheme: as the foundation — classical RK4 on a fixed grid with the two modes
*sliding* (direction d) and *stuck* (v = 0 exactly, friction = holding force
while within the static limit); velocity zeros located by a cubic-Hermite
guess refined by Newton on the RK4 sub-step, breakaways by an Illinois
bracketing search.  With every effect off (``EP = 0``) it reproduces
:func:`heavecomp.simulate.simulate` (pinned by ``tests/test_diagnosis_stepper.py``).

Equations (paper A section 4 / cmc-reference.md with the effect terms)::

    p_gas = gas_pressure_fx(s, theta)          p = p_gas - line_drop(v)
    T_ds  = tension(...) + string_damping_fx(dz_h + v - v_b)
    M_c (ddz_h + dv) = p A - F_f - M_c g - T_ds + u
    F_f   = J(|v|, p, w, E) sign(v) + C_v v,   static limit J(0, p, w, E) + dwell_gain(tau)
"""

from __future__ import annotations

import math
import time

import numba as nb
import numpy as np

from heavecomp.effects import terms as _terms
from heavecomp.simulate import _kernel as K

_jit = nb.njit(cache=True, fastmath=False)

gas_pressure_fx = K._compile(_terms.gas_pressure_fx)
truth_thermal_rate = K._compile(_terms.truth_thermal_rate)
line_drop = K._compile(_terms.line_drop)
pressure_friction_fx = K._compile(_terms.pressure_friction_fx)
friction_magnitude_fx = K._compile(_terms.friction_magnitude_fx)
dwell_gain = K._compile(_terms.dwell_gain)
lag_rates = K._compile(_terms.lag_rates)
string_damping_fx = K._compile(_terms.string_damping_fx)
heave_at = K.heave_at
tension = K.tension
wob = K.wob
friction_jump = K.friction_jump
friction_cont = K.friction_cont
_cubic_root = K._cubic_root

STUCK = 0
SLIDING = 1
#: recorded channels (columns of the output array)
CHANNELS = ("t", "heave", "stroke", "pressure", "wob", "stroke_velocity", "stuck", "friction", "gas_pressure",
            "theta")
NCH = len(CHANNELS)


@_jit
def jump_fx(code, a, p, w, el, FP, EP):
    """J with the effect terms (paper A eq. 4 for code STRIBECK, else the foundation law)."""
    if code == 1:
        return friction_magnitude_fx(a, p, w, el, FP, EP)
    return friction_jump(code, a, p, FP) + pressure_friction_fx(p, EP)


@_jit
def _common(t, s, v, yb, vb, th, PP, EP, sp, Z, DZ, DDZ):
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p = gas_pressure_fx(s, th, PP, EP) - line_drop(v, EP)
    T = tension(s, v, yb, vb, zh, dzh, PP) + string_damping_fx(dzh + v - vb, EP)
    hold = p * PP[0] - PP[1] * PP[13] - T - PP[1] * ddzh
    dvb = (T - PP[2] * PP[13] + wob(yb, vb, PP)) / PP[2]
    return p, hold, dvb


@_jit
def rhs(t, X, mode, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    s, v, yb, vb, th, w, el = X
    if mode == STUCK:
        v = 0.0
    p, hold, dvb = _common(t, s, v, yb, vb, th, PP, EP, sp, Z, DZ, DDZ)
    dth = truth_thermal_rate(s, v, th, PP, EP)
    dw, de = lag_rates(v, w, el, FP, EP)
    if mode == STUCK:
        return (0.0, 0.0, vb, dvb, dth, dw, de)
    Ff = jump_fx(code, d * v, p, w, el, FP, EP) * d + friction_cont(code, v, p, FP)
    return (v, (hold + u - Ff) / PP[1], vb, dvb, dth, dw, de)


@_jit
def _axpy(X, h, k):
    return (X[0] + h * k[0], X[1] + h * k[1], X[2] + h * k[2], X[3] + h * k[3], X[4] + h * k[4],
            X[5] + h * k[5], X[6] + h * k[6])


@_jit
def rk4(t, h, X, mode, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    k1 = rhs(t, X, mode, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    h2 = 0.5 * h
    k2 = rhs(t + h2, _axpy(X, h2, k1), mode, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    k3 = rhs(t + h2, _axpy(X, h2, k2), mode, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    k4 = rhs(t + h, _axpy(X, h, k3), mode, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    h6 = h / 6.0
    return (X[0] + h6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            X[1] + h6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            X[2] + h6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]),
            X[3] + h6 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]),
            X[4] + h6 * (k1[4] + 2 * k2[4] + 2 * k3[4] + k4[4]),
            X[5] + h6 * (k1[5] + 2 * k2[5] + 2 * k3[5] + k4[5]),
            X[6] + h6 * (k1[6] + 2 * k2[6] + 2 * k3[6] + k4[6]))


@_jit
def _hold(t, X, PP, EP, u, sp, Z, DZ, DDZ):
    p, hold, dvb = _common(t, X[0], 0.0, X[2], X[3], X[4], PP, EP, sp, Z, DZ, DDZ)
    return hold + u, p


@_jit
def _limit(code, p, X, tau, FP, EP):
    return jump_fx(code, 0.0, p, X[5], X[6], FP, EP) + dwell_gain(tau, EP)


@nb.njit(cache=True, nogil=True)
def advance_fx(X0, mode_dir, t0, n_steps, h, code, FP, PP, EP, u, sp, Z, DZ, DDZ, out, out_every, out_pos):
    """Advance ``n_steps`` of size ``h`` from ``t0``; ``X0`` (8: s, v, yb, vb, theta, w, E, tau) and
    ``mode_dir`` are updated in place; rows of CHANNELS go to ``out`` every ``out_every`` steps."""
    X = (X0[0], X0[1], X0[2], X0[3], X0[4], X0[5], X0[6])
    tau = X0[7]
    mode = int(mode_dir[0])
    d = mode_dir[1]
    pos = out_pos
    if pos == 0 and out.shape[0] > 0:
        _record(out, pos, t0, X, mode, d, tau, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
        pos += 1
    for i in range(n_steps):
        tc = t0 + i * h
        left = h
        for _ev in range(8):
            if mode == SLIDING:
                X1 = rk4(tc, left, X, SLIDING, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                if X1[1] * d > 0.0:
                    X = X1
                    break
                a0 = rhs(tc, X, SLIDING, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)[1]
                a1 = rhs(tc + left, X1, SLIDING, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)[1]
                tz = _cubic_root(X[1], a0, X1[1], a1, left)
                Xt = X1
                for _n in range(4):
                    Xt = rk4(tc, tz, X, SLIDING, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                    if abs(Xt[1]) < 1e-13:
                        break
                    at = rhs(tc + tz, Xt, SLIDING, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)[1]
                    if at == 0.0:
                        break
                    nt = tz - Xt[1] / at
                    if nt <= 0.0:
                        nt = 0.5 * tz
                    if nt >= left:
                        nt = 0.5 * (tz + left)
                    tz = nt
                X = (Xt[0], 0.0, Xt[2], Xt[3], Xt[4], Xt[5], Xt[6])
                tc += tz
                left -= tz
                F, p = _hold(tc, X, PP, EP, u, sp, Z, DZ, DDZ)
                if abs(F) <= _limit(code, p, X, 0.0, FP, EP):
                    mode = STUCK
                    tau = 0.0
                else:
                    d = 1.0 if F > 0 else -1.0
                if left <= 0.0:
                    break
            else:
                X1 = rk4(tc, left, X, STUCK, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                F1, p1 = _hold(tc + left, X1, PP, EP, u, sp, Z, DZ, DDZ)
                lim1 = _limit(code, p1, X1, tau + left, FP, EP)
                if abs(F1) <= lim1:
                    tau += left
                    X = X1
                    break
                sg = 1.0 if F1 > 0 else -1.0
                F0, p0 = _hold(tc, X, PP, EP, u, sp, Z, DZ, DDZ)
                m_lo = _limit(code, p0, X, tau, FP, EP) - sg * F0
                m_hi = lim1 - sg * F1
                lo, hi = 0.0, left
                Xhi = X1
                side = 0
                for _n in range(60):
                    if hi - lo < 1e-12 * h:
                        break
                    tt = lo + (hi - lo) * m_lo / (m_lo - m_hi) if m_lo != m_hi else 0.5 * (lo + hi)
                    if not (lo < tt < hi):
                        tt = 0.5 * (lo + hi)
                    X2 = rk4(tc, tt, X, STUCK, d, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                    F2, p2 = _hold(tc + tt, X2, PP, EP, u, sp, Z, DZ, DDZ)
                    m = _limit(code, p2, X2, tau + tt, FP, EP) - sg * F2
                    if m >= 0.0:
                        lo, m_lo = tt, m
                        if side == -1:
                            m_hi *= 0.5
                        side = -1
                    else:
                        hi, m_hi = tt, m
                        Xhi = X2
                        if side == 1:
                            m_lo *= 0.5
                        side = 1
                    if abs(m) < 1e-9 * (1.0 + abs(lim1)):
                        if m < 0.0:
                            break
                X = (X[0], 0.0, Xhi[2], Xhi[3], Xhi[4], Xhi[5], Xhi[6])
                tc += hi
                left -= hi
                tau = 0.0
                mode = SLIDING
                d = sg
                if left <= 0.0:
                    break
        if (i + 1) % out_every == 0 and pos < out.shape[0]:
            _record(out, pos, t0 + (i + 1) * h, X, mode, d, tau, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
            pos += 1
    for k in range(7):
        X0[k] = X[k]
    X0[7] = tau
    mode_dir[0] = mode
    mode_dir[1] = d
    return pos


@_jit
def _record(out, pos, t, X, mode, d, tau, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    s, v, yb, vb, th, w, el = X
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    pg = gas_pressure_fx(s, th, PP, EP)
    p, hold, dvb = _common(t, s, v, yb, vb, th, PP, EP, sp, Z, DZ, DDZ)
    if mode == STUCK:
        Ff = hold + u
    else:
        Ff = jump_fx(code, d * v, p, w, el, FP, EP) * d + friction_cont(code, v, p, FP)
    out[pos, 0] = t
    out[pos, 1] = zh
    out[pos, 2] = s
    out[pos, 3] = p
    out[pos, 4] = wob(yb, vb, PP)
    out[pos, 5] = v
    out[pos, 6] = 1.0 if mode == STUCK else 0.0
    out[pos, 7] = Ff
    out[pos, 8] = pg
    out[pos, 9] = th


def initial_state(FP, EP) -> np.ndarray:
    """Start at rest at the operating point (stuck): theta = 1, w = 0, E = F_S - F_C, tau = 0."""
    X0 = np.zeros(8)
    X0[4] = 1.0
    X0[6] = FP[0] - FP[1]
    return X0


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
    n_out = n_steps // out_every + 1
    out = np.empty((n_out, NCH))
    FP = np.asarray(FP, dtype=float)
    PP = np.asarray(PP, dtype=float)
    EP = np.asarray(EP, dtype=float)
    X0 = initial_state(FP, EP)
    mode_dir = np.array([float(STUCK), 1.0])
    done, pos = 0, 0
    while done < n_steps:
        n = min(max(out_every, chunk_steps - chunk_steps % out_every), n_steps - done)
        pos = advance_fx(X0, mode_dir, done * h, n, h, int(code), FP, PP, EP, float(u_active), 0.5 * h,
                         hs.z, hs.dz, hs.ddz, out, out_every, pos)
        done += n
        if progress is not None:
            progress(done / n_steps)
    return out[:pos]


def replay_dt(params, rate: float | None = None) -> float:
    """RK4 step of the diagnosis [s]: h * lambda_max <= 0.25 and at most 10 ms (a divisor of the
    output interval 1/rate when ``rate`` is given).

    Fixed here (not the simulator's default step, which may trade accuracy for speed): replay,
    candidates and the withheld-effect generator must all integrate on a step whose error is far
    below the measurement noise, or the discretisation error itself shows up as a gap.
    ``lambda_max`` is :func:`heavecomp.simulate.core.plant_eigen_rate`.
    """
    from heavecomp.simulate.core import plant_eigen_rate

    h = min(0.01, 0.25 / plant_eigen_rate(params))
    if rate:
        interval = 1.0 / rate
        h = interval / math.ceil(interval / h - 1e-9)
    return h


def simulate_fx(params, duration, EP=None, *, rate=50.0, heave=None, dt=None):
    """Convenience: simulate ``params`` with effects ``EP`` (default none) for ``duration`` [s].

    Returns a dict channel -> array sampled at ``rate`` [Hz].
    """
    from heavecomp.friction.laws import FrictionLaw
    from heavecomp.plants.cmc import plant_vector
    from heavecomp.simulate import excitation
    h = dt if dt is not None else replay_dt(params, rate)
    out_every = max(1, int(round(1.0 / (rate * h))))
    n_steps = int(math.ceil(duration / h - 1e-9))
    if heave is None:
        hs = excitation.make_heave(params.heave, n_steps * h, 0.5 * h, params.base_dir)
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
    FP = np.asarray(FP, dtype=float)
    PP = np.asarray(PP, dtype=float)
    EP = np.asarray(EP, dtype=float)
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
        advance_fx(X0, mode_dir, i0 * h, i1 - i0, h, int(code), FP, PP, EP, 0.0, 0.5 * h, hs.z, hs.dz, hs.ddz,
                   out[i0:], 1, 0)
    return out
