"""Compiled exact stick-slip stepper for the CMC (numba): the implementation of
:mod:`heavecomp.simulate.stepper`, which holds the public entry points (call those).

The physics is not restated here: the equations are the functions of
:mod:`heavecomp.plants.cmc` and :mod:`heavecomp.friction.laws`, and the effects' methods at
the plant's hooks (:mod:`heavecomp.effects`), compiled by numba from the same source
(``tests/test_kernel_pins.py`` pins the compiled forces to the symbolic model anyway).

One stepper serves the simulator and the gap diagnosis.  It integrates the hook functions
of an effect composition (:mod:`heavecomp.effects.compose`: ``plant_fx``,
``sliding_friction_fx``, ``static_limit_fx``, ``effect_rates``; the effects' states in the
slots after the plant's four in the state, as many as the composition has, the dwell time tau
since the last stick event kept by the stepper),
each effect switched on by its slot of the effect-parameter vector ``EP``.  This module's
functions are compiled for the composition of no effect, where the hooks are the plain CMC:
:func:`advance` (used by :func:`heavecomp.simulate.simulate`, the closed loop, the campaigns,
and compiled ahead of time).  :func:`kernel_for` compiles the same functions again with the
hooks of a composition (the library's effects for the diagnosis and ``simulate(effects=...)``,
the generator's truth laws for the benchmark) and returns its ``advance``.  Every stepper takes
the plant and what drives it as two tuples (:class:`~heavecomp.simulate.layout.Plant`,
:class:`~heavecomp.simulate.layout.Drive`) and names its output columns and stats slots by
the constants of :mod:`heavecomp.simulate.layout`.

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

With effects, J and the static limit are the composition's ``sliding_friction_fx`` /
``static_limit_fx`` (the seal-friction hooks: friction memories, pressure friction, the
dwell gain since the stick event).  Laws without a
jump (``none``; eq. 7 with C_p = 0; and no effect adding one) are integrated as one
smooth system.  The end of the sine fade-in, where d2z_h/dt2 jumps, is a step
boundary with the left-limit heave sample before it (``core.drive``).  The
remainder of a step after an event is integrated to the grid, so the output stays
on the uniform grid.

Heave samples come on a grid of spacing h/2 (the RK4 stage times); between
samples they are interpolated with quintic Hermite polynomials.
"""

from __future__ import annotations

import sys
import threading
import types

import numba as nb
import numpy as np

from heavecomp.effects import compose as _compose
from heavecomp.friction import laws as _laws
from heavecomp.plants import cmc as _cmc



from heavecomp.simulate import cache as _cache

#: cache key of the nominal stepper (:data:`heavecomp.simulate.layout.KERNEL_SOURCES`); the steppers
#: of effect compositions are keyed by :func:`heavecomp.simulate.cache.composition_key`
KERNEL_KEY = _cache.source_key()


def _jit(func=None, *, inline=False, nogil=False):
    """``njit(cache=True, fastmath=False)`` cached under :data:`KERNEL_KEY` (``inline``: inlined
    into its callers in numba's IR; ``nogil``: releases the GIL)."""
    def decorate(f):
        opts = {"cache": True, "fastmath": False}
        if inline:
            opts["inline"] = "always"
        if nogil:
            opts["nogil"] = True
        with _cache.keyed(KERNEL_KEY):
            return nb.njit(**opts)(f)

    return decorate if func is None else decorate(func)


_ENV: dict = {}


