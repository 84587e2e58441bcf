"""What the two MPCs share: one estimation component (held, not inherited) and the bookkeeping.

:class:`StateEstimation` is what an MPC knows of the plant at a control instant, from what a rig
measures: the heave over the horizon (:class:`~heavecomp.controllers.estimation.HeavePredictor`),
the friction forecast (:class:`~heavecomp.controllers.model.ControllerFriction`: the friction law
and the seal-hook effects the controller knows, smoothed with ``friction_eps``) and the state and
force-disturbance estimate of the Kalman observer
(:class:`~heavecomp.controllers.estimation.DisturbanceObserver`) on the discrete linear model
(:func:`~heavecomp.controllers.model.discrete_model`).  The linear MPC (osqp) and the nonlinear
MPC (casadi) each hold one; neither derives from the other, so the nonlinear MPC builds no QP.

:class:`PredictiveController` is the base both MPCs derive from: the controller's parameters and
effects, its estimation, the plan and the fall-back to the previous plan shifted.
"""

from __future__ import annotations

import logging

import numpy as np

from heavecomp.controllers.base import Controller, ControllerConfig
from heavecomp.controllers.estimation import DisturbanceObserver, HeavePredictor
from heavecomp.controllers.model import ControllerFriction, controller_params, discrete_model
from heavecomp.effects.spec import effects_for

#: newtons per kilonewton (the MPCs' decision variables are in kN)
KN = 1e3


class StateEstimation:
    """Heave preview, friction forecast and observer of one MPC (module docstring).

    Parameters
    ----------
    cparams : CMCParams
        The parameters the controller believes (:func:`~heavecomp.controllers.model.controller_params`).
    config : ControllerConfig
    effects : sequence of Effect
        Effects the controller knows (resolved instances).

    Attributes
    ----------
    model : DiscreteModel
        The observer's (and the linear MPC's) discrete linear model, without seal friction.
    friction : ControllerFriction
        The seal friction the controller believes, smoothed with ``config.friction_eps``.
    predictor : HeavePredictor
    observer : DisturbanceObserver
    last_preview : (float, ndarray) or None
        Time [s] and predicted heave [m] over the horizon of the last update.
    """

    def __init__(self, cparams, config: ControllerConfig, effects=()):
        self.config = config
        self.N = config.horizon
        self.model = discrete_model(cparams, config.dt, config.model_frame, effects)
        self.friction = ControllerFriction(cparams, config.friction_eps, effects)
        self.predictor = HeavePredictor(config.dt, config.predictor_order, config.predictor_window,
                                        horizon=max(config.horizon, 40))
        self.observer = DisturbanceObserver(self.model, sigma_d=config.observer_sigma_d)
        self.reset()

    def reset(self) -> None:
        """Forget the heave history, the observer's estimate and the last interval."""
        self.predictor.reset()
        self.observer.reset()
        self._last = None  # (u_applied, w, f_ff) for the observer's time update
        self.last_preview = None

    def friction_ff(self, dz: np.ndarray, p: float, s=0.0) -> np.ndarray:
        """Friction forecast at the stroke velocity full compensation needs, v = -dz_h [N]
        (pressure ``p`` [Pa], stroke ``s`` [m]); zero when feed-forward is off."""
        if not self.config.friction_feedforward:
            return np.zeros_like(dz)
        return self.friction.force(-dz, p, s)

    def update(self, t: float, meas, preview) -> tuple:
        """One control instant: the heave trajectory H (N+1, 3) [m, m/s, m/s^2] (``preview`` if
        given, else predicted), the friction forecast f (N+1,) [N] along it, and the observer's
        time update over the last interval and measurement update now.

        Under full compensation the top mass stays put in the earth frame, so the stroke over the
        horizon is the measured one minus the heave still to come (``s_k = s + z_0 - z_k``)."""
        self.predictor.update(t, meas.heave)
        H = self.predictor.trajectory(t, self.N) if preview is None else np.asarray(preview, dtype=float)
        self.last_preview = (t, H[:, 0].copy())
        f = self.friction_ff(H[:, 1], meas.pressure, meas.stroke + H[0, 0] - H[:, 0])
        w_now = H[0]
        if self._last is not None:
            u_prev, w_prev, f_prev = self._last
            u_avg = 0.5 * (u_prev + meas.u_active)
            self.observer.predict(u_avg, 0.5 * (w_prev + w_now), 0.5 * (f_prev + f[0]))
        self.observer.correct(np.array([meas.wob, meas.stroke, meas.pressure]), w_now)
        self._last = (meas.u_active, H[0].copy(), float(f[0]))
        return H, f


class PredictiveController(Controller):
    """Base of the MPCs: ``cparams``, ``effects``, ``estimation`` and the plan (module docstring).

    Parameters
    ----------
    params : CMCParams
    config : ControllerConfig, optional
    effects : sequence, optional
        Effects the controller's model knows (:mod:`heavecomp.effects`: instances, names or
        ``(name, values)``; None: the plant effects of the parameter file's ``[[effects]]``).  Every
        registered plant effect is taken; a channel or heave effect
        with a delay, a drift or a vessel angle has no finite-state, time-invariant model and is
        refused here, before any run, with a one-line ParameterError naming it.
    """

    #: the controller in the fall-back log line
    log_name = "MPC"

    def __init__(self, params, config=None, effects=None):
        config = config or ControllerConfig.from_params(params)
        self.params, self.config = params, config
        self.cparams = controller_params(params, config)
        # effects at the plant's hooks the controller's model knows (None: the parameter file's plant effects)
        self.effects = effects_for(params, effects)
        self.estimation = StateEstimation(self.cparams, config, self.effects)
        self.model = self.estimation.model
        self.N = config.horizon
        super().__init__(params, config)

    @property
    def last_preview(self):
        """Time [s] and predicted heave [m] over the horizon of the last step (the loop's preview error)."""
        return self.estimation.last_preview

    def reset(self):
        super().reset()
        self.estimation.reset()
        self.plan = None

    def fall_back(self, t: float, why: str) -> float:
        """The previous plan shifted by one interval after a failed solve (``why``, logged; counted in
        ``solver_failures`` and ``fallbacks``) [N]; the last command when there is no plan."""
        self.stats["solver_failures"] += 1
        self.stats["fallbacks"] += 1
        log = logging.getLogger(type(self).__module__)
        (log.warning if self.stats["solver_failures"] <= 5 else log.debug)(
            "%s: %s at t = %.2f s; using the shifted previous plan", self.log_name, why, t)
        if self.plan is not None and self.plan.size > 1:
            self.plan = np.r_[self.plan[1:], self.plan[-1]]
            return float(self.plan[0])
        return self.u_prev
