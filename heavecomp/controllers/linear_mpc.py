"""Linear MPC (osqp) with friction as an estimated disturbance plus model feed-forward.

Prediction model: the frictionless CMC linearised at the operating point and
discretised (ZOH) at the control interval Ts, with the top mass in the earth
frame by default (:mod:`heavecomp.controllers.model`)::

    x_{k+1} = Ad x_k + Bu u_k + Bw w_k + Bf (f_k + d)

with w_k the predicted heave (online preview, :class:`HeavePredictor`), f_k the
friction model (paper A eq. 4/6/7, smoothed with width ``friction_eps``) at the
stroke velocity full compensation would need, v = -dz_h (the friction jumps at
every stroke reversal, which the preview sees coming), and d the Kalman
estimate of the friction the model misses (:class:`DisturbanceObserver`).

Condensed QP in the forces U = (u_0 .. u_{N-1}) [kN]::

    min  q_wob sum_k (W_k - W_0)^2 + r_u sum u_k^2 + r_du sum (u_k - u_{k-1})^2
    s.t. |u_k| <= u_max,  |u_k - u_{k-1}| <= rate_max Ts

The Hessian and constraint matrix are fixed: osqp is set up once and each step
only updates the linear term and the bounds (warm-started).  If osqp does not
return "solved", the previous plan shifted by one interval is used (counted in
``stats['solver_failures']`` and ``stats['fallbacks']``).
"""

from __future__ import annotations

import logging

import numpy as np

from heavecomp.controllers.base import Controller, ControllerConfig
from heavecomp.controllers.estimation import DisturbanceObserver, HeavePredictor
from heavecomp.controllers.model import controller_params, discrete_model
from heavecomp.friction.laws import FrictionLaw
from heavecomp.effects.spec import effects_for

log = logging.getLogger(__name__)
KN = 1e3


def controller_friction(cparams):
    """The friction law the controller believes (of :func:`controller_params`: forces scaled)."""

    return FrictionLaw.from_params(cparams.friction)