def _compile(func, inline=False, env=None, *, cache=True, name=None, nogil=False, key=None):
    """njit ``func`` from its own source, with the names it calls bound to the
    already-compiled versions (so the plant modules need not import numba).
    ``inline=True`` inlines it into its callers in numba's IR (no call, no array
    reference counting: LLVM leaves larger functions out of line).  ``env`` (default the
    module's ``_ENV``) receives it under ``name`` (default its own); ``cache=False`` for
    source without a file for numba's cache (generated source where no cache folder is writable).  ``key``: the cache key
    (:mod:`heavecomp.simulate.cache`; default :data:`KERNEL_KEY`)."""
    env = _ENV if env is None else env
    g = dict(func.__globals__)
    g.update(env)
    clone = types.FunctionType(func.__code__, g, func.__name__, func.__defaults__, func.__closure__)
    clone.__qualname__ = func.__qualname__ if name is None else name
    clone.__module__ = func.__module__
    opts = {"cache": cache, "fastmath": False}
    if inline:
        opts["inline"] = "always"
    if nogil:
        opts["nogil"] = True
    with _cache.keyed(KERNEL_KEY if key is None else key):
        jitted = nb.njit(**opts)(clone)
    env[func.__name__] = jitted
    return jitted


# the small pieces the hook functions add to the hot path are inlined (as the restated plant was):
# out-of-line they cost the ahead-of-time build ~25 % (numba.pycc does not inline across functions);
# so are the plant's and the laws' functions the hooks call
stribeck_excess = _compile(_laws.stribeck_excess, inline=True)
stribeck_curve = _compile(_laws.stribeck_curve, inline=True)
friction_jump = _compile(_laws.friction_jump, inline=True)
friction_cont = _compile(_laws.friction_cont, inline=True)
gas_pressure = _compile(_cmc.gas_pressure, inline=True)
tension = _compile(_cmc.tension, inline=True)
contact_force = _compile(_cmc.contact_force, inline=True)
wob = _compile(_cmc.wob)
net_force = _compile(_cmc.net_force, inline=True)
top_accel = _compile(_cmc.top_accel, inline=True)
cylinder_reading = _compile(_cmc.cylinder_reading, inline=True)
holding_force = _compile(_cmc.holding_force)
lower_accel_wob = _compile(_cmc.lower_accel_wob)
lower_accel = _compile(_cmc.lower_accel)
lower_accel_tension = _compile(_cmc.lower_accel_tension, inline=True)
lower_accel_contact = _compile(_cmc.lower_accel_contact)
stroke_accel = _compile(_cmc.stroke_accel)
sliding_friction = _compile(_cmc.sliding_friction)
static_limit = _compile(_cmc.static_limit)
contact_switch = _compile(_cmc.contact_switch)
# the stepper integrates the CMC through the hook functions of an effect composition
# (heavecomp.effects.compose): with no effect they are the functions above, composed; the composite
# CMC functions it does not call directly (holding_force, ..., static_limit) stay compiled for callers
# and for the pins (tests/test_kernel_pins.py): numba compiles them on first use only.


def _generated(comp, key):
    """``(functions, cacheable)``: the generated hook functions of ``comp`` (name -> Python function), from a
    file in the cache folder of ``key`` (:func:`heavecomp.simulate.cache.source_file`), so numba's disk cache
    keeps them too when they are compiled on their own (the pins call them from Python: ~4 compiles per
    composition, in every fresh process); ``cacheable`` False (the source exec'd from memory, as
    :class:`~heavecomp.effects.compose.Composition` does) when no cache folder is writable."""
    path = _cache.source_file(key, f"hooks_{comp.key}.py", comp.source)
    if path is None:
        return comp.functions, False
    name = f"_heavecomp_hooks_{key}_{comp.key}"
    if name not in sys.modules:  # a module numba's cache finds again when it loads the compiled code
        module = types.ModuleType(name)
        module.__file__ = str(path)
        exec(compile(comp.source, str(path), "exec"), module.__dict__)
        sys.modules[name] = module
    return vars(sys.modules[name]), True


def _compile_composition(comp, env, key=None):
    """Compile the effects' hook methods and the generated hook functions of ``comp`` into ``env``."""
    for i, c in enumerate(comp.classes):
        for m in c.methods():
            f = getattr(c, m)
            _compile(f, inline=True, env=env, key=key)
            env[f"E{i}_{m}"] = env.pop(f.__name__)
    key = KERNEL_KEY if key is None else key
    functions, cacheable = _generated(comp, key)
    for fname in _compose.GENERATED:
        _compile(functions[fname], inline=True, env=env, cache=cacheable, key=key)


