"""The crown-block mounted compensator (CMC): equations, written once.

Reference structure: ``docs/contracts/parameter-file.md`` (paper A, section 4).
The functions below are scalar and use ``np.*`` only, so one source serves

- the compiled exact stick-slip stepper (:mod:`heavecomp.simulate._kernel`, numba),
- the symbolic model (:func:`casadi_model`) for linearisation, MPC and fitting,
- vectorised numpy evaluation (diagnosis, plots).

State ``x = [s, v, y_b, v_b]``: stroke, stroke velocity, lower-mass
displacement and velocity (from the operating point).  Heave input
``z_h, dz_h, ddz_h``.  Positive is up.

Equations (M_c top mass, m_b lower mass, y_c = z_h + s)::

    M_c (ddz_h + dv) = p A - F_f(v, p) - M_c g - T_ds + u
    m_b dv_b         = T_ds - m_b g + W
    p + p_atm        = (p_0 + p_atm) (V_0 / (V_0 + A s))^n
    T_ds = T_0 + k_ds (z_h + s - y_b) + c_ds (dz_h + v - v_b)
    W    = max(0, k_F (delta_0 - y_b) - c_F v_b)   if delta_0 - y_b > 0 else 0

``u`` is an optional active-cylinder force on the top mass (0 for the passive
system).  While the cylinder is stuck (v = 0, dv = 0) the friction equals the
holding force :func:`holding_force`, admissible while it is within the static
limit ``friction_jump(code, 0, p, FP)``.

Plant parameter vector ``PP`` (see :func:`plant_vector` for the layout).
"""

from __future__ import annotations

import numpy as np

from heavecomp.friction.laws import friction_cont, friction_jump, friction_smooth, FrictionLaw
from heavecomp.params.cmc import G as g, P_ATM
from heavecomp.plants.symbolic import casadi

# PP layout
A, MC, MB, PATM, P0ABS, V0, N, KDS, CDS, T0, KF, CF, D0, G = range(14)
PP_NAMES = ("A", "M_c", "m_b", "p_atm", "p0_abs", "V_0", "n", "k_ds", "c_ds", "T_0", "k_F", "c_F",
            "delta_0", "g")
STATE_NAMES = ("stroke", "stroke_velocity", "lower_displacement", "lower_velocity")


def plant_vector(params) -> np.ndarray:
    """Plant parameter vector PP from a :class:`heavecomp.params.CMCParams`."""
    c, ds, f, op = params.compensator, params.drill_string, params.formation, params.operating_point
    W0 = op.wob_setpoint
    return np.array([
        params.area, c.moving_mass, ds.lower_mass, P_ATM, params.p0 + P_ATM, params.gas_volume,
        c.polytropic_index, ds.stiffness, ds.damping, ds.lower_mass * g - W0, f.stiffness, f.damping,
        W0 / f.stiffness, g,
    ], dtype=float)


# ----------------------------------------------------------------------------
# the equations (scalar; numba- and casadi-compatible)
# ----------------------------------------------------------------------------
def gas_pressure(s, PP):
    """Cylinder gauge pressure p(s) [Pa]: polytropic gas, p + p_atm = (p_0+p_atm)(V_0/(V_0+A s))^n."""
    return PP[P0ABS] * (PP[V0] / (PP[V0] + PP[A] * s)) ** PP[N] - PP[PATM]


def tension(s, v, yb, vb, zh, dzh, PP):
    """Drill-string tension T_ds [N]."""
    return PP[T0] + PP[KDS] * (zh + s - yb) + PP[CDS] * (dzh + v - vb)


def contact_force(yb, vb, PP):
    """The formation's spring-damper force on the bit while in contact, unclamped [N]:
    ``k_F (delta_0 - y_b) - c_F v_b``."""
    return PP[KF] * (PP[D0] - yb) - PP[CF] * vb


def wob(yb, vb, PP):
    """Weight on bit W [N]: one-sided spring-damper contact with the formation."""
    pen = PP[D0] - yb
    return np.maximum(0.0, contact_force(yb, vb, PP)) * (pen > 0.0)


