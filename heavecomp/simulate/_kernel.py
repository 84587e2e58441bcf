"""Compiled exact stick-slip stepper for the CMC (numba).

The physics is not restated here: the equations are the functions of
:mod:`heavecomp.plants.cmc`, :mod:`heavecomp.friction.laws` and
:mod:`heavecomp.effects.terms`, compiled by numba from the same source
(``tests/test_kernel_pins.py`` pins the compiled forces to the symbolic model anyway).

One stepper serves the simulator and the gap diagnosis.  It integrates the CMC with
the effect terms of :mod:`heavecomp.effects.terms` (:func:`heavecomp.effects.terms.plant_fx`;
extra states: gas temperature ratio theta, friction memories w and E, dwell time tau),
switched by the effect-parameter vector ``EP``.  :func:`advance` (used by
:func:`heavecomp.simulate.simulate`, the closed loop, the campaigns, and compiled ahead
of time) runs it with every effect off, ``EP = 0``, where the terms reduce to the
plain CMC bit for bit; :func:`advance_fx` (the diagnosis,
:mod:`heavecomp.diagnosis.stepper`) with effects.

Scheme
------
Classical RK4 on a fixed grid ``h`` with event location, as a hybrid system
with two modes:

* **sliding** in a direction ``d = +-1``: friction ``J(d v) d + K(v)``.  When
  the velocity reaches 0 inside a step (only possible when J > 0), the crossing
  is found (cubic Hermite guess, then Newton on the RK4 sub-step) and v is set
  to exactly 0.  There the holding force decides: within the static limit the
  cylinder sticks, otherwise it reverses at once (no stall).
* **stuck**: v = 0 exactly, the stroke is frozen, the lower mass keeps moving;
  the friction is the holding force.  Breakaway when |holding| exceeds the
  static limit, located by a bracketing (Illinois) search on the sub-step and
  taken on the side where the limit is exceeded, so the motion that follows
  leaves v = 0 in the direction of the force.

* **bit contact**: lift-off and touchdown (zero crossings of
  :func:`heavecomp.plants.cmc.contact_switch`, where W has a kink or jumps by
  c_F |v_b|) are located the same way; the contact state is held through every
  RK4 sub-step (unclamped contact law on the rock, none off it) and flipped at
  the event, so no stage straddles the switch.

With the effects, J and the static limit are those of
:func:`heavecomp.effects.terms.sliding_friction_fx` / ``static_limit_fx`` (friction
memories, pressure friction, the dwell gain since the stick event).  Laws without a
jump (``none``; eq. 7 with C_p = 0; and no effect adding one) are integrated as one
smooth system.  The end of the sine fade-in, where d2z_h/dt2 jumps, is a step
boundary with the left-limit heave sample before it (``core.drive``).  The
remainder of a step after an event is integrated to the grid, so the output stays
on the uniform grid.

Heave samples come on a grid of spacing h/2 (the RK4 stage times); between
samples they are interpolated with quintic Hermite polynomials.
"""

from __future__ import annotations

import types

import numba as nb
import numpy as np

from heavecomp.effects import terms as _terms
from heavecomp.friction import laws as _laws
from heavecomp.plants import cmc as _cmc



def _numba_cache_dir():
    """A numba cache folder keyed to the hash of every heavecomp source file.

    numba invalidates a cached function only when *its own* file changes, but the
    compiled steppers inline physics from other files (friction/laws.py,
    plants/cmc.py, ...): after an edit or an upgrade, a stale cache would run old
    physics.  Keying the whole cache to all sources makes that impossible.
    ``NUMBA_CACHE_DIR`` set by the user wins.
    """
    import hashlib
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for p in sorted(root.rglob("*.py")):
        h.update(p.relative_to(root).as_posix().encode())
        h.update(p.read_bytes())
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "heavecomp"
    return base / f"numba-{h.hexdigest()[:16]}"


def _use_keyed_cache():
    import os

    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    from numba.core import config

    d = _numba_cache_dir()
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError:  # read-only home: numba's default (__pycache__ beside the sources)
        return
    config.CACHE_DIR = str(d)


_use_keyed_cache()  # before any njit(cache=True) below or in modules that import this one
_jit = nb.njit(cache=True, fastmath=False)
_jit_inline = nb.njit(cache=True, fastmath=False, inline="always")
_ENV: dict = {}