class LinearMPC(Controller):
    """Linear MPC on the WOB with osqp (see module docstring)."""

    name = "linear-mpc"

    def __init__(self, params, config=None, effects=None):
        import osqp
        import scipy.sparse as sp

        config = config or ControllerConfig.from_params(params)
        self.params, self.config = params, config
        self.cparams = controller_params(params, config)

        self.effects = effects_for(params, effects)  # None: the file's [[effects]]; effects at the plant's hooks the controller's model knows
        self.model = m = discrete_model(self.cparams, config.dt, config.model_frame, self.effects)
        self.law = controller_friction(self.cparams)
        N, n = config.horizon, m.Ad.shape[0]
        self.N = N
        # condensed prediction x_k (k = 1..N) = Sx x0 + Su U + Sd Wd
        Apow = [np.eye(n)]
        for _ in range(N):
            Apow.append(m.Ad @ Apow[-1])
        Cw = m.C[0]
        self.Gx = np.array([Cw @ Apow[k] for k in range(1, N + 1)])  # (N, n)
        Gu = np.zeros((N, N))
        Gd = np.zeros((N, N * n))
        for k in range(1, N + 1):
            for j in range(k):
                Gu[k - 1, j] = Cw @ Apow[k - 1 - j] @ m.Bu[:, 0]
                Gd[k - 1, j * n:(j + 1) * n] = Cw @ Apow[k - 1 - j]
        # decision variables and WOB errors both in kN: Gu [N/N] is unchanged
        self.Gu, self.Gd = Gu, Gd
        qw = config.q_wob * KN ** 2       # per kN^2 of WOB error
        ru = config.r_u * KN ** 2
        rdu = config.r_du * KN ** 2
        D = np.eye(N) - np.eye(N, k=-1)
        self.qw, self.rdu = qw, rdu
        P = 2.0 * (qw * Gu.T @ Gu + ru * np.eye(N) + rdu * D.T @ D)
        Acon = np.vstack([np.eye(N), D])
        self._umax = config.u_max / KN
        self._dumax = config.du_max / KN
        l0, u0 = self._bounds(0.0)
        self.solver = osqp.OSQP()
        self.solver.setup(sp.csc_matrix(np.triu(P)), np.zeros(N), sp.csc_matrix(Acon), l0, u0,
                          verbose=False, warm_starting=True, polishing=False, eps_abs=1e-4, eps_rel=1e-4,
                          max_iter=4000)
        self.predictor = HeavePredictor(config.dt, config.predictor_order, config.predictor_window,
                                        horizon=max(config.horizon, 40))
        self.observer = DisturbanceObserver(m, sigma_d=config.observer_sigma_d)
        super().__init__(params, config)

    def _bounds(self, u_prev_kN):
        N = self.N
        l = np.r_[-self._umax * np.ones(N), -self._dumax * np.ones(N)]
        u = np.r_[self._umax * np.ones(N), self._dumax * np.ones(N)]
        l[N] += u_prev_kN
        u[N] += u_prev_kN
        return l, u

    def reset(self):
        super().reset()
        if hasattr(self, "predictor"):
            self.predictor.reset()
            self.observer.reset()
        self.plan = None
        self._last = None  # (u_applied, w, f_ff) for the observer's time update
        self.last_preview = None

    def friction_ff(self, dz: np.ndarray, p: float) -> np.ndarray:
        """Friction model force at v = -dz_h [N] (zero when feed-forward is off)."""
        if not self.config.friction_feedforward:
            return np.zeros_like(dz)
        return self.law.smooth(-dz, p, eps=self.config.friction_eps)

    def _estimate(self, t, meas, preview):
        """Heave trajectory (N+1, 3), friction forecast (N+1,), observer update."""
        self.predictor.update(t, meas.heave)
        H = self.predictor.trajectory(t, self.N) if preview is None else np.asarray(preview, dtype=float)
        self.last_preview = (t, H[:, 0].copy())
        f = self.friction_ff(H[:, 1], meas.pressure)
        w_now = H[0]
        if self._last is not None:
            u_prev, w_prev, f_prev = self._last
            u_avg = 0.5 * (u_prev + meas.u_active)
            self.observer.predict(u_avg, 0.5 * (w_prev + w_now), 0.5 * (f_prev + f[0]))
        self.observer.correct(np.array([meas.wob, meas.stroke, meas.pressure]), w_now)
        return H, f

    def _step(self, t, meas, preview):
        H, f = self._estimate(t, meas, preview)
        self._last = (meas.u_active, H[0].copy(), float(f[0]))
        m, N = self.model, self.N
        wbar = 0.5 * (H[:-1] + H[1:])                       # (N, 3) interval means
        fbar = 0.5 * (f[:-1] + f[1:]) + self.observer.d      # (N,)
        Wd = (wbar @ m.Bw.T + fbar[:, None] * m.Bf[:, 0][None, :]).ravel()
        e0 = self.Gx @ self.observer.x + self.Gd @ Wd + m.Dw[0] @ H[1:].T  # free WOB deviation [N]
        e0_kN = e0 / KN
        u_prev = self.u_prev / KN
        q = 2.0 * self.qw * self.Gu.T @ e0_kN
        q[0] -= 2.0 * self.rdu * u_prev
        l, u = self._bounds(u_prev)
        self.solver.update(q=q, l=l, u=u)
        res = self.solver.solve(raise_error=False)
        status = str(getattr(res.info, "status", "")).lower()
        if status == "solved" and np.all(np.isfinite(res.x)):
            self.plan = res.x * KN
            return float(self.plan[0])
        self.stats["solver_failures"] += 1
        self.stats["fallbacks"] += 1
        (log.warning if self.stats["solver_failures"] <= 5 else log.debug)(
            "linear MPC: osqp status %r at t = %.2f s; using the shifted previous plan", status, t)
        if self.plan is not None and self.plan.size > 1:
            self.plan = np.r_[self.plan[1:], self.plan[-1]]
            return float(self.plan[0])
        return self.u_prev