_NONE = _compose.composition(())
_compile_composition(_NONE, _ENV)
gas_fx = _ENV["gas_fx"]
cylinder_pressure_fx = _ENV["cylinder_pressure_fx"]
line_mass_fx = _ENV["line_mass_fx"]
tension_fx = _ENV["tension_fx"]
plant_fx = _ENV["plant_fx"]
jump_fx = _ENV["jump_fx"]
sliding_friction_fx = _ENV["sliding_friction_fx"]
static_limit_fx = _ENV["static_limit_fx"]
effect_rates = _ENV["effect_rates"]
state_axpy = _ENV["state_axpy"]
state_rest = _ENV["state_rest"]
state_dot = _ENV["state_dot"]
state_load = _ENV["state_load"]
state_store = _ENV["state_store"]
state_record = _ENV["state_record"]

from heavecomp.simulate.layout import (CHANNELS, FX_CHANNELS, NCH, NSTATS, SLIDING, STATS, STUCK,  # noqa: E402,F401
                                      COL_FRICTION, COL_GAS_PRESSURE, COL_HEAVE, COL_LOWER_DISPLACEMENT,
                                      COL_LOWER_VELOCITY, COL_PRESSURE, COL_STROKE, COL_STROKE_VELOCITY,
                                      COL_STUCK, COL_T, COL_TENSION, COL_U_ACTIVE, COL_WOB, STAT_EVENT_CAP_FIRST_T,
                                      STAT_EVENT_CAP_HITS, STAT_N_BREAKAWAY, STAT_N_CONTACT_SWITCH, STAT_N_REVERSAL,
                                      STAT_N_STICK, STAT_STUCK_TIME, Plant)

#: the effect parameters of the plain CMC (no effect composed; read-only: for the hook functions'
#: pins, the stepper takes a writable empty array, :func:`heavecomp.simulate.stepper.plant_args`)
NO_EFFECTS = np.zeros(0)
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


@_jit(inline=True)
def rhs(t, X, mode, d, cm, plant, drive):
    """Time derivatives of ``X = (s, v, yb, vb, effect states...)`` in the given mode.

    The plant is the composition's ``plant_fx`` (:mod:`heavecomp.effects.compose`: the CMC of
    :mod:`heavecomp.plants.cmc` with the effects' hook terms; X[4:] are the effects' states, as
    many as the composition has); the contact state ``cm`` is held, the stroke frozen while stuck.
    ``plant`` and ``drive`` are the stepper's :class:`~heavecomp.simulate.layout.Plant` and
    :class:`~heavecomp.simulate.layout.Drive`.
    """
    code, FP, PP, EP, smooth = plant
    u, sp, Z, DZ, DDZ = drive
    s, v, yb, vb = X[0], X[1], X[2], X[3]
    if mode == STUCK:
        v = 0.0
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p, T, hold, dvb = plant_fx(s, v, yb, vb, X, zh, dzh, ddzh, u, cm, PP, EP)
    if mode == STUCK:
        return state_dot(0.0, 0.0, vb, dvb, s, v, p, dzh + v - vb, zh + s - yb, X, PP, FP, EP)
    if smooth:
        Ff = friction_cont(code, v, p, FP)
    else:
        Ff = sliding_friction_fx(code, d, v, p, s, X, FP, EP)
    # the line's oil (its inertance) moves with the stroke: the stroke's mass is M_c + m_line
    return state_dot(v, top_accel(hold, Ff, line_mass_fx(s, v, X, PP, EP), PP), vb, dvb, s, v, p, dzh + v - vb,
                     zh + s - yb, X, PP, FP, EP)