def _compile(func, inline=False):
    """njit ``func`` from its own source, with the names it calls bound to the
    already-compiled versions (so the plant modules need not import numba).
    ``inline=True`` inlines it into its callers in numba's IR (no call, no array
    reference counting: LLVM leaves larger functions out of line)."""
    g = dict(func.__globals__)
    g.update(_ENV)
    clone = types.FunctionType(func.__code__, g, func.__name__, func.__defaults__, func.__closure__)
    clone.__qualname__ = func.__qualname__
    clone.__module__ = func.__module__
    jitted = (_jit_inline if inline else _jit)(clone)
    _ENV[func.__name__] = jitted
    return jitted


stribeck_curve = _compile(_laws.stribeck_curve)
friction_jump = _compile(_laws.friction_jump)
friction_cont = _compile(_laws.friction_cont)
gas_pressure = _compile(_cmc.gas_pressure)
tension = _compile(_cmc.tension)
contact_force = _compile(_cmc.contact_force)
wob = _compile(_cmc.wob)
holding_force = _compile(_cmc.holding_force)
lower_accel = _compile(_cmc.lower_accel)
lower_accel_contact = _compile(_cmc.lower_accel_contact)
stroke_accel = _compile(_cmc.stroke_accel)
sliding_friction = _compile(_cmc.sliding_friction)
static_limit = _compile(_cmc.static_limit)
contact_switch = _compile(_cmc.contact_switch)
# the stepper integrates the CMC through plant_fx below; the composite CMC functions above
# that it no longer calls directly (holding_force, ..., static_limit) stay compiled for
# callers and for the pins (tests/test_kernel_pins.py): numba compiles them on first use only.
# The effect terms (heavecomp.effects.terms), inlined; with EP = 0 they are the CMC above:
gas_pressure_fx = _compile(_terms.gas_pressure_fx, inline=True)
line_drop = _compile(_terms.line_drop, inline=True)
cylinder_pressure_fx = _compile(_terms.cylinder_pressure_fx, inline=True)
string_damping_fx = _compile(_terms.string_damping_fx, inline=True)
plant_fx = _compile(_terms.plant_fx, inline=True)
pressure_friction_fx = _compile(_terms.pressure_friction_fx, inline=True)
friction_magnitude_fx = _compile(_terms.friction_magnitude_fx, inline=True)
friction_jump_fx = _compile(_terms.friction_jump_fx, inline=True)
sliding_friction_fx = _compile(_terms.sliding_friction_fx, inline=True)
dwell_gain = _compile(_terms.dwell_gain, inline=True)
static_limit_fx = _compile(_terms.static_limit_fx, inline=True)
truth_thermal_rate = _compile(_terms.truth_thermal_rate, inline=True)
lag_rates = _compile(_terms.lag_rates, inline=True)

from heavecomp.simulate.layout import CHANNELS, FX_CHANNELS, NCH, NSTATS, SLIDING, STATS, STUCK  # noqa: E402,F401

#: the effect parameters of the plain CMC (every effect off; a constant of the compiled code)
NO_EFFECTS = np.zeros(_terms.N_EP)
NO_EFFECTS.setflags(write=False)


