"""The crown-block mounted compensator (CMC): equations, written once.

Reference structure: ``docs/contracts/parameter-file.md`` (paper A, section 4).
The functions below are scalar and use ``np.*`` only, so one source serves

- the compiled exact stick-slip stepper (:mod:`heavecomp.simulate._kernel`, numba),
- (the symbolic model for linearisation, MPC and fitting, with effects at the hooks, is
  :func:`heavecomp.effects.model.casadi_model`),
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

from typing import NamedTuple

import numpy as np

from heavecomp.friction.laws import FrictionLaw, friction_cont, friction_jump
from heavecomp.params.cmc import G as g, P_ATM
from heavecomp.friction.laws import steepest_slope

#: PP layout: names in vector order; the index constants below are generated from it
PP_NAMES = ("A", "M_c", "m_b", "p_atm", "p0_abs", "V_0", "n", "k_ds", "c_ds", "T_0", "k_F", "c_F",
            "delta_0", "g")
A, MC, MB, PATM, P0ABS, V0, N, KDS, CDS, T0, KF, CF, D0, G = range(len(PP_NAMES))
STATE_NAMES = ("stroke", "stroke_velocity", "lower_displacement", "lower_velocity")


class PlantVectors(NamedTuple):
    """The CMC's parameters as the compiled kernel takes them: friction law code, friction
    vector FP (:data:`heavecomp.friction.laws.FP_NAMES`) and plant vector PP (:data:`PP_NAMES`)."""

    code: int
    FP: np.ndarray
    PP: np.ndarray
    has_stiction: bool


def plant_vectors(params) -> PlantVectors:
    """``(code, FP, PP, has_stiction)`` of a :class:`heavecomp.params.CMCParams` — the one
    params -> vectors conversion (simulate, closed loop, diagnosis, generator use it).

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    """
    law = FrictionLaw.from_params(params.friction)
    return PlantVectors(int(law.code), law.FP, plant_vector(params), bool(law.has_stiction))


def plant_vector(params) -> np.ndarray:
    """Plant parameter vector PP (layout :data:`PP_NAMES`) from a :class:`heavecomp.params.CMCParams`.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    """
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
    """Cylinder gauge pressure p(s) [Pa]: polytropic gas, p + p_atm = (p_0+p_atm)(V_0/(V_0+A s))^n.

    Parameters
    ----------
    s : float [m]
        Stroke (from the operating point, positive up).
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return PP[P0ABS] * (PP[V0] / (PP[V0] + PP[A] * s)) ** PP[N] - PP[PATM]


def tension(s, v, yb, vb, zh, dzh, PP):
    """Drill-string tension T_ds [N].

    Parameters
    ----------
    s : float [m]
        Stroke (from the operating point, positive up).
    v : float [m/s]
        Stroke velocity.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    zh : float [m]
        Heave z_h of the platform.
    dzh : float [m/s]
        Heave velocity.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return PP[T0] + PP[KDS] * (zh + s - yb) + PP[CDS] * (dzh + v - vb)


def contact_force(yb, vb, PP):
    """The formation's spring-damper force on the bit while in contact, unclamped [N]:
    ``k_F (delta_0 - y_b) - c_F v_b``.

    Parameters
    ----------
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return PP[KF] * (PP[D0] - yb) - PP[CF] * vb


def wob(yb, vb, PP):
    """Weight on bit W [N]: one-sided spring-damper contact with the formation.

    Parameters
    ----------
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    pen = PP[D0] - yb
    return np.maximum(0.0, contact_force(yb, vb, PP)) * (pen > 0.0)


def contact_switch(yb, vb, PP):
    """Switching function of the bit-rock contact [N]: W > 0 exactly where it is > 0.

    ``min(k_F pen, k_F pen - c_F v_b)`` with ``pen = delta_0 - y_b``; its zero crossings
    (lift-off and touchdown) are where :func:`wob` has a kink or a jump, located as events
    by the stepper.

    Parameters
    ----------
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    pen = PP[D0] - yb
    return np.minimum(PP[KF] * pen, PP[KF] * pen - PP[CF] * vb)