@_jit
def rk4(t, h, X, mode, d, cm, plant, drive):
    """One classical RK4 step of :func:`rhs` from ``X`` at ``t`` over ``h``.

    The four stages are one loop around one call of :func:`rhs`, so its inlined copy of the plant's hook
    functions is compiled once, not four times (issue 32: the superset stepper's compile 39 s -> 17 s of CPU,
    the run time unchanged); the sums are the classical ones in the same order,
    ``X + h/6 (((k1 + 2 k2) + 2 k3) + k4)``, so the step is bit for bit the unrolled one."""
    h2 = 0.5 * h
    acc = X
    Xs = X
    ts = t
    for stage in range(4):
        k = rhs(ts, Xs, mode, d, cm, plant, drive)
        if stage == 0:
            acc = k
            Xs = state_axpy(X, h2, k)
            ts = t + h2
        elif stage == 1:
            acc = state_axpy(acc, 2.0, k)
            Xs = state_axpy(X, h2, k)
        elif stage == 2:
            acc = state_axpy(acc, 2.0, k)
            Xs = state_axpy(X, h, k)
            ts = t + h
        else:
            acc = state_axpy(acc, 1.0, k)
    return state_axpy(X, h / 6.0, acc)


@_jit
def _sliding_accel(t, X, d, cm, plant, drive):
    """dv/dt sliding in direction ``d`` (:func:`rhs`), for the velocity-zero location: a call, not
    inlined, so the plant's hook functions are compiled once here rather than at each of its three
    call sites in :func:`_advance` (issue 32: compile work; it runs only at a reversal or a stick)."""
    return rhs(t, X, SLIDING, d, cm, plant, drive)[1]


@_jit
def _static_limit(code, p, s, d, X, tau, FP, EP):
    """The static friction limit (the composition's ``static_limit_fx``) as a call, not inlined: compiled
    once rather than at each of its four call sites in :func:`_advance` (issue 32: compile work; one call
    per step while stuck, beside the four right-hand sides of :func:`rk4`)."""
    return static_limit_fx(code, p, s, d, X, tau, FP, EP)


@_jit
def hold(t, X, plant, drive):
    """(holding force, cylinder pressure) at v = 0: while stuck the friction is the holding force."""
    code, FP, PP, EP, smooth = plant
    u, sp, Z, DZ, DDZ = drive
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p, T, F, dvb = plant_fx(X[0], 0.0, X[2], X[3], X, zh, dzh, ddzh, u, 1.0, PP, EP)
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


@_jit(nogil=True)
def advance(state, mode_dir, t0, n_steps, h, plant, drive, out, out_every, out_pos, stats):
    """Advance the CMC ``n_steps`` steps of size ``h`` from ``t0``.

    ``plant`` is a :class:`~heavecomp.simulate.layout.Plant` (its ``EP`` the effect parameters of
    this stepper's composition: :meth:`Composition.ep`, empty for this module's stepper, which has
    no effect), ``drive`` a :class:`~heavecomp.simulate.layout.Drive` (active force, heave samples).
    ``state`` is ``[s, v, yb, vb, effect states..., tau]`` (the composition's effect states, the
    dwell time at rest: :meth:`Composition.initial_state`) and ``mode_dir = [mode, direction]``;
    both are updated in place.  Every ``out_every`` steps a row of CHANNELS is written to
    ``out[out_pos]`` (``out_pos`` is returned, advanced); the first row written is the state at
    ``t0`` when ``out_pos == 0``; when ``out`` has more than NCH columns the next ones get
    FX_CHANNELS (the gas pressure, then the effect states as far as there is room).  ``stats``
    accumulates STATS.  Releases the GIL (the diagnosis fits in threads).
    """
    X, tau = state_load(state)
    X, tau, mode, d, pos = _advance(X, tau, int(mode_dir[0]), mode_dir[1], t0, n_steps, h, own_effects(plant),
                                    drive, out, out_every, out_pos, stats)
    state_store(state, X, tau)
    mode_dir[0] = mode
    mode_dir[1] = d
    return pos


