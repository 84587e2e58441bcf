"""Loop contract, controller registry, the passive and PID controllers.

Contract (``docs/control.md``): a controller is built from the
plant parameters and a frozen config, ``reset()`` clears its memory and
``step(t, measurement, preview=None) -> u`` returns the commanded active force
[N] (positive up on the top mass).  A controller should command within
``|u| <= u_max`` and ``|u - u_prev| <= rate_max / control_rate``; the base class
does not clip its command: the actuator in the closed loop applies the limits,
once, and counts the commands that break them (``violations_*``).  ``stats``
counts solver failures and fallbacks; ``solve_times`` holds the wall time of
each ``step`` [s].

The contract is duck-typed: :class:`Controller` is a convenience, not a
requirement (:mod:`heavecomp.controllers.registry`, ``docs/control.md``).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from heavecomp.controllers.model import FRAMES
from heavecomp.errors import InputError, did_you_mean
from heavecomp.params.cmc import active
from heavecomp.params.core import q
from heavecomp.params.core import check_value

#: ControllerConfig fields that take one of a few names
CHOICES = {"nlp_solver": ("sqp", "ipopt"), "model_frame": FRAMES}


@dataclass(frozen=True)
class Measurement:
    """What a rig measures at one control instant (SI, noise included).

    Attributes
    ----------
    t : float [s]
    stroke : float [m]
    pressure : float [Pa]
        Main-cylinder gauge pressure.
    wob : float [N]
    heave : float [m]
    u_active : float [N]
        Active force the actuator applies now (its own load cell / pressure).
    """

    t: float
    stroke: float
    pressure: float
    wob: float
    heave: float
    u_active: float = 0.0


@dataclass(frozen=True, kw_only=True)
class ControllerConfig:
    """Settings shared by all controllers (frozen).

    Attributes
    ----------
    u_max : float [N]
        Active force limit |u| <= u_max (``[active].u_max``).
    rate_max : float [N/s]
        Force rate limit (``[active].rate_max``).
    control_rate : float [Hz]
        Controller sample rate; commands are held between samples.
    horizon : int
        MPC prediction horizon in control intervals (default 20 = 1 s at 20 Hz).
    q_wob : float [1/N^2]
        MPC weight on the WOB error (default 1 per kN^2).
    r_u : float [1/N^2]
        MPC weight on the active force.
    r_du : float [1/N^2]
        MPC weight on the force change per interval.
    friction_eps : float [m/s]
        Regularisation width of the friction model used for feed-forward and the
        nonlinear MPC.
    friction_feedforward : bool
        Linear MPC: add the friction model's force at the predicted stroke
        velocity v = -dz_h (full compensation) to the disturbance forecast.
    friction_scale : float
        Multiplies the controller's friction-model forces (robustness studies:
        0.7 / 1.3 = a 30 % wrong friction model).
    gas_stiffness_scale : float
        Multiplies k_gas in the controller's model (robustness to a wrong gas spring).
    kp, ki, kd : float
        PID gains on the WOB error [-, 1/s, s] (u = kp e + ki int e + kd de/dt, e = WOB - W_0).
    pid_tf : float [s]
        Time constant of the PID's derivative filter.
    observer_sigma_d : float [N]
        Random-walk std per interval of the observer's force disturbance (how fast
        it follows friction changes).
    nlp_solver : {"sqp", "ipopt"}
        Nonlinear MPC solver: casadi sqpmethod + qrqp (default) or ipopt.
    sqp_iterations : int
        Largest number of SQP iterations per control step.
    predictor_order : int
        Number of past heave samples (every 2nd sample at the control rate) the
        direct multi-step heave predictor regresses on.
    predictor_window : float [s]
        Forgetting time constant of the predictor's least-squares fit.
    model_frame : {"earth", "stroke"}
        Coordinates of the MPCs' prediction model: the top mass in the earth frame
        (default; the heave acceleration drops out, so heave-preview errors matter
        through the gas spring only) or relative to the cylinder as the plant is
        written (:mod:`heavecomp.controllers.model`).
    """

    u_max: float = q(60e3, "N", bounds=(1e3, 1e7), unit_low="kN", why="as [active].u_max")
    rate_max: float = q(300e3, "N/s", bounds=(1e3, 1e9), unit_low="kN/s", why="as [active].rate_max")
    control_rate: float = q(20.0, "Hz", bounds=(1.0, 1e3), why="as [active].control_rate")
    horizon: int = q(20, "-", bounds=(1, 500), integer=True,
                     why="at least one interval; 500 intervals (25 s at 20 Hz) is beyond any useful preview")
    q_wob: float = q(1e-6, "1/N^2", bounds=(0.0, 1.0), open_low=True,
                     why="> 0, or the MPC has nothing to track")
    r_u: float = q(1e-12, "1/N^2", bounds=(0.0, 1.0), why="a non-negative weight")
    r_du: float = q(3e-7, "1/N^2", bounds=(0.0, 1.0), why="a non-negative weight")
    friction_eps: float = q(0.02, "m/s", bounds=(1e-3, 1.0), unit_high="mm/s",
                            why="tanh width: below 1 mm/s the smoothed friction is too stiff for the solvers")
    friction_feedforward: bool = True
    friction_scale: float = q(1.0, "-", bounds=(0.0, 10.0), why="multiplier of the model's friction")
    gas_stiffness_scale: float = q(1.0, "-", bounds=(0.1, 10.0), why="multiplier of k_gas (keeps the gas "
                                   "column of the controller's model plausible)")
    kp: float = q(0.5, "-", bounds=(0.0, 100.0), why="non-negative: a negative gain is positive feedback")
    ki: float = q(0.3, "1/s", bounds=(0.0, 100.0), why="non-negative")
    kd: float = q(0.2, "s", bounds=(0.0, 100.0), why="non-negative")
    pid_tf: float = q(0.2, "s", bounds=(0.0, 100.0), why="a non-negative time constant")
    observer_sigma_d: float = q(300.0, "N", bounds=(0.0, 1e7), open_low=True,
                                why="> 0, or the observer never follows the friction")
    nlp_solver: str = "sqp"
    sqp_iterations: int = q(3, "-", bounds=(1, 100), integer=True,
                            why="at least one iteration, or the force stays at its start value")
    predictor_order: int = q(80, "-", bounds=(2, 400), integer=True,
                             why="two lags represent one sine; 400 lags (40 s at 20 Hz) overfit")
    predictor_window: float = q(240.0, "s", bounds=(1.0, 1e5), why="forgetting time of at least 1 s")
    model_frame: str = "earth"

    def __post_init__(self):

        for f in dataclasses.fields(self):
            if "kind" in f.metadata:
                object.__setattr__(self, f.name, check_value(f"controller option {f.name}", f, getattr(self, f.name)))
        for k, allowed in CHOICES.items():
            if getattr(self, k) not in allowed:
                raise InputError(f"controller option {k} = {getattr(self, k)!r}: not one of {', '.join(allowed)}")
        if not isinstance(self.friction_feedforward, bool):
            raise InputError(f"controller option friction_feedforward = {self.friction_feedforward!r}: "
                             f"not true or false")

    @property
    def dt(self) -> float:
        """Control interval 1/control_rate [s]."""
        return 1.0 / self.control_rate

    @property
    def du_max(self) -> float:
        """Largest change of the command per control interval [N]."""
        return self.rate_max / self.control_rate

    @classmethod
    def from_params(cls, params, **overrides) -> "ControllerConfig":
        """Limits and rate from ``params``' ``[active]`` table (or its defaults)."""
        a = active(params)
        kw = dict(u_max=a.u_max, rate_max=a.rate_max, control_rate=a.control_rate)
        names = {f.name for f in dataclasses.fields(cls)}
        for k in overrides:
            if k not in names:
                raise InputError(f"controller option {k!r}: unknown{did_you_mean(k, names)}")
            if k in kw and overrides[k] != kw[k]:  # the loop and the actuator read [active]: one source only
                raise InputError(f"controller option {k} = {overrides[k]!r}: set [active].{k} in the parameter "
                                 f"file instead (the actuator and the loop use it; now {kw[k]:g})")
        kw.update(overrides)
        return cls(**kw)


