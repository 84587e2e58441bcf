"""The diagnosis' effect-aware replay: thin wrappers over the foundation stepper.

The stepper is :func:`heavecomp.simulate.stepper.kernel_for` of an effect composition
(:mod:`heavecomp.effects.compose`), the same compiled exact stick-slip RK4 with event location
that :func:`heavecomp.simulate.simulate` runs (velocity reversal, stick, breakaway, bit lift-off
and touchdown, the end of the fade-in as a step boundary), with the effects' terms at the
plant's hooks switched on by the effect-parameter vector ``EP`` (extra states: the slots after the
plant's four, dwell time at rest ``tau``).  With every effect off a run is :func:`heavecomp.simulate.simulate`
bit for bit (``tests/test_diagnosis_stepper.py``).

Equations: paper A section 4 / cmc-reference.md with the hook terms of the composed effects
(:class:`heavecomp.effects.compose.Composition`)::

    p_gas = gas hooks(polytropic p(s))         p = line hooks(p_gas)
    T_ds  = string hooks(tension(...))
    M_c (ddz_h + dv) = p A - F_f - M_c g - T_ds + u
    F_f   = J sign(v) + K(v),  J = seal hooks(J_law(|v|, p)),  static limit = static hooks(J(0, p), tau)
"""

from __future__ import annotations

import math
import time

import numpy as np

from heavecomp.effects.compose import composition_for
from heavecomp.simulate import stepper as S
from heavecomp.simulate.core import drive
from heavecomp.simulate.layout import CHANNELS as _SIM_CHANNELS
from heavecomp.simulate.layout import FX_CHANNELS, NSTATS, SLIDING, STUCK, Drive
from heavecomp.simulate import excitation
from heavecomp.effects.registry import resolve
from heavecomp.plants.cmc import eigen_rate, plant_vectors

#: recorded channels (columns of the output array): simulate()'s channels, then the gas
#: pressure before the line and the effects' states
CHANNELS = _SIM_CHANNELS + FX_CHANNELS
NCH = len(CHANNELS)


def smooth_fx(plant, comp, EP) -> bool:
    """True when neither the friction law nor an active effect has a part that jumps with sign(v):
    the stepper then integrates one smooth system, as :func:`heavecomp.simulate.simulate` does.

    Parameters
    ----------
    plant : heavecomp.plants.cmc.PlantVectors
        :func:`heavecomp.plants.cmc.plant_vectors` of the parameter set.
    comp : heavecomp.effects.compose.Composition
        The effect composition.
    EP : numpy.ndarray
        Its effect parameters (:meth:`Composition.ep`).
    """
    return not (plant.has_stiction or comp.adds_stiction(EP))


