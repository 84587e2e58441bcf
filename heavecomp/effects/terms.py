"""Effect terms as scalar ``np.*`` functions (numba- and numpy-compatible).

Two families live here, deliberately with **different equations**:

* the *candidate* terms (``cand_*``) that the diagnosis fits, one per effect
  class in :mod:`heavecomp.effects.candidates`;
* the *truth* terms (``truth_*``) that the withheld-effect generator
  (:mod:`heavecomp.diagnosis.generator`) uses to make test runs.  A benchmark
  whose generator shared the candidate's equations would prove nothing.

All effects act through one effect-parameter vector ``EP`` (layout below; a
zero switches a term off).  The foundation stepper
(:func:`heavecomp.simulate._kernel.advance_fx`, wrapped for the diagnosis by
:mod:`heavecomp.diagnosis.stepper`) integrates the plant with these terms, so it is
compiled once for every combination; with ``EP = 0`` every term below reduces to the
nominal CMC of :mod:`heavecomp.plants.cmc` bit for bit (``tests/test_kernel_pins.py``),
which is how :func:`heavecomp.simulate.simulate` runs it.

Pairs (truth law -> fitted candidate law):

============================  ===========================================  =============================================
effect                        generator (truth)                            candidate (fitted)
============================  ===========================================  =============================================
friction_lag                  Stribeck curve evaluated at a first-order    asymmetric memory of the Stribeck *excess force*
                              lagged *speed* w, dw/dt = (|v| - w)/T_w      E, dE/dt = ((F_S-F_C) e^{-|v|/v_S} - E)/T,
                                                                           T = T_E rising, T_drop falling
dwell_stiction                dF (1 - exp(-tau/tau_d)), tau = dwell time   power law a tau^beta
pressure_friction             k max(p - p_th, 0) (energised seal)           dC_p |p| (linear in pressure)
gas_heat_transfer             thermal state theta = T/T_0, adiabatic        effective polytropic index n_eff plus a
                              gamma, Newton heat exchange, tau_th           linear loss c_g v in the pressure
flow_loss                     orifice, dp = K v|v| (turbulent)              laminar line, dp = R v
string_damping                quadratic drag c_q dv|dv| in the tension      linear dashpot c dv added to c_ds
sensor_delay                  first-order sensor lag (causal low-pass)      pure transport delay of one channel
============================  ===========================================  =============================================
"""

from __future__ import annotations

import numpy as np

from heavecomp.friction.laws import STRIBECK, friction_cont, friction_jump
from heavecomp.plants.cmc import A, G, MB, MC, contact_force, tension

# --------------------------------------------------------------------------
# EP layout (effect parameter vector)
# --------------------------------------------------------------------------
LAG_T_TRUTH = 0        # s      T_w, speed lag of the Stribeck curve (truth)
LAG_T_CAND = 1         # s      T_E, lag of the Stribeck excess force (candidate)
DWELL_DF_TRUTH = 2     # N      dF, saturating static-friction gain (truth)
DWELL_TAU_TRUTH = 3    # s      tau_d (truth)
DWELL_A_CAND = 4       # N/s^beta  a (candidate)
DWELL_BETA_CAND = 5    # -      beta (candidate)
PF_K_TRUTH = 6         # N/Pa   k (truth)
PF_PTH_TRUTH = 7       # Pa     p_th (truth)
PF_DCP_CAND = 8        # N/Pa   dC_p (candidate)
TH_GAMMA_TRUTH = 9     # -      gamma (truth; 0 = thermal model off)
TH_TAU_TRUTH = 10      # s      tau_th (truth)
GAS_N_CAND = 11        # -      n_eff (candidate; 0 = nominal n)
GAS_LOSS_CAND = 12     # Pa s/m c_g (candidate)
FLOW_K_TRUTH = 13      # Pa s^2/m^2  K (truth)
FLOW_R_CAND = 14       # Pa s/m R (candidate)
SD_CQ_TRUTH = 15       # N s^2/m^2  c_q (truth)
SD_C_CAND = 16         # N s/m  c (candidate)
LAG_TDOWN_CAND = 17    # s      T_drop, relaxation time while the excess falls (candidate)
N_EP = 18


def zero_ep() -> np.ndarray:
    """An effect-parameter vector with every effect switched off."""
    return np.zeros(N_EP)