def parse_options(items) -> dict:
    """``["horizon=30", "model_frame=stroke", ...]`` -> typed :class:`ControllerConfig` overrides.

    One-line :class:`InputError` naming the option for a missing ``=``, an unknown name
    (with a suggestion) or a value of the wrong type.

    Parameters
    ----------
    items : iterable of str or None
        ``KEY=VALUE`` strings, each key a field of :class:`ControllerConfig` (None: none).

    Returns
    -------
    dict
        Field -> value converted to the field's type (bool, int, finite float or str).

    Raises
    ------
    heavecomp.errors.InputError
        A missing ``=``, an unknown key or a value of the wrong type.
    """
    types = {f.name: f.type for f in dataclasses.fields(ControllerConfig)}
    out = {}
    for item in items or ():
        key, sep, val = str(item).partition("=")
        key, val = key.strip(), val.strip()
        if not sep or not key:
            raise InputError(f"controller option {item!r}: expected KEY=VALUE", option="controller_option")
        if key not in types:
            raise InputError(f"controller option {key!r}: unknown{did_you_mean(key, types)}")
        kind = types[key]
        try:
            if kind == "bool":
                if val.lower() not in ("true", "false", "1", "0", "yes", "no"):
                    raise ValueError
                out[key] = val.lower() in ("true", "1", "yes")
            elif kind == "int":
                out[key] = int(val)
            elif kind == "float":
                out[key] = float(val)
                if not math.isfinite(out[key]):
                    raise ValueError
            else:
                out[key] = val
        except ValueError:
            raise InputError(f"controller option {key} = {val!r}: not a finite {kind}") from None
    return out