@_jit
def heave_at(t, sp, Z, DZ, DDZ):
    """Quintic Hermite interpolation of (z, dz, ddz) at time t (grid spacing sp)."""
    x = t / sp
    k = int(np.floor(x))
    n = Z.size
    if k < 0:
        k = 0
    if k >= n - 1:
        k = n - 2
    u = x - k
    if u <= 0.0:
        return Z[k], DZ[k], DDZ[k]
    if u >= 1.0 and k + 1 < n:
        return Z[k + 1], DZ[k + 1], DDZ[k + 1]
    H = sp
    z0, d0, a0 = Z[k], DZ[k], DDZ[k]
    z1, d1, a1 = Z[k + 1], DZ[k + 1], DDZ[k + 1]
    u2 = u * u
    u3 = u2 * u
    u4 = u3 * u
    u5 = u4 * u
    h00 = 1 - 10 * u3 + 15 * u4 - 6 * u5
    h01 = 10 * u3 - 15 * u4 + 6 * u5
    h10 = u - 6 * u3 + 8 * u4 - 3 * u5
    h11 = -4 * u3 + 7 * u4 - 3 * u5
    h20 = 0.5 * (u2 - 3 * u3 + 3 * u4 - u5)
    h21 = 0.5 * (u3 - 2 * u4 + u5)
    # first derivatives wrt u
    g00 = -30 * u2 + 60 * u3 - 30 * u4
    g01 = -g00
    g10 = 1 - 18 * u2 + 32 * u3 - 15 * u4
    g11 = -12 * u2 + 28 * u3 - 15 * u4
    g20 = 0.5 * (2 * u - 9 * u2 + 12 * u3 - 5 * u4)
    g21 = 0.5 * (3 * u2 - 8 * u3 + 5 * u4)
    # second derivatives wrt u
    q00 = -60 * u + 180 * u2 - 120 * u3
    q01 = -q00
    q10 = -36 * u + 96 * u2 - 60 * u3
    q11 = -24 * u + 84 * u2 - 60 * u3
    q20 = 0.5 * (2 - 18 * u + 36 * u2 - 20 * u3)
    q21 = 0.5 * (6 * u - 24 * u2 + 20 * u3)
    z = h00 * z0 + h01 * z1 + H * (h10 * d0 + h11 * d1) + H * H * (h20 * a0 + h21 * a1)
    dz = (g00 * z0 + g01 * z1 + H * (g10 * d0 + g11 * d1) + H * H * (g20 * a0 + g21 * a1)) / H
    ddz = (q00 * z0 + q01 * z1 + H * (q10 * d0 + q11 * d1) + H * H * (q20 * a0 + q21 * a1)) / (H * H)
    return z, dz, ddz