def net_force(p, T, ddzh, u, PP):
    """Net non-friction force on the top mass in the platform frame for a cylinder pressure ``p``
    and string tension ``T`` [N]: ``p A - M_c g - T_ds + u - M_c ddz_h``.

    Parameters
    ----------
    p : float [Pa]
        Cylinder gauge pressure.
    T : float [N]
        Drill-string tension T_ds.
    ddzh : float [m/s^2]
        Heave acceleration.
    u : float [N]
        Active-cylinder force on the top mass (0 for the passive system).
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return p * PP[A] - PP[MC] * PP[G] - T + u - PP[MC] * ddzh


def top_accel(hold, Ff, m_line, PP):
    """Stroke acceleration dv/dt [m/s^2] while sliding: the holding force less the seal friction over the
    moving mass, M_c plus ``m_line``, the mass a line's oil adds to the stroke (its inertance times A^2;
    0 for a lossless or a purely resistive line).

    Parameters
    ----------
    hold : float [N]
        Net non-friction force on the top mass (:func:`net_force`).
    Ff : float [N]
        Seal friction.
    m_line : float [kg]
        Mass of the line's oil as the stroke feels it.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return (hold - Ff) / (PP[MC] + m_line)


def cylinder_reading(p, m_line, a, PP):
    """The cylinder pressure a sensor reads [Pa]: the line's quasi-static pressure ``p`` less the inertial
    drop m a / A of the line's oil (``m_line`` [kg], accelerated with the stroke at ``a`` [m/s^2]).

    Parameters
    ----------
    p : float [Pa]
        Cylinder gauge pressure through the line's hooks, without the oil's inertia.
    m_line : float [kg]
        Mass of the line's oil as the stroke feels it.
    a : float [m/s^2]
        Stroke acceleration.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return p - m_line * a / PP[A]


def holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP):
    """Net non-friction force on the top mass in the platform frame [N]:
    :func:`net_force` of the gas pressure and the tension.  While stuck the friction equals it.

    Parameters
    ----------
    s : float [m]
        Stroke (from the operating point, positive up).
    v : float [m/s]
        Stroke velocity.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    zh : float [m]
        Heave z_h of the platform.
    dzh : float [m/s]
        Heave velocity.
    ddzh : float [m/s^2]
        Heave acceleration.
    u : float [N]
        Active-cylinder force on the top mass (0 for the passive system).
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return net_force(gas_pressure(s, PP), tension(s, v, yb, vb, zh, dzh, PP), ddzh, u, PP)


def lower_accel(s, v, yb, vb, zh, dzh, PP):
    """dv_b/dt of the lower mass [m/s^2].

    Parameters
    ----------
    s : float [m]
        Stroke (from the operating point, positive up).
    v : float [m/s]
        Stroke velocity.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    zh : float [m]
        Heave z_h of the platform.
    dzh : float [m/s]
        Heave velocity.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return lower_accel_wob(tension(s, v, yb, vb, zh, dzh, PP), yb, vb, PP)


def lower_accel_wob(T, yb, vb, PP):
    """dv_b/dt for a string tension ``T`` with the clamped contact law :func:`wob` [m/s^2].

    Parameters
    ----------
    T : float [N]
        Drill-string tension T_ds.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return (T - PP[MB] * PP[G] + wob(yb, vb, PP)) / PP[MB]


def lower_accel_contact(s, v, yb, vb, zh, dzh, contact, PP):
    """dv_b/dt with the contact state held (``contact`` = 1 on the rock, 0 lifted off) [m/s^2].

    Equal to :func:`lower_accel` wherever ``contact == (contact_switch > 0)``; the stepper
    holds the state through a step and flips it at the located lift-off / touchdown, so
    its RK4 stages never straddle the kink or the touchdown jump of W.

    Parameters
    ----------
    s : float [m]
        Stroke (from the operating point, positive up).
    v : float [m/s]
        Stroke velocity.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    zh : float [m]
        Heave z_h of the platform.
    dzh : float [m/s]
        Heave velocity.
    contact : float
        Contact state held through the step: 1 on the rock, 0 lifted off.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return lower_accel_tension(tension(s, v, yb, vb, zh, dzh, PP), yb, vb, contact, PP)


def lower_accel_tension(T, yb, vb, contact, PP):
    """dv_b/dt for a string tension ``T`` with the contact state held [m/s^2]:
    ``(T - m_b g + contact k_F (delta_0 - y_b) - c_F v_b) / m_b``.

    Parameters
    ----------
    T : float [N]
        Drill-string tension T_ds.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    contact : float
        Contact state held through the step: 1 on the rock, 0 lifted off.
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return (T - PP[MB] * PP[G] + contact * contact_force(yb, vb, PP)) / PP[MB]


