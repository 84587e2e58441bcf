"""The CMC's symbolic model with effects at its hooks (casadi), for linearisation, MPC and fitting.

It sits above :mod:`heavecomp.plants.cmc` (the nominal plant functions) and
:mod:`heavecomp.effects.compose` (which writes the hook functions of a set of effects from the
effects' own source): casadi traces the same composed functions the stepper compiles, so no plant
or effect equation is restated here.
"""

from __future__ import annotations

import logging

import numpy as np

from heavecomp.effects.compose import composition, hook_order
from heavecomp.effects.registry import resolve, split_effects
from heavecomp.errors import ParameterError
from heavecomp.friction.laws import friction_cont
from heavecomp.plants.cmc import cylinder_reading, lower_accel_wob, plant_vectors, top_accel, wob
from heavecomp.plants.symbolic import casadi

log = logging.getLogger(__name__)


def casadi_model(params, *, eps: float | None = None, sym: str = "SX", effects=(), friction: bool = True,
                 line_mass: bool = True):
    """The CMC as a casadi Function ``f(x, u) -> (xdot, y)`` with smooth friction.

    Parameters
    ----------
    params : CMCParams
        Validated parameter set (:mod:`heavecomp.params`).
    eps : float, optional
        Regularisation width of the friction's sign [m/s]; required when the
        friction law or an effect has stiction (there is no smooth exact law).
        Ignored without.
    sym : {"SX", "MX"}
        casadi symbol type of the traced function.
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`: instances, registered names or
        ``(name, values)``).  Their hook methods are traced by casadi from the same source the
        stepper compiles (:mod:`heavecomp.effects.compose`); their states follow the four
        plant states.  The seal-friction ``static`` hook (e.g. a dwell gain) has no part in a
        regularised model, which never sticks.  A heave effect scales the heave input (its gain;
        a delay is refused: ParameterError), a channel effect scales and shifts its output
        (``g y + o``; a heave sensor's inverse on the input; a delay or a drift is refused).
    friction : bool
        False: no seal friction at all, neither the law's nor the seal-hook effects' (the
        friction output is 0; ``eps`` is then not needed).  The linear MPC's model: it takes the
        friction as a force input (:func:`heavecomp.controllers.model.discrete_model`).
    line_mass : bool
        False: the mass a line effect's oil adds to the stroke (``line_mass``, e.g. ``line_inertia``) is
        left out.  That oil is accelerated relative to the platform, so in the earth frame the model
        would depend on the heave acceleration, which the controllers' earth-frame model may not
        (:func:`heavecomp.controllers.model.earth_frame`); the controllers predict without it.

    Returns
    -------
    casadi.Function
        Inputs ``x`` (4 + effect states: s, v, y_b, v_b, ...) and ``u`` (4: z_h, dz_h, ddz_h,
        u_active); outputs ``xdot`` and ``y`` (5: wob, stroke, pressure, tension, friction).
    """
    ca = casadi()
    plant = plant_vectors(params)
    effects, heave_fx, sensor_fx = split_effects(resolve(effects))
    comp = composition(hook_order(type(e) for e in effects))
    EP = comp.ep(effects)
    if friction and (plant.has_stiction or comp.adds_stiction(EP)) and not (eps and eps > 0):
        what = ", ".join([f"the friction law {params.friction.model!r}"] * plant.has_stiction
                         + [f"effect {e.name}" for e in effects if e.adds_stiction])
        raise ValueError(f"casadi_model: {what} has stiction; a smooth model needs an explicit eps > 0 [m/s]")
    code, FP, PP = plant.code, plant.FP, plant.PP
    n_eff = comp.n_states
    S = getattr(ca, sym)
    x = S.sym("x", 4 + n_eff)
    u = S.sym("u", 4)
    s, v, yb, vb = x[0], x[1], x[2], x[3]
    X = [x[i] for i in range(4 + n_eff)]  # the stepper's state: the plant's four, then the effects'
    ua = u[3]
    a, b = heave_map(heave_fx + sensor_fx)  # the heave the plant sees from the measured one
    zh, dzh, ddzh = seen_heave(u, (a, b))
    fn = comp.functions
    p, T, hold, dvb = fn["plant_fx"](s, v, yb, vb, X, zh, dzh, ddzh, ua, 1.0, PP, EP)
    dvb = lower_accel_wob(T, yb, vb, PP)  # the clamped contact law (smooth model)
    Ff = smooth_seal_friction(fn, code, v, p, s, X, FP, EP, eps or 1.0) if friction else 0.0 * v
    # the line's oil moves with the stroke (line_mass=False: left out, for a model in the earth frame)
    m_line = fn["line_mass_fx"](s, v, X, PP, EP) if line_mass else 0.0 * v
    dv = top_accel(hold, Ff, m_line, PP)
    rates = fn["effect_rates"](s, v, p, dzh + v - vb, zh + s - yb, X, PP, FP, EP)
    xdot = ca.vertcat(v, dv, vb, dvb, *rates)
    y = {"wob": wob(yb, vb, PP), "stroke": s, "pressure": cylinder_reading(p, m_line, dv, PP)}
    for e in sensor_fx:  # a recorded channel that reads g y + o
        if e.channel in y:
            g, o = _static_affine(e)
            y[e.channel] = g * y[e.channel] + o
    y = ca.vertcat(y["wob"], y["stroke"], y["pressure"], T, Ff)
    return ca.Function("cmc", [x, u], [xdot, y], ["x", "u"], ["xdot", "y"])


