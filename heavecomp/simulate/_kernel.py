"""Compiled exact stick-slip stepper for the CMC (numba).

The physics is not restated here: the equations are the functions of
:mod:`heavecomp.plants.cmc` and :mod:`heavecomp.friction.laws`, compiled by
numba from the same source (``tests/test_kernel_pins.py`` pins the compiled
forces to the symbolic model anyway).

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

Laws without a jump (``none``; eq. 7 with C_p = 0) are integrated as one smooth
system.  The end of the sine fade-in, where d2z_h/dt2 jumps, is a step
boundary with the left-limit heave sample before it (``core.run_kernel``).  The remainder of a step after an event is integrated to the grid, so
the output stays on the uniform grid.

Heave samples come on a grid of spacing h/2 (the RK4 stage times); between
samples they are interpolated with quintic Hermite polynomials.
"""

from __future__ import annotations

import types

import numba as nb
import numpy as np

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
_ENV: dict = {}


def _compile(func):
    """njit ``func`` from its own source, with the names it calls bound to the
    already-compiled versions (so the plant modules need not import numba)."""
    g = dict(func.__globals__)
    g.update(_ENV)
    clone = types.FunctionType(func.__code__, g, func.__name__, func.__defaults__, func.__closure__)
    clone.__qualname__ = func.__qualname__
    clone.__module__ = func.__module__
    jitted = _jit(clone)
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

from heavecomp.simulate.layout import CHANNELS, NCH, NSTATS, SLIDING, STATS, STUCK  # noqa: E402,F401


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


@_jit
def rhs(t, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ):
    """Time derivatives (ds, dv, dyb, dvb) in the given mode."""
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    dvb = lower_accel_contact(s, v, yb, vb, zh, dzh, cm, PP)
    if mode == STUCK:
        return 0.0, 0.0, vb, dvb
    if smooth:
        p = gas_pressure(s, PP)
        Ff = friction_cont(code, v, p, FP)
    else:
        Ff = sliding_friction(code, d, s, v, FP, PP)
    dv = stroke_accel(s, v, yb, vb, zh, dzh, ddzh, u, Ff, PP)
    return v, dv, vb, dvb


@_jit
def rk4(t, h, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ):
    k1 = rhs(t, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
    h2 = 0.5 * h
    k2 = rhs(t + h2, s + h2 * k1[0], v + h2 * k1[1], yb + h2 * k1[2], vb + h2 * k1[3],
             mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
    k3 = rhs(t + h2, s + h2 * k2[0], v + h2 * k2[1], yb + h2 * k2[2], vb + h2 * k2[3],
             mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
    k4 = rhs(t + h, s + h * k3[0], v + h * k3[1], yb + h * k3[2], vb + h * k3[3],
             mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
    h6 = h / 6.0
    return (s + h6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            v + h6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            yb + h6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]),
            vb + h6 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]))


@_jit
def hold(t, s, v, yb, vb, u, PP, sp, Z, DZ, DDZ):
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    return holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP)


