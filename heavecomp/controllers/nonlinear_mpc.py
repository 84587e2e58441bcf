"""Nonlinear MPC (casadi: SQP with qrqp, or ipopt) on the smooth-friction CMC, warm-started.

Prediction model: :func:`heavecomp.effects.model.casadi_model` (through
:func:`heavecomp.controllers.model.controller_model`: the top mass in the earth
frame by default) with the friction law of the parameter file (paper A eq. 4/6/7) regularised with width
``friction_eps`` (``sign(v) -> tanh(v/eps)``), integrated by RK4 with two
sub-steps per control interval (multiple shooting).  The heave over the horizon
is the online preview of :class:`~heavecomp.controllers.estimation.HeavePredictor`;
the initial state comes from the same Kalman observer as the linear MPC, and the
part of its disturbance estimate the smooth friction model does not explain is
added as a constant force over the horizon.  Both MPCs hold one
:class:`~heavecomp.controllers.predictive.StateEstimation` each (heave preview, friction
forecast, observer); this one builds no QP.  Every friction term of the model, the law's and
each seal-hook effect's the controller knows (``effects=``; stiction included), is smoothed
with ``friction_eps``.  The states of seal-hook effects (a friction memory) do not reach the
observer's frictionless linear model; they start each horizon where the previous solution put
them one interval on (at rest before the first solve and after a failed one).

NLP (N intervals, decision variables X_0..X_N, U_0..U_{N-1})::

    min  q_wob sum_k (W(X_k) - W_0)^2 + r_u sum U_k^2 + r_du sum (U_k - U_{k-1})^2
    s.t. X_0 = x_hat,  X_{k+1} = RK4(X_k, U_k, heave_k),  |U_k| <= u_max,
         |U_k - U_{k-1}| <= rate_max Ts

The NLP is built once (a casadi ``nlpsol`` with the horizon data as parameters)
and warm-started from the previous solution shifted by one interval (primal and
dual).  Solver (``ControllerConfig.nlp_solver``): ``"sqp"`` (default) —
casadi's ``sqpmethod`` with the exact Hessian and the active-set QP solver
``qrqp``, at most ``sqp_iterations`` (3) iterations per step (a real-time-iteration
scheme: from the shifted warm start it usually converges within them); or
``"ipopt"`` (interior point, up to 40 iterations).  A failed solve (an
exception, a status other than success / acceptable / iteration limit for SQP,
a non-finite iterate) falls back to the previous plan shifted (counted in
``solver_failures`` / ``fallbacks``).
"""

from __future__ import annotations

import numpy as np

from heavecomp.controllers.model import controller_model
from heavecomp.controllers.predictive import KN, PredictiveController
from heavecomp.plants.symbolic import casadi
from heavecomp.effects.model import initial_effect_states

#: ipopt return statuses accepted as a solution
_OK = ("Solve_Succeeded", "Solved_To_Acceptable_Level")



def rk4_steps(f, x, u, h, M):
    """``M`` classical RK4 steps of size ``h`` of the casadi model ``f(x, u) -> (xdot, y)``
    with ``u`` held: the MPC's discretisation (symbolic in, symbolic out).

    Parameters
    ----------
    f : casadi.Function
        The model ``f(x, u) -> (xdot, y)``.
    x : casadi.SX or casadi.MX
        State at the start of the interval [SI, model order].
    u : casadi.SX or casadi.MX
        Input held over the ``M`` steps [SI].
    h : float [s]
        Step size.
    M : int
        Number of steps.

    Returns
    -------
    casadi.SX or casadi.MX
        State after ``M h`` [SI].
    """
    for _ in range(M):
        k1 = f(x, u)[0]
        k2 = f(x + h / 2 * k1, u)[0]
        k3 = f(x + h / 2 * k2, u)[0]
        k4 = f(x + h * k3, u)[0]
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x