def contact_switch(yb, vb, PP):
    """Switching function of the bit-rock contact [N]: W > 0 exactly where it is > 0.

    ``min(k_F pen, k_F pen - c_F v_b)`` with ``pen = delta_0 - y_b``; its zero crossings
    (lift-off and touchdown) are where :func:`wob` has a kink or a jump, located as events
    by the stepper.
    """
    pen = PP[D0] - yb
    return np.minimum(PP[KF] * pen, PP[KF] * pen - PP[CF] * vb)


def holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP):
    """Net non-friction force on the top mass in the platform frame [N]:
    ``p A - M_c g - T_ds + u - M_c ddz_h``.  While stuck the friction equals it."""
    p = gas_pressure(s, PP)
    return p * PP[A] - PP[MC] * PP[G] - tension(s, v, yb, vb, zh, dzh, PP) + u - PP[MC] * ddzh


def lower_accel(s, v, yb, vb, zh, dzh, PP):
    """dv_b/dt of the lower mass [m/s^2]."""
    return (tension(s, v, yb, vb, zh, dzh, PP) - PP[MB] * PP[G] + wob(yb, vb, PP)) / PP[MB]


def lower_accel_contact(s, v, yb, vb, zh, dzh, contact, PP):
    """dv_b/dt with the contact state held (``contact`` = 1 on the rock, 0 lifted off) [m/s^2].

    Equal to :func:`lower_accel` wherever ``contact == (contact_switch > 0)``; the stepper
    holds the state through a step and flips it at the located lift-off / touchdown, so
    its RK4 stages never straddle the kink or the touchdown jump of W.
    """
    return (tension(s, v, yb, vb, zh, dzh, PP) - PP[MB] * PP[G] + contact * contact_force(yb, vb, PP)) / PP[MB]


def stroke_accel(s, v, yb, vb, zh, dzh, ddzh, u, Ff, PP):
    """dv/dt of the stroke for a given friction force ``Ff`` [m/s^2]."""
    return (holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP) - Ff) / PP[MC]


def sliding_friction(code, direction, s, v, FP, PP):
    """Friction while sliding in ``direction`` (+1/-1): J(direction v) direction + K(v) [N]."""
    p = gas_pressure(s, PP)
    return friction_jump(code, direction * v, p, FP) * direction + friction_cont(code, v, p, FP)


def static_limit(code, s, FP, PP):
    """Largest friction the cylinder can hold at v = 0 [N]."""
    return friction_jump(code, 0.0 * s, gas_pressure(s, PP), FP)


# ----------------------------------------------------------------------------
# symbolic model
# ----------------------------------------------------------------------------
def casadi_model(params, *, eps: float | None = None, sym: str = "SX"):
    """The CMC as a casadi Function ``f(x, u) -> (xdot, y)`` with smooth friction.

    Parameters
    ----------
    params : CMCParams
    eps : float, optional
        Regularisation width of the friction's sign [m/s]; required when the
        friction law has stiction (there is no smooth exact law).  Ignored for
        ``model = "none"``.
    sym : {"SX", "MX"}

    Returns
    -------
    casadi.Function
        Inputs ``x`` (4: s, v, y_b, v_b) and ``u`` (4: z_h, dz_h, ddz_h, u_active);
        outputs ``xdot`` (4) and ``y`` (5: wob, stroke, pressure, tension, friction).
    """
    ca = casadi()

    law = FrictionLaw.from_params(params.friction)
    if law.has_stiction and not (eps and eps > 0):
        raise ValueError("casadi_model: friction with stiction needs an explicit eps > 0 [m/s]")
    PP = plant_vector(params)
    S = getattr(ca, sym)
    x = S.sym("x", 4)
    u = S.sym("u", 4)
    s, v, yb, vb = x[0], x[1], x[2], x[3]
    zh, dzh, ddzh, ua = u[0], u[1], u[2], u[3]
    p = gas_pressure(s, PP)
    Ff = friction_smooth(law.code, v, p, law.FP, eps or 1.0)
    dv = stroke_accel(s, v, yb, vb, zh, dzh, ddzh, ua, Ff, PP)
    dvb = lower_accel(s, v, yb, vb, zh, dzh, PP)
    xdot = ca.vertcat(v, dv, vb, dvb)
    y = ca.vertcat(wob(yb, vb, PP), s, p, tension(s, v, yb, vb, zh, dzh, PP), Ff)
    return ca.Function("cmc", [x, u], [xdot, y], ["x", "u"], ["xdot", "y"])