# --------------------------------------------------------------------------
# gas and line
# --------------------------------------------------------------------------
def gas_pressure_fx(s, th, PP, EP):
    """Gas gauge pressure with the gas effects [Pa].

    Nominal (cmc-reference.md): p + p_atm = (p_0+p_atm)(V_0/(V_0+A s))^n.
    Candidate ``gas_heat_transfer``: the same with an effective index n_eff
    (EP[GAS_N_CAND] > 0).  Truth thermal model (EP[TH_GAMMA_TRUTH] > 0): ideal
    gas p_abs V = m R T, p_abs = (p_0+p_atm) theta V_0/(V_0 + A s).
    """
    ratio = PP[5] / (PP[5] + PP[0] * s)
    if EP[TH_GAMMA_TRUTH] > 0.0:
        return PP[4] * th * ratio - PP[3]
    n = EP[GAS_N_CAND] if EP[GAS_N_CAND] > 0.0 else PP[6]
    return PP[4] * ratio ** n - PP[3]


def truth_thermal_rate(s, v, th, PP, EP):
    """d theta/dt of the gas temperature ratio theta = T/T_0 (truth) [1/s].

    Ideal gas with adiabatic index gamma and Newton heat exchange with the
    vessel wall at T_0: dtheta/dt = -(gamma-1) theta A v/(V_0 + A s) + (1 - theta)/tau_th.
    """
    if EP[TH_GAMMA_TRUTH] <= 0.0:  # (the effect switches: branches on parameters only)
        return 0.0 * v
    tau = EP[TH_TAU_TRUTH] + (EP[TH_TAU_TRUTH] <= 0.0)
    return -(EP[TH_GAMMA_TRUTH] - 1.0) * th * PP[0] * v / (PP[5] + PP[0] * s) + (1.0 - th) / tau


def line_drop(v, EP):
    """Pressure drop cylinder -> gas, p_cyl = p_gas - line_drop [Pa].

    Truth ``flow_loss``: orifice K v|v|; candidate ``flow_loss``: laminar R v;
    candidate ``gas_heat_transfer``: its loss term c_g v.  Flow out of the
    cylinder (v < 0, plunger pushed in) raises the cylinder pressure.
    """
    return EP[FLOW_K_TRUTH] * v * np.abs(v) + (EP[FLOW_R_CAND] + EP[GAS_LOSS_CAND]) * v


# --------------------------------------------------------------------------
# friction
# --------------------------------------------------------------------------
def friction_magnitude_fx(a, p, w, el, FP, EP):
    """Sliding friction magnitude J (the part that jumps with sign v) [N].

    Paper A eq. 4, J = F_C + (F_S - F_C) e^{-a/v_S} + C_p |p|, with the effects:
    truth friction lag evaluates the Stribeck curve at the lagged speed ``w``;
    candidate friction lag replaces the Stribeck excess with the lagged force
    ``el``; pressure friction adds its term.
    """
    lag_t = EP[LAG_T_TRUTH] > 0.0
    lag_c = EP[LAG_T_CAND] > 0.0
    # a < 0 only in the stepper's trial steps past a reversal: held at its v = 0 value, as in
    # friction.laws.friction_jump
    speed = np.maximum(a, 0.0) * (1.0 - lag_t) + w * lag_t
    excess = (FP[0] - FP[1]) * np.exp(-speed / FP[2])
    excess = excess * (1.0 - lag_c) + el * lag_c
    return FP[1] + excess + FP[4] * np.abs(p) + pressure_friction_fx(p, EP)


def pressure_friction_fx(p, EP):
    """Extra seal friction from pressure [N]: truth k max(p - p_th, 0); candidate dC_p |p|."""
    return EP[PF_K_TRUTH] * np.maximum(p - EP[PF_PTH_TRUTH], 0.0) + EP[PF_DCP_CAND] * np.abs(p)


def dwell_gain(tau, EP):
    """Extra static friction after a dwell ``tau`` [s] at rest [N].

    Truth: dF (1 - exp(-tau/tau_d)) (saturating exponential, paper B's "static
    friction grows with the time at rest"); candidate: a tau^beta.
    """
    gain = 0.0 * tau
    if EP[DWELL_DF_TRUTH] != 0.0:
        td = EP[DWELL_TAU_TRUTH] + (EP[DWELL_TAU_TRUTH] <= 0.0)
        gain = gain + EP[DWELL_DF_TRUTH] * (1.0 - np.exp(-tau / td))
    if EP[DWELL_A_CAND] > 0.0:
        gain = gain + EP[DWELL_A_CAND] * np.maximum(tau, 1e-12) ** EP[DWELL_BETA_CAND]
    return gain