class NonlinearMPC(PredictiveController):
    """Nonlinear MPC with casadi (see module docstring).

    Holds the same estimation as the linear MPC (heave predictor, friction forecast, Kalman
    observer: :class:`~heavecomp.controllers.predictive.StateEstimation`), so the two
    controllers differ only in the prediction model and the solver.

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

    name = "nonlinear-mpc"
    log_name = "nonlinear MPC"
    substeps = 2

    def __init__(self, params, config=None, effects=None):
        super().__init__(params, config, effects)
        self._build()

    def _build(self):
        ca = casadi()
        cfg, N = self.config, self.N

        mp = self.cparams
        f = controller_model(mp, eps=cfg.friction_eps, frame=cfg.model_frame, effects=self.effects)
        self._f = f
        n = f.size1_in(0)  # 4 plant states, then the known effects' states
        self._x_op = np.r_[np.zeros(4), initial_effect_states(mp, self.effects)]  # operating point
        # the WOB reading the set-point gives: W_0 itself unless the controller knows a WOB channel
        # effect (g W + o), as the linear MPC's deviation from its y0
        W0 = float(f(self._x_op, np.zeros(4))[1][0])
        self.wob_target = W0
        Ts, M = cfg.dt, self.substeps
        h = Ts / M
        x = ca.SX.sym("x", n)
        uu = ca.SX.sym("u", 4)  # [z, dz, ddz, force]
        F = ca.Function("F", [x, uu], [rk4_steps(f, x, uu, h, M)])
        Y = ca.Function("Y", [x, uu], [f(x, uu)[1][0]])

        X = ca.SX.sym("X", n, N + 1)
        U = ca.SX.sym("U", N)              # kN
        P = ca.SX.sym("P", n + 3 * (N + 1) + 2)  # x0, heave (N+1 x 3), d [kN], u_prev [kN]
        x0 = P[0:n]
        H = ca.reshape(P[n:n + 3 * (N + 1)], 3, N + 1)
        d = P[-2]
        up = P[-1]
        g = [X[:, 0] - x0]
        J = 0
        qw = cfg.q_wob * KN ** 2
        ru = cfg.r_u * KN ** 2
        rdu = cfg.r_du * KN ** 2
        # state scaling for the defects (m and m/s are small): metres -> millimetres
        for k in range(N):
            hk = 0.5 * (H[:, k] + H[:, k + 1])
            uk = ca.vertcat(hk, (U[k] - d) * KN)
            g.append((X[:, k + 1] - F(X[:, k], uk)) * 1e3)
            wob = Y(X[:, k + 1], ca.vertcat(H[:, k + 1], 0))
            J += qw * ((wob - W0) / KN) ** 2 + ru * U[k] ** 2
            du = U[k] - (up if k == 0 else U[k - 1])
            J += rdu * du ** 2
            g.append(du)
        g[0] = g[0] * 1e3
        w = ca.vertcat(ca.vec(X), U)
        nlp = {"x": w, "f": J, "g": ca.vertcat(*g), "p": P}
        if cfg.nlp_solver == "ipopt":
            opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.max_iter": 40, "ipopt.tol": 1e-6,
                    "ipopt.acceptable_tol": 1e-3, "ipopt.acceptable_iter": 3,
                    "ipopt.warm_start_init_point": "yes", "ipopt.mu_init": 1e-3, "ipopt.sb": "yes"}
            self.solver = ca.nlpsol("nmpc", "ipopt", nlp, opts)
            self._ok = _OK
        else:  # "sqp": sequential QP (exact Hessian, casadi's active-set qrqp), a few warm iterations
            opts = {"qpsol": "qrqp", "qpsol_options": {"print_iter": False, "print_header": False,
                                                       "error_on_fail": False},
                    "max_iter": cfg.sqp_iterations, "print_header": False, "print_iteration": False,
                    "print_status": False, "print_time": False, "error_on_fail": False}
            self.solver = ca.nlpsol("nmpc", "sqpmethod", nlp, opts)
            # real-time iteration: the iterate after max_iter warm SQP steps is used
            # (input bounds and rate limits are linear, so every QP iterate satisfies them)
            # "Search_Direction_Becomes_Too_Small": the SQP step is negligible (converged/stalled)
            self._ok = _OK + ("Maximum_Iterations_Exceeded", "SOLVER_RET_LIMITED",
                              "Search_Direction_Becomes_Too_Small")
        nx = n * (N + 1)
        umax, dumax = cfg.u_max / KN, cfg.du_max / KN
        self._lbx = np.r_[-np.inf * np.ones(nx), -umax * np.ones(N)]
        self._ubx = np.r_[np.inf * np.ones(nx), umax * np.ones(N)]
        ng = n + N * (n + 1)
        lbg, ubg = np.zeros(ng), np.zeros(ng)
        for k in range(N):
            i = n + (n + 1) * k + n
            lbg[i], ubg[i] = -dumax, dumax
        self._lbg, self._ubg = lbg, ubg
        self._nx = nx
        self._w0 = None
        self._lam_x = None
        self._lam_g = None
        self._fric = ca.Function("fric", [x, uu], [f(x, uu)[1][4]])
        # seal-hook effect states: unseen by the observer's frictionless model, carried by this one
        self._carried = list(self.estimation.friction.seal_slots)

    def reset(self):
        super().reset()
        self._w0 = None
        self._x_next = None  # the model state one interval on, from the last solution

    def _step(self, t, meas, preview):
        est = self.estimation
        H, fff = est.update(t, meas, preview)
        N = self.N
        xh = est.observer.x + self._x_op
        if self._carried and self._x_next is not None:
            xh[self._carried] = self._x_next[self._carried]
        # the friction the observer attributes to the top mass minus what the smooth model predicts now
        f_model = float(self._fric(xh, np.r_[H[0], 0.0]))
        d_res = est.observer.d + float(fff[0]) - f_model
        # twice the static limit the controller believes (law and seal-hook effects)
        lim = 2.0 * est.friction.static_limit(meas.pressure, meas.stroke) + 5e3
        d_res = float(np.clip(d_res, -lim, lim))
        P = np.r_[xh, H.ravel(), d_res / KN, self.u_prev / KN]
        if self._w0 is None:
            X0 = np.tile(xh[:, None], (1, N + 1))
            w0 = np.r_[X0.ravel(order="F"), np.full(N, self.u_prev / KN)]
            args = {}
        else:
            w0 = self._w0
            args = {"lam_x0": self._lam_x, "lam_g0": self._lam_g}
        try:
            sol = self.solver(x0=w0, p=P, lbx=self._lbx, ubx=self._ubx, lbg=self._lbg, ubg=self._ubg, **args)
            status = self.solver.stats().get("return_status", "")
            wsol = np.array(sol["x"]).ravel()
            ok = status in self._ok and np.all(np.isfinite(wsol))
        except RuntimeError as exc:  # casadi raises on evaluation errors
            status, ok = f"error: {exc}", False
        if ok:
            Xs = wsol[:self._nx].reshape(-1, N + 1, order="F")
            Us = wsol[self._nx:]
            # warm start: shift the plan one interval
            Xn = np.hstack([Xs[:, 1:], Xs[:, -1:]])
            Un = np.r_[Us[1:], Us[-1]]
            self._w0 = np.r_[Xn.ravel(order="F"), Un]
            self._lam_x = np.array(sol["lam_x"]).ravel()
            self._lam_g = np.array(sol["lam_g"]).ravel()
            self._x_next = Xs[:, 1].copy()
            self.plan = Us * KN
            return float(self.plan[0])
        self._w0 = None
        self._x_next = None
        return self.fall_back(t, f"{self.config.nlp_solver} status {status!r}")