#: the name the diagnosis knew the effect-aware stepper by (one stepper now)
advance_fx = advance


@_jit(inline=True)
def _with_no_effects(plant):
    """The plant with the effect parameters of no effect as a constant of the compiled code: the
    nominal stepper reads no EP, and LLVM then drops them (~14 % less time per step than a run-time
    EP, measured on the 1 h paper-A runs); :func:`kernel_for` binds ``own_effects`` to
    :func:`_with_its_effects` instead, so the steppers of compositions use the caller's EP."""
    code, FP, PP, EP, smooth = plant
    return Plant(code, FP, PP, NO_EFFECTS, smooth)


@_jit(inline=True)
def _with_its_effects(plant):
    """The plant as given: the effect parameters of a composition's stepper are the caller's."""
    return plant


#: what :func:`advance` makes of the plant's effect parameters (rebound per composition)
own_effects = _with_no_effects


@_jit(inline=True)
def _accept(X1, tc, left, cut, switched, cm, stats):
    """Take the tentative step ``X1`` of length ``cut``: ``(X, tc, left, cm)`` after it, the held
    contact state flipped (and counted) when the step ended at a contact switch."""
    if switched:
        stats[STAT_N_CONTACT_SWITCH] += 1.0
        cm = 1.0 - cm
    return X1, tc + cut, left - cut, cm