def smooth_seal_friction(fn, code, v, p, s, X, FP, EP, eps):
    """The seal friction regularised with width ``eps`` [m/s]: ``J tanh(v/eps) + K`` [N].

    J is the composition's ``jump_fx`` (the friction law's jump and every seal-hook effect's,
    at the smoothed direction of motion), K the law's continuous part: the same expression for
    casadi symbols (:func:`casadi_model`) and numpy arrays (the controllers' friction
    feed-forward, :class:`heavecomp.controllers.model.ControllerFriction`).  Without effects it
    is :func:`heavecomp.friction.laws.friction_smooth`, operation for operation.

    Parameters
    ----------
    fn : dict
        The composition's generated functions (:attr:`heavecomp.effects.compose.Composition.functions`).
    code : int
        Friction-law code.
    v : float or array [m/s]
        Stroke velocity.
    p : float or array [Pa]
        Cylinder gauge pressure.
    s : float or array [m]
        Stroke.
    X : sequence
        The stepper's state (the effects' states at their slots, 4 onwards).
    FP, EP : array
        Friction and effect parameter vectors.
    eps : float [m/s]
        Regularisation width of sign(v) -> tanh(v / eps).
    """
    sv = np.tanh(v / eps)  # the direction of motion, smoothed
    return fn["jump_fx"](code, np.abs(v), p, s, sv, X, FP, EP) * sv + friction_cont(code, v, p, FP)


#: probe times [s] and values for the static maps of heave and channel effects
_PROBE_T = np.linspace(0.0, 10.0, 41)


def _static_gain(e, seen):
    """g of a heave effect whose map is z -> g z (memoryless, time-invariant), else ParameterError."""
    g = float(seen(_PROBE_T, np.ones_like(_PROBE_T), *e.prm)[20])
    ramp = seen(_PROBE_T, _PROBE_T, *e.prm)
    if not np.allclose(ramp[4:-4], g * _PROBE_T[4:-4], rtol=1e-12, atol=1e-12):
        raise ParameterError(f"effect {e.name} ({', '.join(f'{k}={v:g}' for k, v in e.values.items())}): the "
                             "casadi model (linearise, MPC) takes the heave effect's gain only; its delay has no "
                             "finite-state model: set it to 0")
    return g