def run_fx(plant, comp, EP, hs, h, n_steps, out_every=1, *, u_active=0.0, progress=None, chunk_steps=100_000):
    """Run the stepper of the effect composition ``comp`` from rest at the operating point.

    Parameters
    ----------
    plant : PlantVectors
        :func:`heavecomp.plants.cmc.plant_vectors` of the parameter set.
    comp : Composition
        The effect composition (:mod:`heavecomp.effects.compose`).
    EP : ndarray
        Its effect parameters (:meth:`Composition.ep`).
    hs : HeaveSamples
        Heave samples spaced ``h/2``.
    h : float [s]
        RK4 step.
    n_steps : int
        Steps to run.
    out_every : int
        Steps between output rows.
    u_active : float [N]
        Constant active actuator force.
    progress : callable(fraction), optional
        Called after each chunk (:func:`heavecomp.simulate.core.drive`).
    chunk_steps : int
        Steps per chunk between ``progress`` calls.

    Returns
    -------
    ndarray (n_out, len(CHANNELS))
    """
    advance = S.kernel_for(comp)
    args = S.plant_args(plant, EP, smooth_fx(plant, comp, EP))
    out = np.zeros((n_steps // out_every + 1, NCH))  # zeros: the columns of states a composition lacks read 0, not stale memory
    state = comp.initial_state(plant.FP, plant.PP, args.EP)
    mode_dir = np.array([float(STUCK), 1.0])
    stats = np.zeros(NSTATS)

    def step(t0, n, Z, DZ, DDZ, pos):
        return advance(state, mode_dir, t0, n, h, args, Drive(float(u_active), 0.5 * h, Z, DZ, DDZ), out,
                       int(out_every), int(pos), stats)

    pos = drive(step, hs, h, n_steps, out_every, progress=progress, chunk_steps=chunk_steps)
    return out[:pos]


def replay_dt(params, rate: float | None = None) -> float:
    """RK4 step of the diagnosis [s]: h * lambda_max <= 0.25 and at most 20 ms (a divisor of the
    output interval 1/rate when ``rate`` is given: a uniformly sampled log's samples then fall on the
    replay's grid).

    Fixed here (not the simulator's default step, h * lambda_max <= 0.6 and 50 ms): replay,
    candidates and the withheld-effect generator must all integrate on a step whose error is far
    below the measurement noise, or the discretisation error itself shows up as a gap.  On the
    paper-A plant (lambda_max ~ 12 1/s, 20 ms) the replay is within 0.4 N rms of WOB and 0.05 Pa of
    pressure of a run at 2.5 ms, against sensor noise of hundreds of N and kPa; the RK4 error falls
    as (h lambda_max)^4 (``docs/numerics.md``).  Until issue 32 the cap was 10 ms: 16x less error
    that no log can see, at twice the cost of every replay.
    ``lambda_max`` is :func:`heavecomp.plants.cmc.eigen_rate`.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        Parameter set (its fastest eigen-rate bounds the step).
    rate : float [Hz], optional
        Output rate the step must divide; None: any step.
    """

    return step_within(params, 0.02, rate)


def step_within(params, cap: float, rate: float | None = None) -> float:
    """The longest RK4 step [s] with h * lambda_max <= 0.25 and h <= ``cap``, made a divisor of the output
    interval 1/rate when ``rate`` is given (:func:`replay_dt`; the generator's truth step,
    :func:`heavecomp.benchmark.testbed.truth_dt`).

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        Parameter set (its fastest eigen-rate, :func:`heavecomp.plants.cmc.eigen_rate`, bounds the step).
    cap : float [s]
        Longest step.
    rate : float [Hz], optional
        Output rate the step must divide; None: any step.
    """
    h = min(cap, 0.25 / eigen_rate(params))
    if rate:
        interval = 1.0 / rate
        h = interval / math.ceil(interval / h - 1e-9)
    return h


def simulate_fx(params, duration, effects=(), *, rate=50.0, heave=None, dt=None, comp=None):
    """Convenience: simulate ``params`` with ``effects`` (instances, names or (name, values);
    default none) for ``duration`` [s], with the stepper of the composition ``comp`` (default:
    :func:`heavecomp.effects.compose.composition_for` the effects).

    Returns a dict channel -> array sampled at ``rate`` [Hz].

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        Parameter set.
    duration : float [s]
        Simulated time.
    effects : iterable
        Effects on: instances, names or ``(name, values)`` (:func:`heavecomp.effects.registry.resolve`).
    rate : float [Hz]
        Output rate.
    heave : tuple of numpy.ndarray, optional
        Measured heave ``(t [s], z [m])`` driving the run; None: the parameter set's ``[heave]`` table.
    dt : float [s], optional
        RK4 step; None: :func:`replay_dt`.
    comp : heavecomp.effects.compose.Composition, optional
        The composition to run; None: :func:`heavecomp.effects.compose.composition_for` the effects.
    """
    h = dt if dt is not None else replay_dt(params, rate)
    out_every = max(1, int(round(1.0 / (rate * h))))
    n_steps = int(math.ceil(duration / h - 1e-9))
    if heave is None:
        hs = excitation.make_heave(params.heave, n_steps * h, 0.5 * h, params.base_dir,
                                     measurement=params.extra.get("measurement"))
    else:
        hs = excitation.from_series(heave[0], heave[1], n_steps * h, 0.5 * h)
    effects = resolve(effects)
    comp = composition_for(effects) if comp is None else comp
    t0 = time.perf_counter()
    data = run_fx(plant_vectors(params), comp, comp.ep(effects), hs, h, n_steps, out_every)
    res = {c: data[:, i] for i, c in enumerate(CHANNELS)}
    res["wall_time"] = time.perf_counter() - t0
    return res


def run_segments(plant, comp, EP, hs, h, bounds, starts, n_out):
    """Multiple-shooting replay: segment k covers grid steps ``bounds[k]`` = (i0, i1) and starts
    from the state ``starts[k]`` = (s, v, y_b, v_b, stuck) estimated from the measurement
    (``None``: rest at the operating point).  Effect states restart from their steady values
    at that velocity (:meth:`Composition.steady_states`; slow states, e.g. a gas leak's, carry on
    from the end of the previous segment), the dwell time from 0.

    Returns the output rows on the stepper grid (row i at t = i h), shape (n_out, NCH).

    Parameters
    ----------
    plant : heavecomp.plants.cmc.PlantVectors
        :func:`heavecomp.plants.cmc.plant_vectors` of the parameter set.
    comp : heavecomp.effects.compose.Composition
        The effect composition.
    EP : numpy.ndarray
        Its effect parameters (:meth:`Composition.ep`).
    hs : heavecomp.simulate.excitation.HeaveSamples
        Heave samples spaced ``h/2``.
    h : float [s]
        RK4 step.
    bounds : list of (int, int)
        Grid steps (i0, i1) of each segment.
    starts : list of tuple or None
        Start state (s [m], v [m/s], y_b [m], v_b [m/s], stuck) of each segment; None: rest at the
        operating point.
    n_out : int
        Output rows (grid steps + 1).
    """
    advance = S.kernel_for(comp)
    args = S.plant_args(plant, EP, smooth_fx(plant, comp, EP))
    FP, PP, EP = plant.FP, plant.PP, args.EP
    drive_args = Drive(0.0, 0.5 * h, hs.z, hs.dz, hs.ddz)
    stats = np.zeros(NSTATS)
    out = np.zeros((n_out, NCH))  # zeros: the columns of effect states a composition does not have read 0
    prev = None  # where the previous segment ended (slow effect states carry on from there)
    for (i0, i1), st in zip(bounds, starts):
        if i0 >= n_out - 1:
            break
        i1 = min(i1, n_out - 1)
        X0 = comp.initial_state(FP, PP, EP)
        mode_dir = np.array([float(STUCK), 1.0])
        if st is not None:
            s, v, yb, vb, stuck = st
            X0[0], X0[2], X0[3] = s, yb, vb
            if not stuck:
                X0[1] = v
                mode_dir[:] = (float(SLIDING), 1.0 if v > 0 else -1.0)
            comp.steady_states(X0[1], FP, PP, EP, X0, prev)
        advance(X0, mode_dir, i0 * h, i1 - i0, h, args, drive_args, out[i0:], 1, 0, stats)
        prev = X0
    return out