@_jit
def _advance(X, tau, mode, d, t0, n_steps, h, plant, drive, out, out_every, out_pos, stats):
    """The event-handling stepper; returns ``(X, tau, mode, d, out_pos)`` at ``t0 + n_steps h``."""
    code, FP, PP, EP, smooth = plant
    cm = 1.0 if contact_switch(X[2], X[3], PP) > 0.0 else 0.0  # bit on the rock (held between events)
    if smooth:
        mode = SLIDING
    pos = out_pos
    if pos == 0 and out.shape[0] > 0:
        _record(out, pos, t0, X, mode, d, cm, plant, drive)
        pos += 1
    for i in range(n_steps):
        tc = t0 + i * h
        left = h
        for _ev in range(8):
            # tentative step to the grid, cut at the first contact switch (lift-off/touchdown)
            if mode == STUCK:
                X = state_rest(X)
            X1 = rk4(tc, left, X, mode, d, cm, plant, drive)
            cut = left
            switched = False
            if (contact_switch(X1[2], X1[3], PP) > 0.0) != (cm > 0.5):
                cut = _contact_time(tc, left, X, mode, d, cm, plant, drive)
                X1 = rk4(tc, cut, X, mode, d, cm, plant, drive)
                switched = True
            if mode == SLIDING:
                if smooth or X1[1] * d > 0.0:
                    X, tc, left, cm = _accept(X1, tc, left, cut, switched, cm, stats)
                    if left <= 0.0:
                        break
                    continue
                # velocity reaches zero before the cut: locate it
                a0 = _sliding_accel(tc, X, d, cm, plant, drive)
                a1 = _sliding_accel(tc + cut, X1, d, cm, plant, drive)
                tz = _cubic_root(X[1], a0, X1[1], a1, cut)
                Xt = X1
                for _n in range(4):
                    Xt = rk4(tc, tz, X, mode, d, cm, plant, drive)  # mode, not the constant SLIDING: one rk4
                    if abs(Xt[1]) < 1e-13:
                        break
                    at = _sliding_accel(tc + tz, Xt, d, cm, plant, drive)
                    if at == 0.0:
                        break
                    nt = tz - Xt[1] / at
                    if nt <= 0.0:
                        nt = 0.5 * tz
                    if nt >= cut:
                        nt = 0.5 * (tz + cut)
                    tz = nt
                X = state_rest(Xt)
                tc += tz
                left -= tz
                F, p = hold(tc, X, plant, drive)
                if abs(F) <= _static_limit(code, p, X[0], 1.0 if F > 0 else -1.0, X, 0.0, FP, EP):
                    mode = STUCK
                    tau = 0.0
                    stats[STAT_N_STICK] += 1.0
                else:
                    d = 1.0 if F > 0 else -1.0
                    stats[STAT_N_REVERSAL] += 1.0
                if left <= 0.0:
                    break
            else:  # STUCK
                F1, p1 = hold(tc + cut, X1, plant, drive)
                lim1 = _static_limit(code, p1, X1[0], 1.0 if F1 > 0 else -1.0, X1, tau + cut, FP, EP)
                if abs(F1) <= lim1:
                    stats[STAT_STUCK_TIME] += cut
                    tau += cut
                    X, tc, left, cm = _accept(X1, tc, left, cut, switched, cm, stats)
                    if left <= 0.0:
                        break
                    continue
                # breakaway before the cut: bracket [lo, hi] with margin(lo) >= 0 > margin(hi)
                sg = 1.0 if F1 > 0 else -1.0
                F0, p0 = hold(tc, X, plant, drive)
                m_lo = _static_limit(code, p0, X[0], sg, X, tau, FP, EP) - sg * F0
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
                    X2 = rk4(tc, tt, X, mode, d, cm, plant, drive)  # mode (STUCK here): one compiled rk4
                    F2, p2 = hold(tc + tt, X2, plant, drive)
                    m = _static_limit(code, p2, X2[0], sg, X2, tau + tt, FP, EP) - sg * F2
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
                X = state_rest(Xhi)
                stats[STAT_STUCK_TIME] += hi
                tc += hi
                left -= hi
                tau = 0.0
                mode = SLIDING
                d = sg
                stats[STAT_N_BREAKAWAY] += 1.0
                if left <= 0.0:
                    break
        else:
            # more than 8 events inside one step (chattering; not expected): finish the
            # step in the current mode without further event checks, count it and keep
            # the time of the first (STATS "event_cap_hits", "event_cap_first_t")
            if left > 0.0:
                X = rk4(tc, left, X, mode, d, cm, plant, drive)
                if mode == STUCK:
                    X = state_rest(X)
                    stats[STAT_STUCK_TIME] += left
                    tau += left
                if stats[STAT_EVENT_CAP_HITS] == 0.0:
                    stats[STAT_EVENT_CAP_FIRST_T] = tc
                stats[STAT_EVENT_CAP_HITS] += 1.0
        if (i + 1) % out_every == 0 and pos < out.shape[0]:
            _record(out, pos, t0 + (i + 1) * h, X, mode, d, cm, plant, drive)
            pos += 1
    return X, tau, mode, d, pos