def lag_rates(v, w, el, FP, EP):
    """(dw/dt, dE/dt) of the friction memory states [m/s^2, N/s].

    Truth: dw/dt = (|v| - w)/T_w (the Stribeck curve sees a lagged speed).
    Candidate: the Stribeck excess force E relaxes towards its steady value with an
    asymmetric memory, dE/dt = ((F_S-F_C) e^{-|v|/v_S} - E)/T, T = T_E (recovery, target
    above E) or T_drop (target below E; T_drop = T_E when not set).
    """
    dw = 0.0 * v
    de = 0.0 * v
    if EP[LAG_T_TRUTH] > 0.0:
        dw = (np.abs(v) - w) / EP[LAG_T_TRUTH]
    if EP[LAG_T_CAND] > 0.0:
        te = EP[LAG_T_CAND]
        td = EP[LAG_TDOWN_CAND] + (EP[LAG_TDOWN_CAND] <= 0.0) * te
        target = (FP[0] - FP[1]) * np.exp(-np.abs(v) / FP[2])
        up = target > el
        de = (target - el) / (te * up + td * (1.0 - up))
    return dw, de


# --------------------------------------------------------------------------
# drill string
# --------------------------------------------------------------------------
def string_damping_fx(dv, EP):
    """Extra drill-string tension from damping [N]: truth c_q dv|dv|; candidate c dv.

    ``dv = dz_h + v - v_b`` is the relative velocity across the string.
    """
    return EP[SD_CQ_TRUTH] * dv * np.abs(dv) + EP[SD_C_CAND] * dv


# --------------------------------------------------------------------------
# the CMC with the effect terms (used by the stepper, heavecomp.simulate._kernel)
# --------------------------------------------------------------------------
def friction_jump_fx(code, a, p, w, el, FP, EP):
    """J with the effect terms [N]: :func:`friction_magnitude_fx` for paper A eq. 4, else the
    foundation law (:func:`heavecomp.friction.laws.friction_jump`) plus the pressure term."""
    if code == STRIBECK:
        return friction_magnitude_fx(a, p, w, el, FP, EP)
    return friction_jump(code, a, p, FP) + pressure_friction_fx(p, EP)


def sliding_friction_fx(code, direction, v, p, w, el, FP, EP):
    """Friction while sliding in ``direction`` (+1/-1): J(direction v) direction + K(v) [N]
    (:func:`heavecomp.plants.cmc.sliding_friction` with the effects)."""
    return friction_jump_fx(code, direction * v, p, w, el, FP, EP) * direction + friction_cont(code, v, p, FP)


def static_limit_fx(code, p, w, el, tau, FP, EP):
    """Largest friction the cylinder can hold at v = 0 after a dwell ``tau`` [s] [N]
    (:func:`heavecomp.plants.cmc.static_limit` with the effects)."""
    return friction_jump_fx(code, 0.0 * p, p, w, el, FP, EP) + dwell_gain(tau, EP)


def cylinder_pressure_fx(s, v, th, PP, EP):
    """Cylinder gauge pressure [Pa]: the gas pressure less the line drop."""
    return gas_pressure_fx(s, th, PP, EP) - line_drop(v, EP)


def plant_fx(s, v, yb, vb, th, zh, dzh, ddzh, u, contact, PP, EP):
    """The CMC forces with the effect terms: ``(p, T_ds, holding force, dv_b/dt)``.

    ``p`` is :func:`cylinder_pressure_fx`; ``T_ds`` the tension of
    :func:`heavecomp.plants.cmc.tension` plus :func:`string_damping_fx`; the holding
    force ``p A - M_c g - T_ds + u - M_c ddz_h`` and ``dv_b/dt`` with the contact state
    held (``contact`` = 1 on the rock, 0 lifted off) are
    :func:`heavecomp.plants.cmc.holding_force` and
    :func:`heavecomp.plants.cmc.lower_accel_contact` with that ``p`` and ``T_ds``
    (pinned to them at ``EP = 0``, bit for bit, by ``tests/test_kernel_pins.py``).
    The stroke acceleration is ``(holding force - F_f) / M_c``.
    """
    p = cylinder_pressure_fx(s, v, th, PP, EP)
    T = tension(s, v, yb, vb, zh, dzh, PP) + string_damping_fx(dzh + v - vb, EP)
    hold = p * PP[A] - PP[MC] * PP[G] - T + u - PP[MC] * ddzh
    dvb = (T - PP[MB] * PP[G] + contact * contact_force(yb, vb, PP)) / PP[MB]
    return p, T, hold, dvb


def adds_stiction(EP) -> bool:
    """True when an effect adds friction that jumps with sign(v) (pressure friction, dwell):
    the stepper must then treat even a smooth friction law as stick-slip."""
    return bool(EP[PF_K_TRUTH] != 0.0 or EP[PF_DCP_CAND] != 0.0 or EP[DWELL_DF_TRUTH] != 0.0
                or EP[DWELL_A_CAND] != 0.0)