def stroke_accel(s, v, yb, vb, zh, dzh, ddzh, u, Ff, PP):
    """dv/dt of the stroke for a given friction force ``Ff`` [m/s^2].

    Parameters
    ----------
    s : float [m]
        Stroke (from the operating point, positive up).
    v : float [m/s]
        Stroke velocity.
    yb : float [m]
        Lower-mass displacement y_b from the operating point.
    vb : float [m/s]
        Lower-mass velocity v_b.
    zh : float [m]
        Heave z_h of the platform.
    dzh : float [m/s]
        Heave velocity.
    ddzh : float [m/s^2]
        Heave acceleration.
    u : float [N]
        Active-cylinder force on the top mass (0 for the passive system).
    Ff : float [N]
        Friction force on the top mass (opposing ``v`` while sliding).
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return (holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP) - Ff) / PP[MC]


def sliding_friction(code, direction, s, v, FP, PP):
    """Friction while sliding in ``direction`` (+1/-1): J(direction v) direction + K(v) [N].

    Parameters
    ----------
    code : int
        Friction law code (:mod:`heavecomp.friction.laws`: eq. 4, 6 or 7 of paper A, or none).
    direction : float
        Sliding direction, +1 or -1 [-].
    s : float [m]
        Stroke (from the operating point, positive up).
    v : float [m/s]
        Stroke velocity.
    FP : (6,) array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]`` [N, N, m/s, N s/m, N/Pa, m/s].
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    p = gas_pressure(s, PP)
    return friction_jump(code, direction * v, p, FP) * direction + friction_cont(code, v, p, FP)


def static_limit(code, s, FP, PP):
    """Largest friction the cylinder can hold at v = 0 [N].

    Parameters
    ----------
    code : int
        Friction law code (:mod:`heavecomp.friction.laws`: eq. 4, 6 or 7 of paper A, or none).
    s : float [m]
        Stroke (sets the gas pressure the pressure term C_p |p| acts on).
    FP : (6,) array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]`` [N, N, m/s, N s/m, N/Pa, m/s].
    PP : (14,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:func:`plant_vector`).
    """
    return friction_jump(code, 0.0 * s, gas_pressure(s, PP), FP)


# ----------------------------------------------------------------------------
# the linear model (eigenvalues, default step sizes, band edges)
# ----------------------------------------------------------------------------
def modal_matrices(params, friction_slope: float = 0.0):
    """Mass, damping and stiffness matrices ``(M, C, K)`` of the CMC linearised at the operating
    point, coordinates (top-mass stroke, lower-mass displacement), the bit on the rock [SI].

    ``K = [[k_gas + k_ds, -k_ds], [-k_ds, k_ds + k_F]]``,
    ``C = [[c_ds + slope, -c_ds], [-c_ds, c_ds + c_F]]``, ``M = diag(M_c, m_b)``, with
    ``slope`` a friction slope dF_f/dv [N s/m] added on the stroke.  The one linear model the
    default step (:func:`eigen_rate`) and the diagnosis' band edges (:func:`eigenfrequencies`) are
    derived from; ``tests/test_conformance.py`` pins it to the jacobian of :func:`heavecomp.effects.model.casadi_model`.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    friction_slope : float [N s/m]
        Friction slope dF_f/dv added to the stroke's damping (0: frictionless).
    """
    c, ds, fo = params.compensator, params.drill_string, params.formation
    K = np.array([[c.gas_stiffness + ds.stiffness, -ds.stiffness], [-ds.stiffness, ds.stiffness + fo.stiffness]])
    C = np.array([[ds.damping + friction_slope, -ds.damping], [-ds.damping, ds.damping + fo.damping]])
    M = np.diag([c.moving_mass, ds.lower_mass])
    return M, C, K


def eigen_rate(params) -> float:
    """Largest |eigenvalue| [1/s] of the linear model (stroke stuck or free), including the
    steepest friction slope near v = 0 (:func:`heavecomp.friction.laws.steepest_slope`).

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    """

    plant = plant_vectors(params)
    M, C, K = modal_matrices(params, steepest_slope(plant.code, plant.FP))
    Minv = np.diag([1 / M[0, 0], 1 / M[1, 1]])
    Asys = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ C]])
    lam = np.abs(np.linalg.eigvals(Asys)).max()
    ds, fo = params.drill_string, params.formation
    return float(max(lam, np.sqrt((ds.stiffness + fo.stiffness) / M[1, 1]), (ds.damping + fo.damping) / M[1, 1]))


def eigenfrequencies(params) -> list[float]:
    """Undamped eigenfrequencies [Hz] of the linear model: sliding (2 DOF: top mass on the gas
    spring, lower mass on string and formation) and stuck (lower mass on k_ds + k_F).

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    """
    M, C, K = modal_matrices(params)
    lam = np.linalg.eigvals(np.linalg.solve(M, K)).real
    f = sorted(float(np.sqrt(max(x, 0.0)) / (2 * np.pi)) for x in lam)
    f.append(float(np.sqrt(K[1, 1] / M[1, 1]) / (2 * np.pi)))
    return f