def limit(u_cmd: float, u_prev: float, cfg: ControllerConfig) -> float:
    """Clip a command to |u| <= u_max and |u - u_prev| <= rate_max dt [N].

    Parameters
    ----------
    u_cmd : float [N]
        The command asked for.
    u_prev : float [N]
        The command of the previous control interval.
    cfg : ControllerConfig
        ``u_max`` [N] and ``du_max`` [N per control interval].

    Returns
    -------
    float [N]
    """
    du = cfg.du_max
    u = min(max(u_cmd, u_prev - du), u_prev + du)
    return float(min(max(u, -cfg.u_max), cfg.u_max))


class Controller:
    """Base class: bookkeeping of solve times, failures and fallbacks.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        The plant's parameters.
    config : ControllerConfig or None
        Tuning and limits; None: ``ControllerConfig.from_params(params)``.
    """

    name = "base"

    def __init__(self, params, config: ControllerConfig | None = None):
        self.params = params
        self.config = config or ControllerConfig.from_params(params)
        self.reset()

    def reset(self) -> None:
        self.u_prev = 0.0
        self.stats = {"solver_failures": 0, "fallbacks": 0, "saturated_steps": 0}
        self.solve_times: list[float] = []

    def step(self, t: float, measurement: Measurement, preview=None) -> float:
        """Commanded active force [N] for the next control interval, as ``_step`` decided it.

        The command is not clipped here (the loop's actuator applies the limits);
        ``u_prev`` records the force the actuator will reach, ``limit(u, u_prev)``,
        which the MPCs' rate constraint starts from.
        """
        t0 = time.perf_counter()
        u = self._step(t, measurement, preview)
        if not math.isfinite(u):
            self.stats["fallbacks"] += 1
            u = self.u_prev
        u_lim = limit(u, self.u_prev, self.config)
        if abs(u_lim) >= self.config.u_max * (1 - 1e-9):
            self.stats["saturated_steps"] += 1
        self.u_prev = u_lim
        self.solve_times.append(time.perf_counter() - t0)
        return float(u)

    def _step(self, t, m, preview):  # pragma: no cover - abstract
        raise NotImplementedError


class PassiveController(Controller):
    """u = 0: the passive CMC."""

    name = "passive"

    def _step(self, t, m, preview):
        return 0.0


class PIDController(Controller):
    """PID on the WOB error, the baseline a rig would have.

    ``u = kp e + ki int(e) dt + kd de_f/dt`` with ``e = WOB - W_0`` (a WOB above
    the set-point lifts the top mass), derivative on a first-order filtered error
    (time constant ``pid_tf``), and conditional-integration anti-windup: the
    integral stops while the command is at a limit and the error pushes further.
    No heave preview, no friction model.
    """

    name = "pid"

    def reset(self):
        super().reset()
        self.integral = 0.0
        self.e_f = None

    def _step(self, t, m, preview):
        c = self.config
        e = m.wob - self.params.operating_point.wob_setpoint
        dt = c.dt
        if self.e_f is None:
            self.e_f = e
        a = dt / (c.pid_tf + dt)
        e_f_new = self.e_f + a * (e - self.e_f)
        de = (e_f_new - self.e_f) / dt
        self.e_f = e_f_new
        integral = self.integral + c.ki * e * dt
        u = c.kp * e + integral + c.kd * de
        u_lim = limit(u, self.u_prev, c)
        if u_lim == u or np.sign(e) != np.sign(u - u_lim):
            self.integral = integral  # conditional integration (anti-windup)
        return u_lim