def _static_affine(e):
    """(g, o) of a channel effect that reads g y + o (memoryless, time-invariant), else ParameterError.
    A reading with :attr:`~heavecomp.effects.base.ChannelEffect.dynamic_params` is read through its static
    map (:meth:`~heavecomp.effects.base.ChannelEffect.static_map`), and what is left out is logged."""
    static = e.static_map()
    left = {k: e.values[k] for k in e.dynamic_params if e.values[k] != static.values[k]}
    if left:
        log.warning("effect %s on %s: the casadi model (linearise, MPC) reads its static map; its %s "
                    "is left out: the controller's model has no state for a reading's dynamics",
                    e.name, e.channel, ", ".join(f"{k}={v:g}" for k, v in left.items()))
        e = static
    t = _PROBE_T
    o = e.measure(t, t, np.zeros_like(t))
    g = e.measure(t, t, np.ones_like(t)) - o
    ramp = e.measure(t, t, t)
    if not (np.allclose(o, o[20], rtol=0, atol=1e-12 * (1 + abs(o[20])))
            and np.allclose(g, g[20], rtol=1e-12, atol=1e-12)
            and np.allclose(ramp[4:-4], g[20] * t[4:-4] + o[20], rtol=1e-12, atol=1e-12 * (1 + abs(o[20])))):
        raise ParameterError(f"effect {e.name} on {e.channel} ({', '.join(f'{k}={v:g}' for k, v in e.values.items())}): "
                             "the casadi model (linearise, MPC) takes a reading g y + o only; a delay, a lag or a drift "
                             "in time has no finite-state, time-invariant model: set it to 0")
    if e.channel == "heave" and g[20] == 0.0:
        raise ParameterError(f"effect {e.name} on heave: a gain of 0 leaves no heave to compensate")
    return float(g[20]), float(o[20])


def seen_heave(u, ab) -> tuple:
    """(z_h, dz_h, ddz_h) the plant sees from the measured heave in the input ``u`` [m, m/s, m/s^2] under the
    heave map ``ab`` = (a, b) of :func:`heave_map`: (a u0 + b, a u1, a u2); the input itself when (1, 0).

    Parameters
    ----------
    u : casadi symbol or sequence
        Model input (z_h [m], dz_h [m/s], ddz_h [m/s^2], u_active [N]); its first three are read.
    ab : (float, float) [-], [m]
        Heave map ``(a, b)`` of :func:`heave_map`: gain and offset.
    """
    a, b = ab
    return (u[0], u[1], u[2]) if (a, b) == (1.0, 0.0) else (a * u[0] + b, a * u[1], a * u[2])


def heave_map(effects) -> tuple:
    """``(a, b)``: the heave the plant sees is ``a z_meas + b`` (its derivatives ``a`` times the
    measured ones) for the heave and channel effects among ``effects`` (instances): a heave
    effect's gain, the inverse of a heave sensor's reading g z + o.  ParameterError for a map with
    memory or a drift (no finite-state, time-invariant model).

    Parameters
    ----------
    effects : sequence of Effect
        Effect instances; those of kind ``heave`` and the channel effects on ``heave`` count.
    """
    a, b = 1.0, 0.0
    for e in effects:
        if e.kind == "heave":
            if any(e.values.get(k, 0.0) != 0.0 for k in e.angle_params):
                raise ParameterError(f"effect {e.name} ({', '.join(f'{k}={v:g}' for k, v in e.values.items())}): the "
                                     "casadi model (linearise, MPC) has no vessel-angle input for its "
                                     f"{', '.join(e.angle_params)}: set it to 0")
            g = _static_gain(e, e.seen)
            a, b = g * a, g * b
        elif e.kind == "output" and e.channel == "heave":
            g, o = _static_affine(e)
            a, b = a / g, (b - o) / g
    return a, b


def initial_effect_states(params, effects=()) -> np.ndarray:
    """The effect states of :func:`casadi_model` at rest at the operating point (its x[4:]).

    Parameters
    ----------
    params : CMCParams
        Validated parameter set (:mod:`heavecomp.params`).
    effects : sequence, optional
        Effects as for :func:`casadi_model` (instances, registered names or ``(name, values)``);
        only the plant effects have states.
    """
    plant = plant_vectors(params)
    effects = split_effects(resolve(effects))[0]
    comp = composition(hook_order(type(e) for e in effects))
    n_eff = comp.n_states
    return comp.initial_state(plant.FP, plant.PP, comp.ep(effects))[4:4 + n_eff]
