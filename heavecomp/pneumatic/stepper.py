"""Exact stick-slip simulation of paper B's pneumatic meter-out cylinder (numba).

The physics is not restated: the plant (:mod:`heavecomp.pneumatic.plant`) and
the friction (:mod:`heavecomp.pneumatic.friction`) are compiled from their
own source with :func:`heavecomp.simulate._kernel._compile`.

Scheme: classical RK4 on a fixed step ``h`` as a hybrid system.

* **stuck** (v = 0 exactly, x frozen; the pressures keep evolving): breakaway
  when the drive force ``|A (P_a - P_b)|`` exceeds the static limit — ``F_0``
  before the first motion, ``F_s1`` after a stick.  The crossing is located by
  secant iterations on the RK4 sub-step; the motion starts on the
  *accelerating* branch whose peak is the static force just overcome.
* **sliding** in direction ``d``: the *accelerating* branch is left for the
  *decelerating* one (peak ``F_k``) at the velocity maximum (``d dv/dt <= 0``)
  or when ``|v| >= u_cr``.  When v reaches 0 inside a step the crossing is
  located (secant on the sub-step) and v set to exactly 0; the piston sticks
  if ``|A (P_a - P_b)| <= F_s1``, otherwise it reverses.
* the run stops at either cover (``x <= 0`` or ``x >= L``) or at ``t_end``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from heavecomp.pneumatic import friction as _fr
from heavecomp.pneumatic import plant as _pn
from heavecomp.simulate import cache
from heavecomp.simulate._kernel import _compile

#: the files this stepper is compiled from (its numba cache folder is keyed to them)
SOURCES = ("pneumatic/friction.py", "pneumatic/plant.py", "pneumatic/stepper.py")
_KEY = cache.source_key(SOURCES)

mixed_shape = _compile(_fr.mixed_shape, key=_KEY)
branch_magnitude = _compile(_fr.branch_magnitude, key=_KEY)
critical_ratio = _compile(_pn.critical_ratio, key=_KEY)
flow_function = _compile(_pn.flow_function, key=_KEY)
orifice_flow = _compile(_pn.orifice_flow, key=_KEY)
chamber_volumes = _compile(_pn.chamber_volumes, key=_KEY)
pressure_rates = _compile(_pn.pressure_rates, key=_KEY)
drive_force = _compile(_pn.drive_force, key=_KEY)
piston_accel = _compile(_pn.piston_accel, key=_KEY)

STUCK, SLIDING = 0, 1
CHANNELS = ("t", "position", "velocity", "pressure_a", "pressure_b", "friction", "stuck", "accelerating")
NCH = len(CHANNELS)
STATS = ("n_stick", "n_breakaway", "n_reversal", "t_first_breakaway", "t_first_stick", "t_second_breakaway",
         "v_max", "end_of_stroke", "t_final", "stuck_time")
NST = len(STATS)
_jit = cache.jit(SOURCES)


@_jit
def _deriv(x, v, Pa, Pb, mode, d, peak, PP, FPB):
    dPa, dPb = pressure_rates(x, v, Pa, Pb, PP)
    if mode == STUCK:
        return 0.0, 0.0, dPa, dPb
    Ff = d * branch_magnitude(d * v, peak, FPB)
    return v, piston_accel(Pa, Pb, Ff, PP), dPa, dPb


@_jit
def _rk4(x, v, Pa, Pb, h, mode, d, peak, PP, FPB):
    k1 = _deriv(x, v, Pa, Pb, mode, d, peak, PP, FPB)
    h2 = 0.5 * h
    k2 = _deriv(x + h2 * k1[0], v + h2 * k1[1], Pa + h2 * k1[2], Pb + h2 * k1[3], mode, d, peak, PP, FPB)
    k3 = _deriv(x + h2 * k2[0], v + h2 * k2[1], Pa + h2 * k2[2], Pb + h2 * k2[3], mode, d, peak, PP, FPB)
    k4 = _deriv(x + h * k3[0], v + h * k3[1], Pa + h * k3[2], Pb + h * k3[3], mode, d, peak, PP, FPB)
    h6 = h / 6.0
    return (x + h6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]), v + h6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            Pa + h6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]), Pb + h6 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]))


@_jit
def _push(F, x, L):
    """Drive force that can move a stuck piston: a cover takes the part pushing into it."""
    if x <= 0.0 and F < 0.0:
        return 0.0
    if x >= L and F > 0.0:
        return 0.0
    return F


@_jit
def _locate(x, v, Pa, Pb, h, mode, d, peak, PP, FPB, g0, g1, which, limit):
    """Secant/Illinois search for the sub-step theta*h where the event function
    crosses zero (which = 0: d*v; which = 1: |drive| - limit)."""
    a, b = 0.0, 1.0
    ga, gb = g0, g1
    th = 0.5
    side = 0
    for _ in range(30):
        th = (a * gb - b * ga) / (gb - ga) if gb != ga else 0.5 * (a + b)
        if th <= a or th >= b:
            th = 0.5 * (a + b)
        s = _rk4(x, v, Pa, Pb, th * h, mode, d, peak, PP, FPB)
        if which == 0:
            g = d * s[1]
        else:
            g = abs(_push(drive_force(s[2], s[3], PP), s[0], PP[1])) - limit
        if abs(g) < 1e-13 or (b - a) < 1e-10:
            break
        if (g > 0) == (gb > 0):
            b, gb = th, g
            if side == 1:
                ga *= 0.5
            side = 1
        else:
            a, ga = th, g
            if side == -1:
                gb *= 0.5
            side = -1
    return th


@_jit
def run(state, t_end, h, PP, FPB, moved, stop_at_stick, out, out_every):
    """Integrate from ``state = [x, v, P_a, P_b]`` (stuck if v == 0) to ``t_end`` [s].

    ``moved`` = 1 when the piston has moved before (static limit F_s1, else F_0).
    ``stop_at_stick`` = 1 stops at the first stick after a breakaway.
    Writes every ``out_every``-th step into ``out`` (rows of :data:`CHANNELS`);
    returns (number of rows written, stats array of :data:`STATS`).

    Parameters
    ----------
    state : (4,) array
        Initial ``[x, v, P_a, P_b]`` [m, m/s, Pa abs, Pa abs] (stuck if v == 0; not modified).
    t_end : float [s]
        Duration to integrate.
    h : float [s]
        RK4 step.
    PP : (12,) array
        Plant parameter vector [SI], layout :data:`heavecomp.pneumatic.plant.PP_NAMES`.
    FPB : (6,) array
        Friction parameters ``[F_0, F_s1, F_C, C, u_cr, F_k]`` [N, N, N, N s/m, m/s, N].
    moved : int
        1 when the piston has moved before (static limit F_s1), 0 at the first start (F_0).
    stop_at_stick : int
        1 to stop at the first stick after a breakaway.
    out : (n, 8) array
        Output rows of :data:`CHANNELS`, filled up to its length.
    out_every : int
        Write every ``out_every``-th step [steps].
    """
    stats = np.zeros(NST)
    stats[3] = np.nan
    stats[4] = np.nan
    stats[5] = np.nan
    x, v, Pa, Pb = state[0], state[1], state[2], state[3]
    F0, Fs1, Fk, ucr = FPB[0], FPB[1], FPB[5], FPB[4]
    L = PP[1]
    mode = SLIDING if v != 0.0 else STUCK
    d = 1.0 if v >= 0.0 else -1.0
    peak = Fk
    accel_branch = 0
    n_steps = int(np.ceil(t_end / h - 1e-9))
    pos = 0
    nout = out.shape[0]
    t = 0.0
    for i in range(n_steps + 1):
        if i % out_every == 0 and pos < nout:
            if mode == STUCK:
                Ff = _push(drive_force(Pa, Pb, PP), x, L)  # a cover takes the rest
            else:
                Ff = d * branch_magnitude(d * v, peak, FPB)
            out[pos, 0] = t
            out[pos, 1] = x
            out[pos, 2] = v
            out[pos, 3] = Pa
            out[pos, 4] = Pb
            out[pos, 5] = Ff
            out[pos, 6] = 1.0 if mode == STUCK else 0.0
            out[pos, 7] = accel_branch
            pos += 1
        if i == n_steps:
            break
        rem = h
        tt = t
        guard = 0
        while rem > 1e-15 and guard < 4:
            guard += 1
            s = _rk4(x, v, Pa, Pb, rem, mode, d, peak, PP, FPB)
            if mode == STUCK:
                limit = Fs1 if moved else F0
                g1 = abs(_push(drive_force(s[2], s[3], PP), x, L)) - limit
                if g1 <= 0.0:
                    x, v, Pa, Pb = s
                    stats[9] += rem
                    rem = 0.0
                    break
                g0 = abs(_push(drive_force(Pa, Pb, PP), x, L)) - limit
                th = _locate(x, v, Pa, Pb, rem, mode, d, peak, PP, FPB, min(g0, 0.0), g1, 1, limit)
                s = _rk4(x, v, Pa, Pb, th * rem, mode, d, peak, PP, FPB)
                x, v, Pa, Pb = s
                v = 0.0
                stats[9] += th * rem
                tt += th * rem
                rem -= th * rem
                F = drive_force(Pa, Pb, PP)
                d = 1.0 if F > 0 else -1.0
                peak = limit
                accel_branch = 1
                mode = SLIDING
                moved = 1
                stats[1] += 1
                if stats[1] == 1:
                    stats[3] = tt
                elif stats[1] == 2:
                    stats[5] = tt
                continue
            # sliding
            if d * s[1] < 0.0:
                th = _locate(x, v, Pa, Pb, rem, mode, d, peak, PP, FPB, 0.0, d * s[1], 0, 0.0)
                s = _rk4(x, v, Pa, Pb, th * rem, mode, d, peak, PP, FPB)
                x, v, Pa, Pb = s
                v = 0.0
                tt += th * rem
                rem -= th * rem
                F = drive_force(Pa, Pb, PP)
                if abs(F) <= Fs1:
                    mode = STUCK
                    accel_branch = 0
                    stats[0] += 1
                    if stats[0] == 1:
                        stats[4] = tt
                    if stop_at_stick and stats[1] >= 1:
                        stats[8] = tt
                        return pos, stats
                else:
                    d = 1.0 if F > 0 else -1.0
                    peak = Fs1
                    accel_branch = 1
                    stats[2] += 1
                continue
            x, v, Pa, Pb = s
            rem = 0.0
            if accel_branch == 1:
                a = piston_accel(Pa, Pb, d * branch_magnitude(d * v, peak, FPB), PP)
                if d * a <= 0.0 or d * v >= ucr:
                    accel_branch = 0
                    peak = Fk
        t = (i + 1) * h
        if abs(v) > stats[6]:
            stats[6] = abs(v)
        if x >= L or x <= 0.0 and mode == SLIDING and d < 0:
            stats[7] = 1.0
            stats[8] = t
            return pos, stats
    stats[8] = t
    return pos, stats


@cache.jit(SOURCES, parallel=True)
def run_many(states, t_ends, h, PPs, FPBs, moved, stop_at_stick):
    """Run many independent simulations in parallel (numba prange); returns stats (n, NST).

    Parameters
    ----------
    states : (n, 4) array
        Initial states ``[x, v, P_a, P_b]`` [m, m/s, Pa abs, Pa abs] (copied).
    t_ends : (n,) array [s]
        Duration of each run.
    h : float [s]
        RK4 step, shared.
    PPs : (n, 12) array
        Plant vectors [SI] (layout :data:`heavecomp.pneumatic.plant.PP_NAMES`).
    FPBs : (n, 6) array
        Friction vectors ``[F_0, F_s1, F_C, C, u_cr, F_k]`` [N, N, N, N s/m, m/s, N].
    moved : int
        1: static limit F_s1 (moved before), 0: F_0.
    stop_at_stick : int
        1 to stop each run at its first stick after a breakaway.
    """
    n = states.shape[0]
    res = np.empty((n, NST))
    for k in nb.prange(n):
        out = np.empty((1, NCH))
        _, st = run(states[k].copy(), t_ends[k], h, PPs[k], FPBs[k], moved, stop_at_stick, out, 1 << 62)
        res[k] = st
    return res


def compile_many() -> None:
    """Compile :func:`run_many` for the argument types the stick-slip map passes
    (:func:`heavecomp.pneumatic.stickslip.grid_map`), or load it from numba's cache: a call over
    no run (``setup.py`` runs it at install, so the first ``heavecomp stickslip --map`` compiles nothing)."""
    run_many(np.zeros((0, 4)), np.zeros(0), 1e-3, np.zeros((0, 12)), np.zeros((0, 6)), 1, 1)


def default_step(p, position: float = 0.0) -> float:
    """RK4 step [s]: h * lambda <= 0.3 for the fastest linear mode, at most 1 ms.

    Modes: the charging chamber's pressure at its steepest flow slope (pressure
    ratio 0.995) with the chamber volume at ``position`` [m] (the smallest volume
    the run will see when the piston moves forward from there; 0 = start cover),
    the pneumatic spring of that chamber, and the steepest friction slope.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    position : float [m]
        Piston position the run starts from (0 = start cover).
    """
    PP = p.plant_vector()
    A, k, R, T = p.area, p.kappa, p.gas_constant, p.temperature
    Va = PP[_pn.I_VA0] + A * position
    Ps = p.supply_abs
    dP = Ps * (1 - _pn.LAMINAR_RATIO)
    G = float(_pn.orifice_flow(Ps, Ps - dP, p.supply_area, T, k, R))
    lam_p = k * R * T * (G / dP) / Va
    lam_m = np.sqrt(k * Ps * A * A / (p.mass * Va))
    lam_f = (p.viscous_coefficient + 2 * (p.start_static_force - p.coulomb_force) / p.critical_velocity) / p.mass
    return float(min(1e-3, 0.3 / max(lam_p, lam_m, lam_f)))


def simulate(p, duration: float, *, h: float | None = None, rate: float = 1000.0, state=None, moved=False,
             stop_at_stick=False):
    """Simulate paper B's cylinder; returns a dict of channels (:data:`CHANNELS`) and ``stats``.

    Parameters
    ----------
    p : PneumaticParams
    duration : float [s]
    h : float [s], optional
        RK4 step (default :func:`default_step`).
    rate : float [Hz]
        Output rate.
    state : array [x m, v m/s, P_a Pa abs, P_b Pa abs], optional
        Initial state; default paper B's start: piston at the start cover (x = 0),
        stuck, chamber a at atmosphere, chamber b at the supply pressure (the valve
        has just switched).
    moved : bool
        Static limit F_s1 from the start (instead of F_0).
    stop_at_stick : bool
        Stop at the first stick after a breakaway (the stick-slip decision of
        :func:`heavecomp.pneumatic.stickslip.nonlinear_sticks`).
    """
    h = h or default_step(p)
    out_every = max(1, int(round(1.0 / (rate * h))))
    n_steps = int(np.ceil(duration / h - 1e-9))
    out = np.empty((n_steps // out_every + 2, NCH))
    if state is None:
        state = np.array([0.0, 0.0, p.atmosphere, p.supply_abs])
    st = np.asarray(state, dtype=float).copy()
    n, stats = run(st, float(duration), float(h), p.plant_vector(), p.friction.FPB, int(bool(moved)),
                   int(bool(stop_at_stick)), out, out_every)
    res = {c: out[:n, i].copy() for i, c in enumerate(CHANNELS)}
    res["stats"] = {k: float(v) for k, v in zip(STATS, stats)}
    res["h"] = h
    return res