@_jit_inline
def rhs(t, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    """Time derivatives of ``X = (s, v, yb, vb, theta, w, E)`` in the given mode.

    The plant is :func:`heavecomp.effects.terms.plant_fx` (the CMC of
    :mod:`heavecomp.plants.cmc`, bit for bit when ``EP = 0``); the contact state
    ``cm`` is held, the stroke frozen while stuck.
    """
    s, v, yb, vb, th, w, el = X
    if mode == STUCK:
        v = 0.0
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p, T, hold, dvb = plant_fx(s, v, yb, vb, th, zh, dzh, ddzh, u, cm, PP, EP)
    dth = truth_thermal_rate(s, v, th, PP, EP)
    dw, de = lag_rates(v, w, el, FP, EP)
    if mode == STUCK:
        return (0.0, 0.0, vb, dvb, dth, dw, de)
    if smooth:
        Ff = friction_cont(code, v, p, FP)
    else:
        Ff = sliding_friction_fx(code, d, v, p, w, el, FP, EP)
    return (v, (hold - Ff) / PP[1], vb, dvb, dth, dw, de)


@_jit
def _axpy(X, h, k):
    return (X[0] + h * k[0], X[1] + h * k[1], X[2] + h * k[2], X[3] + h * k[3], X[4] + h * k[4],
            X[5] + h * k[5], X[6] + h * k[6])


@_jit
def _at_rest(X):
    """X with the stroke velocity exactly 0."""
    return (X[0], 0.0, X[2], X[3], X[4], X[5], X[6])


@_jit
def rk4(t, h, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    k1 = rhs(t, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    h2 = 0.5 * h
    k2 = rhs(t + h2, _axpy(X, h2, k1), mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    k3 = rhs(t + h2, _axpy(X, h2, k2), mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    k4 = rhs(t + h, _axpy(X, h, k3), mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    h6 = h / 6.0
    return (X[0] + h6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            X[1] + h6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            X[2] + h6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]),
            X[3] + h6 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]),
            X[4] + h6 * (k1[4] + 2 * k2[4] + 2 * k3[4] + k4[4]),
            X[5] + h6 * (k1[5] + 2 * k2[5] + 2 * k3[5] + k4[5]),
            X[6] + h6 * (k1[6] + 2 * k2[6] + 2 * k3[6] + k4[6]))


@_jit
def hold(t, X, u, PP, EP, sp, Z, DZ, DDZ):
    """(holding force, cylinder pressure) at v = 0: while stuck the friction is the holding force."""
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p, T, F, dvb = plant_fx(X[0], 0.0, X[2], X[3], X[4], zh, dzh, ddzh, u, 1.0, PP, EP)
    return F, p


@_jit
def _cubic_root(v0, a0, v1, a1, H):
    """Root in (0, H) of the cubic Hermite through (0, v0, a0), (H, v1, a1); v0 v1 <= 0.

    When ``v0 == 0`` (a sub-step that starts at rest, right after a reversal or a
    breakaway) the root at 0 is the event already handled: the root of the cubic
    divided by ``t`` is returned, the instant the motion that just started stops again.
    """
    if v0 == 0.0:
        return _rest_root(a0, v1, a1, H)
    lo, hi = 0.0, 1.0
    flo = v0
    th = v0 / (v0 - v1) if v0 != v1 else 0.5
    for _ in range(40):
        th2 = th * th
        th3 = th2 * th
        f = (2 * th3 - 3 * th2 + 1) * v0 + (th3 - 2 * th2 + th) * H * a0 + (-2 * th3 + 3 * th2) * v1 + (th3 - th2) * H * a1
        if f == 0.0:
            break
        if (f > 0) == (flo > 0):
            lo = th
            flo = f
        else:
            hi = th
        fp = (6 * th2 - 6 * th) * v0 + (3 * th2 - 4 * th + 1) * H * a0 + (-6 * th2 + 6 * th) * v1 + (3 * th2 - 2 * th) * H * a1
        nt = th - f / fp if fp != 0.0 else 0.5 * (lo + hi)
        if not (lo < nt < hi):
            nt = 0.5 * (lo + hi)
        if abs(nt - th) < 1e-14:
            th = nt
            break
        th = nt
    return th * H


@_jit
def _rest_root(a0, v1, a1, H):
    """Root in (0, H) of the cubic Hermite through (0, 0, a0), (H, v1, a1) divided by t:
    ``q(th) = H a0 (1 - th)^2 + v1 th (3 - 2 th) + H a1 th (th - 1)``, with ``q(0) = H a0``
    and ``q(1) = v1`` of opposite signs, so exactly one root in (0, 1) (H when they are not)."""
    c0 = H * a0
    c1 = 3.0 * v1 - 2.0 * H * a0 - H * a1
    c2 = H * a0 - 2.0 * v1 + H * a1
    if not ((c0 > 0.0 and v1 < 0.0) or (c0 < 0.0 and v1 > 0.0)):
        return H
    if c2 == 0.0:
        return -c0 / c1 * H
    # the two roots without cancellation (c1^2 - 4 c2 c0 > 0: q changes sign on (0, 1))
    qq = -0.5 * (c1 + np.copysign(np.sqrt(c1 * c1 - 4.0 * c2 * c0), c1))
    th = qq / c2
    if not (0.0 < th < 1.0):
        th = c0 / qq
    return min(max(th, 0.0), 1.0) * H


@_jit
def advance(state, mode_dir, t0, n_steps, h, code, FP, PP, smooth, u, sp, Z, DZ, DDZ,
            out, out_every, out_pos, stats):
    """Advance the CMC ``n_steps`` steps of size ``h`` from ``t0``.

    ``state = [s, v, yb, vb]`` and ``mode_dir = [mode, direction]`` are updated
    in place.  Every ``out_every`` steps a row of CHANNELS is written to
    ``out[out_pos]`` (``out_pos`` is returned, advanced); the first row written
    is the state at ``t0`` when ``out_pos == 0``.  ``stats`` accumulates STATS.
    This is :func:`advance_fx` with every effect off.
    """
    X = (state[0], state[1], state[2], state[3], 1.0, 0.0, 0.0)
    X, tau, mode, d, pos = _advance(X, 0.0, int(mode_dir[0]), mode_dir[1], t0, n_steps, h, code, FP, PP,
                                    NO_EFFECTS, smooth, u, sp, Z, DZ, DDZ, out, out_every, out_pos, stats)
    state[0], state[1], state[2], state[3] = X[0], X[1], X[2], X[3]
    mode_dir[0] = mode
    mode_dir[1] = d
    return pos


@nb.njit(cache=True, nogil=True)
def advance_fx(state, mode_dir, t0, n_steps, h, code, FP, PP, EP, smooth, u, sp, Z, DZ, DDZ,
               out, out_every, out_pos, stats):
    """:func:`advance` with the effect terms of :mod:`heavecomp.effects.terms` (parameters ``EP``).

    ``state`` has 8 entries, ``[s, v, yb, vb, theta, w, E, tau]`` (gas temperature ratio,
    friction memories, dwell time at rest); when ``out`` has more than NCH columns the
    next ones get FX_CHANNELS.  Releases the GIL (the diagnosis fits in threads).
    """
    X = (state[0], state[1], state[2], state[3], state[4], state[5], state[6])
    X, tau, mode, d, pos = _advance(X, state[7], int(mode_dir[0]), mode_dir[1], t0, n_steps, h, code, FP, PP,
                                    EP, smooth, u, sp, Z, DZ, DDZ, out, out_every, out_pos, stats)
    for k in range(7):
        state[k] = X[k]
    state[7] = tau
    mode_dir[0] = mode
    mode_dir[1] = d
    return pos


@_jit
def _advance(X, tau, mode, d, t0, n_steps, h, code, FP, PP, EP, smooth, u, sp, Z, DZ, DDZ,
             out, out_every, out_pos, stats):
    """The event-handling stepper; returns ``(X, tau, mode, d, out_pos)`` at ``t0 + n_steps h``."""
    cm = 1.0 if contact_switch(X[2], X[3], PP) > 0.0 else 0.0  # bit on the rock (held between events)
    if smooth:
        mode = SLIDING
    pos = out_pos
    if pos == 0 and out.shape[0] > 0:
        _record(out, pos, t0, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
        pos += 1
    for i in range(n_steps):
        tc = t0 + i * h
        left = h
        for _ev in range(8):
            # tentative step to the grid, cut at the first contact switch (lift-off/touchdown)
            if mode == STUCK:
                X = _at_rest(X)
            X1 = rk4(tc, left, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
            cut = left
            switched = False
            if (contact_switch(X1[2], X1[3], PP) > 0.0) != (cm > 0.5):
                cut = _contact_time(tc, left, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                X1 = rk4(tc, cut, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                switched = True
            if mode == SLIDING:
                if smooth or X1[1] * d > 0.0:
                    X = X1
                    tc += cut
                    left -= cut
                    if switched:
                        stats[5] += 1.0
                        cm = 1.0 - cm
                    if left <= 0.0:
                        break
                    continue
                # velocity reaches zero before the cut: locate it
                a0 = rhs(tc, X, SLIDING, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)[1]
                a1 = rhs(tc + cut, X1, SLIDING, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)[1]
                tz = _cubic_root(X[1], a0, X1[1], a1, cut)
                Xt = X1
                for _n in range(4):
                    Xt = rk4(tc, tz, X, SLIDING, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                    if abs(Xt[1]) < 1e-13:
                        break
                    at = rhs(tc + tz, Xt, SLIDING, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)[1]
                    if at == 0.0:
                        break
                    nt = tz - Xt[1] / at
                    if nt <= 0.0:
                        nt = 0.5 * tz
                    if nt >= cut:
                        nt = 0.5 * (tz + cut)
                    tz = nt
                X = _at_rest(Xt)
                tc += tz
                left -= tz
                F, p = hold(tc, X, u, PP, EP, sp, Z, DZ, DDZ)
                if abs(F) <= static_limit_fx(code, p, X[5], X[6], 0.0, FP, EP):
                    mode = STUCK
                    tau = 0.0
                    stats[1] += 1.0
                else:
                    d = 1.0 if F > 0 else -1.0
                    stats[3] += 1.0
                if left <= 0.0:
                    break
            else:  # STUCK
                F1, p1 = hold(tc + cut, X1, u, PP, EP, sp, Z, DZ, DDZ)
                lim1 = static_limit_fx(code, p1, X1[5], X1[6], tau + cut, FP, EP)
                if abs(F1) <= lim1:
                    stats[0] += cut
                    tau += cut
                    X = X1
                    tc += cut
                    left -= cut
                    if switched:
                        stats[5] += 1.0
                        cm = 1.0 - cm
                    if left <= 0.0:
                        break
                    continue
                # breakaway before the cut: bracket [lo, hi] with margin(lo) >= 0 > margin(hi)
                sg = 1.0 if F1 > 0 else -1.0
                F0, p0 = hold(tc, X, u, PP, EP, sp, Z, DZ, DDZ)
                m_lo = static_limit_fx(code, p0, X[5], X[6], tau, FP, EP) - sg * F0
                m_hi = lim1 - sg * F1
                lo, hi = 0.0, cut
                Xhi = X1
                side = 0
                for _n in range(60):
                    if hi - lo < 1e-12 * h:
                        break
                    tt = lo + (hi - lo) * m_lo / (m_lo - m_hi) if m_lo != m_hi else 0.5 * (lo + hi)
                    if not (lo < tt < hi):
                        tt = 0.5 * (lo + hi)
                    X2 = rk4(tc, tt, X, STUCK, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                    F2, p2 = hold(tc + tt, X2, u, PP, EP, sp, Z, DZ, DDZ)
                    m = static_limit_fx(code, p2, X2[5], X2[6], tau + tt, FP, EP) - sg * F2
                    if m >= 0.0:
                        lo, m_lo = tt, m
                        if side == -1:
                            m_hi *= 0.5  # Illinois
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
                X = _at_rest(Xhi)
                stats[0] += hi
                tc += hi
                left -= hi
                tau = 0.0
                mode = SLIDING
                d = sg
                stats[2] += 1.0
                if left <= 0.0:
                    break
        else:
            # more than 8 events inside one step (chattering; not expected): finish the
            # step in the current mode without further event checks, count it and keep
            # the time of the first (STATS "event_cap_hits", "event_cap_first_t")
            if left > 0.0:
                X = rk4(tc, left, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
                if mode == STUCK:
                    X = _at_rest(X)
                    stats[0] += left
                    tau += left
                if stats[4] == 0.0:
                    stats[6] = tc
                stats[4] += 1.0
        if (i + 1) % out_every == 0 and pos < out.shape[0]:
            _record(out, pos, t0 + (i + 1) * h, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
            pos += 1
    return X, tau, mode, d, pos


@_jit
def _contact_time(tc, left, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    """Time in (0, left] just past the zero of the contact switch (Illinois on RK4 sub-steps
    with the contact state ``cm`` held)."""
    g_lo = contact_switch(X[2], X[3], PP)
    c_lo = cm > 0.5
    X1 = rk4(tc, left, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
    g_hi = contact_switch(X1[2], X1[3], PP)
    lo, hi = 0.0, left
    side = 0
    for _n in range(80):
        if hi - lo < 1e-12 * (1.0 + tc):
            break
        tt = lo + (hi - lo) * g_lo / (g_lo - g_hi) if g_lo != g_hi else 0.5 * (lo + hi)
        if not (lo < tt < hi):
            tt = 0.5 * (lo + hi)
        X2 = rk4(tc, tt, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ)
        g = contact_switch(X2[2], X2[3], PP)
        if (g > 0.0) == c_lo:
            lo, g_lo = tt, g
            if side == -1:
                g_hi *= 0.5  # Illinois
            side = -1
        else:
            hi, g_hi = tt, g
            if side == 1:
                g_lo *= 0.5
            side = 1
    return hi


@_jit
def _record(out, pos, t, X, mode, d, cm, smooth, code, FP, PP, EP, u, sp, Z, DZ, DDZ):
    s, v, yb, vb, th, w, el = X
    if mode == STUCK:
        v = 0.0
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p, T, F, dvb = plant_fx(s, v, yb, vb, th, zh, dzh, ddzh, u, cm, PP, EP)
    if mode == STUCK:
        Ff = F
    elif smooth:
        Ff = friction_cont(code, v, p, FP)
    else:
        Ff = sliding_friction_fx(code, d, v, p, w, el, FP, EP)
    out[pos, 0] = t
    out[pos, 1] = zh
    out[pos, 2] = s
    out[pos, 3] = p
    out[pos, 4] = wob(yb, vb, PP)
    out[pos, 5] = v
    out[pos, 6] = Ff
    out[pos, 7] = T
    out[pos, 8] = yb
    out[pos, 9] = vb
    out[pos, 10] = 1.0 if mode == STUCK else 0.0
    out[pos, 11] = u
    if out.shape[1] >= NCH + 2:  # FX_CHANNELS
        out[pos, NCH] = gas_pressure_fx(s, th, PP, EP)
        out[pos, NCH + 1] = th