@_jit
def _contact_time(tc, left, X, mode, d, cm, plant, drive):
    """Time in (0, left] just past the zero of the contact switch (Illinois on RK4 sub-steps
    with the contact state ``cm`` held)."""
    PP = plant.PP
    g_lo = contact_switch(X[2], X[3], PP)
    c_lo = cm > 0.5
    X1 = rk4(tc, left, X, mode, d, cm, plant, drive)
    g_hi = contact_switch(X1[2], X1[3], PP)
    lo, hi = 0.0, left
    side = 0
    for _n in range(80):
        if hi - lo < 1e-12 * (1.0 + tc):
            break
        tt = lo + (hi - lo) * g_lo / (g_lo - g_hi) if g_lo != g_hi else 0.5 * (lo + hi)
        if not (lo < tt < hi):
            tt = 0.5 * (lo + hi)
        X2 = rk4(tc, tt, X, mode, d, cm, plant, drive)
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
def _record(out, pos, t, X, mode, d, cm, plant, drive):
    code, FP, PP, EP, smooth = plant
    u, sp, Z, DZ, DDZ = drive
    s, v, yb, vb = X[0], X[1], X[2], X[3]
    if mode == STUCK:
        v = 0.0
    zh, dzh, ddzh = heave_at(t, sp, Z, DZ, DDZ)
    p, T, F, dvb = plant_fx(s, v, yb, vb, X, zh, dzh, ddzh, u, cm, PP, EP)
    if mode == STUCK:
        Ff = F
    elif smooth:
        Ff = friction_cont(code, v, p, FP)
    else:
        Ff = sliding_friction_fx(code, d, v, p, s, X, FP, EP)
    m_line = line_mass_fx(s, v, X, PP, EP)
    if m_line != 0.0:  # the cylinder reads the oil column's inertial drop, m a / A (0 while stuck)
        p = cylinder_reading(p, m_line, top_accel(F, Ff, m_line, PP), PP)
    out[pos, COL_T] = t
    out[pos, COL_HEAVE] = zh
    out[pos, COL_STROKE] = s
    out[pos, COL_PRESSURE] = p
    out[pos, COL_WOB] = wob(yb, vb, PP)
    out[pos, COL_STROKE_VELOCITY] = v
    out[pos, COL_FRICTION] = Ff
    out[pos, COL_TENSION] = T
    out[pos, COL_LOWER_DISPLACEMENT] = yb
    out[pos, COL_LOWER_VELOCITY] = vb
    out[pos, COL_STUCK] = 1.0 if mode == STUCK else 0.0
    out[pos, COL_U_ACTIVE] = u
    if out.shape[1] > NCH:  # FX_CHANNELS
        out[pos, COL_GAS_PRESSURE] = gas_fx(s, v, X, PP, EP)
        state_record(out, pos, COL_GAS_PRESSURE + 1, X)


#: kernel functions that call the hook functions, callees first (cloned per composition)
_PER_COMPOSITION = ("rhs", "rk4", "_sliding_accel", "_static_limit", "hold", "_contact_time", "_record", "_advance", "advance")
_KERNELS: dict = {}


_HOOK_ENVS: dict = {}
_LOCK = threading.Lock()


def _hook_env(comp) -> dict:
    """Names -> compiled functions with the hook functions of ``comp`` (compiled on first call)."""
    if comp.key not in _HOOK_ENVS:
        env = dict(_ENV)
        _compile_composition(comp, env, key=_cache.composition_key(comp))
        _HOOK_ENVS[comp.key] = env
    return _HOOK_ENVS[comp.key]


def kernel_for(comp):
    """The compiled :func:`advance` of an effect composition (:class:`heavecomp.effects.compose.Composition`).

    The stepper's functions that call the plant's hooks are compiled again from their own source,
    with the composition's hook functions (the effects' methods, inlined) bound in their place;
    numba's disk cache keeps each under a name and in a folder keyed to what it is compiled from
    (:func:`heavecomp.simulate.cache.composition_key`; about 10-20 s of CPU to compile once per
    composition, then loaded in a fraction of a second).  The composition of no effect is this
    module's :func:`advance`.
    """
    if not comp.classes:
        return advance
    with _LOCK:  # the diagnosis fits in threads: one dispatcher per composition, so one compile
        if comp.key not in _KERNELS:
            env = dict(_hook_env(comp))
            env["own_effects"] = _with_its_effects
            key = _cache.composition_key(comp)
            for fname in _PER_COMPOSITION:
                f = globals()[fname]
                _compile(f.py_func, inline=fname == "rhs", env=env, name=f"{fname}__fx_{key[:12]}",
                         nogil=fname == "advance", key=key)
            _KERNELS[comp.key] = env["advance"]  # numba compiles it once on the first call (its own lock)
    return _KERNELS[comp.key]


def compiled_hooks(comp) -> dict:
    """The compiled hook functions of a composition (name -> numba dispatcher; for the pins)."""
    env = _ENV if not comp.classes else _hook_env(comp)
    return {f: env[f] for f in _compose.GENERATED}
