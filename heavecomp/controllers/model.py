"""The controller's discrete linear model, from the plant's casadi jacobians.

No plant equation is restated: :func:`heavecomp.plants.cmc.casadi_model`
(friction ``none``; the friction is a force input handled as a disturbance) is
differentiated at the operating point (x = 0, heave 0, u = 0) and discretised
exactly for piecewise-constant inputs (zero-order hold) with the control
interval Ts.

Continuous model (deviations from the operating point)::

    dx/dt = A x + B_u u + B_w w + B_f f,     w = [z_h, dz_h, ddz_h],  f = friction force
    y     = C x + D_w w                       y = [wob, stroke, pressure]

f enters like ``-u`` (friction opposes the top mass's stroke, cmc.stroke_accel).
"""

from __future__ import annotations

import dataclasses

import numpy as np

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
    """The parameters the controller *believes* (gas stiffness scaled for robustness studies)."""
    if config.gas_stiffness_scale != 1.0:
        return params.replace(compensator={"gas_stiffness": params.compensator.gas_stiffness
                                           * config.gas_stiffness_scale})
    return params


def discrete_model(params, Ts: float) -> DiscreteModel:
    """Linearise the frictionless CMC at the operating point and discretise (ZOH).

    Parameters
    ----------
    params : CMCParams
    Ts : float [s]
        Control interval.
    """
    from scipy.linalg import expm

    from heavecomp.plants.cmc import casadi_model
    from heavecomp.plants.symbolic import casadi

    ca = casadi()
    f = casadi_model(params.replace(friction={"model": "none"}))
    x = ca.SX.sym("x", 4)
    u = ca.SX.sym("u", 4)
    xdot, y = f(x, u)
    J = ca.Function("J", [x, u], [ca.jacobian(xdot, x), ca.jacobian(xdot, u), ca.jacobian(y, x), ca.jacobian(y, u)])
    x0, u0 = np.zeros(4), np.zeros(4)
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
