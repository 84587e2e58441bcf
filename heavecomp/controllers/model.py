"""The controller's discrete linear model, from the plant's casadi jacobians.

No plant equation is restated: :func:`heavecomp.effects.model.casadi_model`
(without seal friction, ``friction=False``: neither the law's nor a seal-hook effect's; the
friction is a force input, forecast by :class:`ControllerFriction` and estimated as a
disturbance) is
differentiated at the operating point (x = 0, heave 0, u = 0) and discretised
exactly for piecewise-constant inputs (zero-order hold) with the control
interval Ts.

Continuous model (deviations from the operating point)::

    dx/dt = A x + B_u u + B_w w + B_f f,     w = [z_h, dz_h, ddz_h],  f = friction force
    y     = C x + D_w w                       y = [wob, stroke, pressure]

f enters like ``-u`` (friction opposes the top mass's stroke, cmc.stroke_accel).

Frame of the state
------------------
The plant's state is relative to the heaving cylinder (stroke s, its rate v).
The controllers predict in the **earth frame** by default (``frame="earth"``):
the top mass's absolute position X = z_h + s and velocity V = dz_h + v
(:func:`earth_frame`, an exact change of variables of the same casadi model).
In that frame the heave acceleration drops out of the equations (the top
mass's inertia sees only the forces; checked symbolically) and the heave
position enters only through the gas spring's stroke and the friction's
relative velocity.  A heave preview error e then moves the predicted WOB by
about k_gas e instead of k_ds e when z_h and the (separately, noisily)
predicted ddz_h disagree — with 5 mm heave-sensor noise on a JONSWAP sea this
halves the closed-loop WOB std (see docs/control.md).  ``frame="stroke"``
keeps the plant's own coordinates (for comparison).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from heavecomp.effects.compose import composition, hook_order
from heavecomp.effects.model import casadi_model, heave_map, initial_effect_states, seen_heave, smooth_seal_friction
from heavecomp.effects.registry import resolve, split_effects
from heavecomp.friction.laws import FORCE_KEYS
from heavecomp.plants.cmc import plant_vectors
from heavecomp.plants.symbolic import casadi

log = logging.getLogger(__name__)

OUT = ("wob", "stroke", "pressure")


@dataclasses.dataclass(frozen=True)
class DiscreteModel:
    """x+ = Ad x + Bu u + Bw w + Bf f ; y = C x + Dw w (deviations, SI)."""

    Ts: float
    Ad: np.ndarray
    Bu: np.ndarray
    Bw: np.ndarray
    Bf: np.ndarray
    C: np.ndarray
    Dw: np.ndarray
    y0: np.ndarray  # operating-point outputs [W_0, 0, p_0]
    Ac: np.ndarray
    Bc: np.ndarray  # continuous [B_u, B_w, B_f]


def controller_params(params, config):
    """The parameters the controller *believes*: gas stiffness scaled by ``gas_stiffness_scale``
    and the friction forces (:data:`heavecomp.friction.laws.FORCE_KEYS`) by ``friction_scale``,
    for robustness studies; the one place both MPCs take them from.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        The true parameters.
    config : ControllerConfig
        ``gas_stiffness_scale`` and ``friction_scale`` [-].

    Returns
    -------
    heavecomp.params.CMCParams
        ``params`` itself when both scales are 1.
    """

    if config.gas_stiffness_scale != 1.0:
        params = params.replace(compensator={"gas_stiffness": params.compensator.gas_stiffness
                                             * config.gas_stiffness_scale})
    f = params.friction
    if f.model != "none" and config.friction_scale != 1.0:
        params = params.replace(friction={k: getattr(f, k) * config.friction_scale for k in FORCE_KEYS})
    return params


FRAMES = ("earth", "stroke")


def earth_frame(f, heave=(1.0, 0.0)):
    """The casadi model ``f(x, u) -> (xdot, y)`` (x = [s, v, y_b, v_b], u = [z_h, dz_h,
    ddz_h, u_active]) with the top mass in the earth frame: x_e = [X, V, y_b, v_b],
    X = z_h + s, V = dz_h + v.  Same inputs and outputs; exact change of variables.
    ``heave = (a, b)``: the plant sees the heave a z_h + b (a heave effect the controller knows,
    :func:`heavecomp.effects.model.heave_map`), so X = a z_h + b + s, V = a dz_h + v.

    Raises ValueError if the transformed dynamics still depend on ddz_h (they must
    not: the heave acceleration acts on the top mass only through the relative
    coordinates).

    Parameters
    ----------
    f : casadi.Function
        The model in the relative frame, ``f(x, u) -> (xdot, y)`` (the effects' states after the
        four plant states).
    heave : (float, float)
        The heave map (a [-], b [m]).

    Returns
    -------
    casadi.Function
        ``cmc_earth(x, u) -> (xdot, y)`` in the earth frame.
    """
    ca = casadi()
    n = f.size1_in(0)  # 4 plant states, then the effects' states (unchanged by the frame)
    xe = ca.SX.sym("xe", n)
    u = ca.SX.sym("u", 4)
    z, dz, ddz = seen_heave(u, heave)
    x = ca.vertcat(xe[0] - z, xe[1] - dz, xe[2:])
    xdot, y = f(x, u)
    xedot = xdot + ca.vertcat(dz, ddz, ca.SX.zeros(n - 2))
    dep = ca.Function("d", [xe, u], [ca.jacobian(xedot, u[2])])(np.zeros(n), np.zeros(4))
    if np.max(np.abs(np.array(dep))) > 1e-9:
        raise ValueError("earth_frame: the model's dynamics depend on the heave acceleration in the earth frame")
    return ca.Function("cmc_earth", [xe, u], [xedot, y], ["x", "u"], ["xdot", "y"])


def controller_model(params, *, eps=None, frame: str = "earth", effects=(), friction: bool = True):
    """The casadi model the controllers predict with (``frame``: see the module docstring;
    ``effects``: effects at the plant's hooks the controller knows, :mod:`heavecomp.effects`;
    ``eps`` [m/s]: the smoothing width of every friction term, the law's and the effects';
    ``friction=False``: no seal friction, :func:`heavecomp.effects.model.casadi_model`).

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        The parameters the controller believes (:func:`controller_params`).
    eps : float or None [m/s]
        Regularisation width of the friction terms; required when the friction law or an effect has
        stiction (:func:`heavecomp.effects.model.casadi_model`).
    frame : str
        ``earth`` or ``stroke`` (:data:`FRAMES`).
    effects : sequence
        Effects the controller knows (instances, names or ``(name, values)``).
    friction : bool
        Include the seal friction.

    Returns
    -------
    casadi.Function
        ``f(x, u) -> (xdot, y)``.

    Raises
    ------
    ValueError
        ``frame`` is not one of :data:`FRAMES`.
    """
    if frame not in FRAMES:
        raise ValueError(f"model frame {frame!r}: not one of {', '.join(FRAMES)}")
    effects = resolve(effects)
    earth = frame == "earth"
    oil = [e for e in effects if getattr(type(e), "line_mass", None) is not None]
    if earth and oil:
        # the oil is accelerated relative to the platform: in the earth frame its inertia needs the heave
        # acceleration, which the earth-frame model must not read; the MPC predicts without that mass
        log.warning("controller model: %s left out of the earth-frame model (the line's oil moves relative to "
                    "the platform; its inertia would need the heave acceleration); the controller predicts "
                    "without it", ", ".join(f"{e.name}'s oil mass ({e.values.get('added_mass', 0.0):.3g} kg)"
                                             for e in oil))
    f = casadi_model(params, eps=eps, effects=effects, friction=friction, line_mass=not (earth and oil))
    return earth_frame(f, heave_map(effects)) if earth else f


def discrete_model(params, Ts: float, frame: str = "earth", effects=()) -> DiscreteModel:
    """Linearise the CMC without seal friction at the operating point and discretise (ZOH).

    The seal friction, the law's and every seal-hook effect's, is left out (a force input
    ``f``, like ``-u``): linearised at rest its smoothed sign would be a damping J / eps that
    the sliding cylinder never has.  :class:`ControllerFriction` forecasts it instead.

    Parameters
    ----------
    params : CMCParams
    Ts : float [s]
        Control interval.
    frame : {"earth", "stroke"}
        Coordinates of the top mass (module docstring).
    effects : sequence, optional
        Effects at the plant's hooks the model includes (their states follow the plant's four,
        linearised about their values at rest, :func:`heavecomp.effects.model.initial_effect_states`).
    """
    from scipy.linalg import expm


    ca = casadi()
    nominal = params.replace(friction={"model": "none"})
    f = controller_model(nominal, frame=frame, effects=effects, friction=False)
    nx = f.size1_in(0)
    x = ca.SX.sym("x", nx)
    u = ca.SX.sym("u", 4)
    xdot, y = f(x, u)
    J = ca.Function("J", [x, u], [ca.jacobian(xdot, x), ca.jacobian(xdot, u), ca.jacobian(y, x), ca.jacobian(y, u)])
    x0, u0 = np.r_[np.zeros(4), initial_effect_states(nominal, effects)], np.zeros(4)
    Ac, Bfull, Cy, Dy = (np.array(M) for M in J(x0, u0))
    y0 = np.array(f(x0, u0)[1]).ravel()
    Bu = Bfull[:, 3:4]
    Bw = Bfull[:, 0:3]
    Bf = -Bu
    Bc = np.hstack([Bu, Bw, Bf])
    n, m = Ac.shape[0], Bc.shape[1]
    M = np.zeros((n + m, n + m))
    M[:n, :n] = Ac
    M[:n, n:] = Bc
    E = expm(M * Ts)
    Ad, Bd = E[:n, :n], E[:n, n:]
    rows = [0, 1, 2]  # wob, stroke, pressure
    return DiscreteModel(Ts=Ts, Ad=Ad, Bu=Bd[:, 0:1], Bw=Bd[:, 1:4], Bf=Bd[:, 4:5], C=Cy[rows], Dw=Dy[rows, 0:3],
                         y0=y0[rows], Ac=Ac, Bc=Bc)


class ControllerFriction:
    """The seal friction the controllers believe, smoothed with the controller's ``friction_eps``.

    The friction law of ``cparams`` (:func:`controller_params`: forces scaled) and the seal-hook
    effects among ``effects`` (the same expression as the nonlinear MPC's casadi model,
    :func:`heavecomp.effects.model.smooth_seal_friction`, evaluated on numpy arrays).  An effect
    that adds stiction (``dwell_stiction``, ``pressure_friction``, ``position_friction``) is
    smooth here like the law; a static-limit hook (the dwell gain) has no part in a smooth model.

    Parameters
    ----------
    cparams : CMCParams
        The parameters the controller believes.
    eps : float [m/s]
        Regularisation width of sign(v) (``ControllerConfig.friction_eps``).
    effects : sequence, optional
        Effects the controller knows (instances or names; only the plant effects matter here).
    """

    def __init__(self, cparams, eps: float, effects=()):
        plant = plant_vectors(cparams)
        self.code, self.FP, self.PP = plant.code, plant.FP, plant.PP
        self.eps = float(eps)
        fx = split_effects(resolve(effects))[0]
        self.comp = composition(hook_order(type(e) for e in fx))  # as the stepper applies them
        self.EP = self.comp.ep(fx)
        self.effects = fx
        #: indices into the model state x of the effect states the seal friction reads
        self.seal_slots = tuple(i for e in fx if e.hook == "seal_friction" for i in self.comp.slots[e.name])
        self.x_rest = initial_effect_states(cparams, fx)

    def _states(self, v, x_eff):
        """The stepper-state tuple X for :meth:`force`: effect states at their steady value sliding
        at ``v`` where the effect has one (a friction memory), else ``x_eff`` (the estimate)."""
        x_eff = self.x_rest if x_eff is None else np.asarray(x_eff, dtype=float)
        X = [0.0, 0.0, 0.0, 0.0] + [x_eff[i] + 0.0 * v for i in range(x_eff.size)]
        for e in self.effects:
            sl = self.comp.slots[e.name]
            if sl and e.steady is not None:
                for i, val in zip(sl, e.steady(v, self.FP, self.PP, *e.prm)):
                    X[i] = val + 0.0 * v
        return tuple(X)

    def force(self, v, p, s=0.0, x_eff=None) -> np.ndarray:
        """Smoothed seal friction at stroke velocity ``v`` [m/s], pressure ``p`` [Pa] and stroke
        ``s`` [m] (arrays broadcast) [N]; ``x_eff``: the effect states (default: at rest)."""
        v = np.asarray(v, dtype=float)
        fn = self.comp.functions
        if not self.comp.n_ep:  # the law alone: no effect state to set up
            return smooth_seal_friction(fn, self.code, v, np.asarray(p, dtype=float), s, (), self.FP, self.EP,
                                        self.eps)
        return smooth_seal_friction(fn, self.code, v, np.asarray(p, dtype=float), np.asarray(s, dtype=float),
                                    self._states(v, x_eff), self.FP, self.EP, self.eps)

    def static_limit(self, p, s=0.0, x_eff=None) -> float:
        """Largest friction that holds the piston at rest [N] (the law's and the seal-hook effects'
        jump at zero velocity, the larger of the two directions)."""
        fn = self.comp.functions
        X = self._states(0.0, x_eff) if self.comp.n_ep else ()
        p = np.asarray(p, dtype=float)
        return float(max(fn["jump_fx"](self.code, 0.0 * p, p, s, d, X, self.FP, self.EP) for d in (1.0, -1.0)))
