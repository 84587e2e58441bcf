"""Linear MPC (osqp) with friction as an estimated disturbance plus model feed-forward.

Prediction model: the frictionless CMC linearised at the operating point and
discretised (ZOH) at the control interval Ts, with the top mass in the earth
frame by default (:mod:`heavecomp.controllers.model`)::

    x_{k+1} = Ad x_k + Bu u_k + Bw w_k + Bf (f_k + d)

with w_k the predicted heave (online preview, :class:`HeavePredictor`), f_k the
friction model (paper A eq. 4/6/7, smoothed with width ``friction_eps``) at the
stroke velocity full compensation would need, v = -dz_h (the friction jumps at
every stroke reversal, which the preview sees coming), and d the Kalman
estimate of the friction the model misses (:class:`DisturbanceObserver`).  The friction
model is the law's and every seal-hook effect's the controller knows (``effects=``), all
smoothed with ``friction_eps`` (:class:`~heavecomp.controllers.model.ControllerFriction`); the
estimation is the one both MPCs hold (:class:`~heavecomp.controllers.predictive.StateEstimation`).

Condensed QP in the forces U = (u_0 .. u_{N-1}) [kN]::

    min  q_wob sum_k (W_k - W_0)^2 + r_u sum u_k^2 + r_du sum (u_k - u_{k-1})^2
    s.t. |u_k| <= u_max,  |u_k - u_{k-1}| <= rate_max Ts

The Hessian and constraint matrix are fixed: osqp is set up once and each step
only updates the linear term and the bounds (warm-started).  If osqp does not
return "solved", the previous plan shifted by one interval is used (counted in
``stats['solver_failures']`` and ``stats['fallbacks']``).
"""

from __future__ import annotations

import numpy as np

from heavecomp.controllers.predictive import KN, PredictiveController


class LinearMPC(PredictiveController):
    """Linear MPC on the WOB with osqp (see module docstring).

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        The plant's parameters (the model uses :func:`~heavecomp.controllers.model.controller_params`
        of them).
    config : ControllerConfig or None
        Horizon, weights, limits; None: ``ControllerConfig.from_params(params)``.
    effects : sequence
        Effects its model knows, as :class:`~heavecomp.controllers.predictive.PredictiveController`.
    """

    name = "linear-mpc"
    log_name = "linear MPC"

    def __init__(self, params, config=None, effects=None):
        import osqp
        import scipy.sparse as sp

        super().__init__(params, config, effects)
        config, m, N = self.config, self.model, self.N
        n = m.Ad.shape[0]
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

    def _bounds(self, u_prev_kN):
        N = self.N
        l = np.r_[-self._umax * np.ones(N), -self._dumax * np.ones(N)]
        u = np.r_[self._umax * np.ones(N), self._dumax * np.ones(N)]
        l[N] += u_prev_kN
        u[N] += u_prev_kN
        return l, u

    def _step(self, t, meas, preview):
        H, f = self.estimation.update(t, meas, preview)
        obs = self.estimation.observer
        m, N = self.model, self.N
        wbar = 0.5 * (H[:-1] + H[1:])                       # (N, 3) interval means
        fbar = 0.5 * (f[:-1] + f[1:]) + obs.d                # (N,)
        Wd = (wbar @ m.Bw.T + fbar[:, None] * m.Bf[:, 0][None, :]).ravel()
        e0 = self.Gx @ obs.x + self.Gd @ Wd + m.Dw[0] @ H[1:].T  # free WOB deviation [N]
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
        return self.fall_back(t, f"osqp status {status!r}")