@_jit
def _cubic_root(v0, a0, v1, a1, H):
    """Root in (0, H) of the cubic Hermite through (0, v0, a0), (H, v1, a1); v0 v1 <= 0."""
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
def advance(state, mode_dir, t0, n_steps, h, code, FP, PP, smooth, u, sp, Z, DZ, DDZ,
            out, out_every, out_pos, stats):
    """Advance the CMC ``n_steps`` steps of size ``h`` from ``t0``.

    ``state = [s, v, yb, vb]`` and ``mode_dir = [mode, direction]`` are updated
    in place.  Every ``out_every`` steps a row of CHANNELS is written to
    ``out[out_pos]`` (``out_pos`` is returned, advanced); the first row written
    is the state at ``t0`` when ``out_pos == 0``.  ``stats`` accumulates STATS.
    """
    s, v, yb, vb = state[0], state[1], state[2], state[3]
    mode = int(mode_dir[0])
    d = mode_dir[1]
    cm = 1.0 if contact_switch(yb, vb, PP) > 0.0 else 0.0  # bit on the rock (held between events)
    if smooth:
        mode = SLIDING
    pos = out_pos
    if pos == 0 and out.shape[0] > 0:
        _record(out, pos, t0, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
        pos += 1
    for i in range(n_steps):
        tc = t0 + i * h
        left = h
        for _ev in range(8):
            # tentative step to the grid, cut at the first contact switch (lift-off/touchdown)
            vs = v if mode == SLIDING else 0.0
            s1, v1, yb1, vb1 = rk4(tc, left, s, vs, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
            cut = left
            switched = False
            if (contact_switch(yb1, vb1, PP) > 0.0) != (cm > 0.5):
                cut = _contact_time(tc, left, s, vs, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
                s1, v1, yb1, vb1 = rk4(tc, cut, s, vs, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
                switched = True
            if mode == SLIDING:
                if smooth or v1 * d > 0.0:
                    s, v, yb, vb = s1, v1, yb1, vb1
                    tc += cut
                    left -= cut
                    if switched:
                        stats[5] += 1.0
                        cm = 1.0 - cm
                    if left <= 0.0:
                        break
                    continue
                # velocity reaches zero before the cut: locate it
                a0 = rhs(tc, s, v, yb, vb, SLIDING, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)[1]
                a1 = rhs(tc + cut, s1, v1, yb1, vb1, SLIDING, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)[1]
                tau = _cubic_root(v, a0, v1, a1, cut)
                st, vt, ybt, vbt = s1, v1, yb1, vb1
                for _n in range(4):
                    st, vt, ybt, vbt = rk4(tc, tau, s, v, yb, vb, SLIDING, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
                    if abs(vt) < 1e-13:
                        break
                    at = rhs(tc + tau, st, vt, ybt, vbt, SLIDING, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)[1]
                    if at == 0.0:
                        break
                    nt = tau - vt / at
                    if nt <= 0.0:
                        nt = 0.5 * tau
                    if nt >= cut:
                        nt = 0.5 * (tau + cut)
                    tau = nt
                s, v, yb, vb = st, 0.0, ybt, vbt
                tc += tau
                left -= tau
                F = hold(tc, s, v, yb, vb, u, PP, sp, Z, DZ, DDZ)
                lim = static_limit(code, s, FP, PP)
                if abs(F) <= lim:
                    mode = STUCK
                    stats[1] += 1.0
                else:
                    d = 1.0 if F > 0 else -1.0
                    stats[3] += 1.0
                if left <= 0.0:
                    break
            else:  # STUCK
                F1 = hold(tc + cut, s1, 0.0, yb1, vb1, u, PP, sp, Z, DZ, DDZ)
                lim1 = static_limit(code, s1, FP, PP)
                if abs(F1) <= lim1:
                    stats[0] += cut
                    s, v, yb, vb = s1, 0.0, yb1, vb1
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
                F0 = hold(tc, s, 0.0, yb, vb, u, PP, sp, Z, DZ, DDZ)
                m_lo = static_limit(code, s, FP, PP) - sg * F0
                m_hi = lim1 - sg * F1
                lo, hi = 0.0, cut
                yb_hi, vb_hi = yb1, vb1
                side = 0
                for _n in range(60):
                    if hi - lo < 1e-12 * h:
                        break
                    tt = lo + (hi - lo) * m_lo / (m_lo - m_hi) if m_lo != m_hi else 0.5 * (lo + hi)
                    if not (lo < tt < hi):
                        tt = 0.5 * (lo + hi)
                    s2, v2, yb2, vb2 = rk4(tc, tt, s, 0.0, yb, vb, STUCK, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
                    m = static_limit(code, s2, FP, PP) - sg * hold(tc + tt, s2, 0.0, yb2, vb2, u, PP, sp, Z, DZ, DDZ)
                    if m >= 0.0:
                        lo, m_lo = tt, m
                        if side == -1:
                            m_hi *= 0.5  # Illinois
                        side = -1
                    else:
                        hi, m_hi = tt, m
                        yb_hi, vb_hi = yb2, vb2
                        if side == 1:
                            m_lo *= 0.5
                        side = 1
                    if abs(m) < 1e-9 * (1.0 + abs(lim1)):
                        if m < 0.0:
                            break
                if hi < cut:
                    yb, vb = yb_hi, vb_hi
                else:
                    yb, vb = yb1, vb1
                stats[0] += hi
                tc += hi
                left -= hi
                v = 0.0
                mode = SLIDING
                d = sg
                stats[2] += 1.0
                if left <= 0.0:
                    break
        else:
            # more than 8 events inside one step (never seen in practice): finish the
            # step in the current mode without further event checks, and count it
            if left > 0.0:
                s, v, yb, vb = rk4(tc, left, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
                if mode == STUCK:
                    v = 0.0
                    stats[0] += left
                stats[4] += 1.0
        if (i + 1) % out_every == 0 and pos < out.shape[0]:
            _record(out, pos, t0 + (i + 1) * h, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
            pos += 1
    state[0], state[1], state[2], state[3] = s, v, yb, vb
    mode_dir[0] = mode
    mode_dir[1] = d
    return pos


@_jit
def _contact_time(tc, left, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ):
    """Time in (0, left] just past the zero of the contact switch (Illinois on RK4 sub-steps
    with the contact state ``cm`` held)."""
    g_lo = contact_switch(yb, vb, PP)
    c_lo = cm > 0.5
    s1, v1, yb1, vb1 = rk4(tc, left, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
    g_hi = contact_switch(yb1, vb1, PP)
    lo, hi = 0.0, left
    side = 0
    for _n in range(80):
        if hi - lo < 1e-12 * (1.0 + tc):
            break
        tt = lo + (hi - lo) * g_lo / (g_lo - g_hi) if g_lo != g_hi else 0.5 * (lo + hi)
        if not (lo < tt < hi):
            tt = 0.5 * (lo + hi)
        s2, v2, yb2, vb2 = rk4(tc, tt, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ)
        g = contact_switch(yb2, vb2, PP)
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
def _record(out, pos, t, s, v, yb, vb, mode, d, cm, smooth, code, FP, PP, u, sp, Z, DZ, DDZ):
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p = gas_pressure(s, PP)
    if mode == STUCK:
        Ff = holding_force(s, 0.0, yb, vb, zh, dzh, ddzh, u, PP)
    elif smooth:
        Ff = friction_cont(code, v, p, FP)
    else:
        Ff = sliding_friction(code, d, s, v, FP, PP)
    out[pos, 0] = t
    out[pos, 1] = zh
    out[pos, 2] = s
    out[pos, 3] = p
    out[pos, 4] = wob(yb, vb, PP)
    out[pos, 5] = v
    out[pos, 6] = Ff
    out[pos, 7] = tension(s, v, yb, vb, zh, dzh, PP)
    out[pos, 8] = yb
    out[pos, 9] = vb
    out[pos, 10] = 1.0 if mode == STUCK else 0.0
    out[pos, 11] = u
