"""The CMC's symbolic model with effects at its hooks (casadi), for linearisation, MPC and fitting.

It sits above :mod:`heavecomp.plants.cmc` (the nominal plant functions) and
:mod:`heavecomp.effects.compose` (which writes the hook functions of a set of effects from the
effects' own source): casadi traces the same composed functions the stepper compiles, so no plant
or effect equation is restated here.
"""

from __future__ import annotations

import numpy as np

from heavecomp.effects.compose import composition
from heavecomp.effects.registry import resolve
from heavecomp.friction.laws import friction_cont
from heavecomp.plants.cmc import MC, lower_accel_wob, plant_vectors, wob
from heavecomp.plants.symbolic import casadi


def casadi_model(params, *, eps: float | None = None, sym: str = "SX", effects=()):
    """The CMC as a casadi Function ``f(x, u) -> (xdot, y)`` with smooth friction.

    Parameters
    ----------
    params : CMCParams
    eps : float, optional
        Regularisation width of the friction's sign [m/s]; required when the
        friction law or an effect has stiction (there is no smooth exact law).
        Ignored without.
    sym : {"SX", "MX"}
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`: instances, registered names or
        ``(name, values)``).  Their hook methods are traced by casadi from the same source the
        stepper compiles (:mod:`heavecomp.effects.compose`); their states follow the four
        plant states.  The seal-friction ``static`` hook (e.g. a dwell gain) has no part in a
        regularised model, which never sticks.

    Returns
    -------
    casadi.Function
        Inputs ``x`` (4 + effect states: s, v, y_b, v_b, ...) and ``u`` (4: z_h, dz_h, ddz_h,
        u_active); outputs ``xdot`` and ``y`` (5: wob, stroke, pressure, tension, friction).
    """
    ca = casadi()
    plant = plant_vectors(params)
    effects = resolve(effects)
    comp = composition(tuple(dict.fromkeys(type(e) for e in effects)))
    EP = comp.ep(effects)
    if (plant.has_stiction or comp.adds_stiction(EP)) and not (eps and eps > 0):
        raise ValueError("casadi_model: friction with stiction needs an explicit eps > 0 [m/s]")
    code, FP, PP = plant.code, plant.FP, plant.PP
    n_eff = sum(len(c.states) for c in comp.classes)
    S = getattr(ca, sym)
    x = S.sym("x", 4 + n_eff)
    u = S.sym("u", 4)
    s, v, yb, vb = x[0], x[1], x[2], x[3]
    xe = [x[4 + i] for i in range(n_eff)] + [0.0] * (3 - n_eff)  # the effects' state slots x4..x6
    zh, dzh, ddzh, ua = u[0], u[1], u[2], u[3]
    fn = comp.functions
    p, T, hold, dvb = fn["plant_fx"](s, v, yb, vb, *xe, zh, dzh, ddzh, ua, 1.0, PP, EP)
    dvb = lower_accel_wob(T, yb, vb, PP)  # the clamped contact law (smooth model)
    Ff = fn["jump_fx"](code, np.abs(v), p, *xe, FP, EP) * np.tanh(v / (eps or 1.0)) + friction_cont(code, v, p, FP)
    dv = (hold - Ff) / PP[MC]
    rates = fn["effect_rates"](s, v, p, *xe, PP, FP, EP)[:n_eff]
    xdot = ca.vertcat(v, dv, vb, dvb, *rates)
    y = ca.vertcat(wob(yb, vb, PP), s, p, T, Ff)
    return ca.Function("cmc", [x, u], [xdot, y], ["x", "u"], ["xdot", "y"])


def initial_effect_states(params, effects=()) -> np.ndarray:
    """The effect states of :func:`casadi_model` at rest at the operating point (its x[4:])."""
    plant = plant_vectors(params)
    effects = resolve(effects)
    comp = composition(tuple(dict.fromkeys(type(e) for e in effects)))
    n_eff = sum(len(c.states) for c in comp.classes)
    return comp.initial_state(plant.FP, plant.PP, comp.ep(effects))[4:4 + n_eff]
