"""Effect terms as scalar ``np.*`` functions (numba- and numpy-compatible).

Two families live here, deliberately with **different equations**:

* the *candidate* terms (``cand_*``) that the diagnosis fits, one per effect
  class in :mod:`heavecomp.effects.candidates`;
* the *truth* terms (``truth_*``) that the withheld-effect generator
  (:mod:`heavecomp.diagnosis.generator`) uses to make test runs.  A benchmark
  whose generator shared the candidate's equations would prove nothing.

All effects act through one effect-parameter vector ``EP`` (layout below; a
zero switches a term off), so the effect-aware stepper
(:mod:`heavecomp.diagnosis.stepper`) is compiled once for every combination.

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
    n = PP[6] + (EP[GAS_N_CAND] - PP[6]) * (EP[GAS_N_CAND] > 0.0)
    poly = PP[4] * ratio ** n
    therm = PP[4] * th * ratio
    use_th = EP[TH_GAMMA_TRUTH] > 0.0
    return poly * (1.0 - use_th) + therm * use_th - PP[3]


def truth_thermal_rate(s, v, th, PP, EP):
    """d theta/dt of the gas temperature ratio theta = T/T_0 (truth) [1/s].

    Ideal gas with adiabatic index gamma and Newton heat exchange with the
    vessel wall at T_0: dtheta/dt = -(gamma-1) theta A v/(V_0 + A s) + (1 - theta)/tau_th.
    """
    on = EP[TH_GAMMA_TRUTH] > 0.0
    tau = EP[TH_TAU_TRUTH] + (EP[TH_TAU_TRUTH] <= 0.0)
    return on * (-(EP[TH_GAMMA_TRUTH] - 1.0) * th * PP[0] * v / (PP[5] + PP[0] * s) + (1.0 - th) / tau)


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
    speed = a * (1.0 - lag_t) + w * lag_t
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
    td = EP[DWELL_TAU_TRUTH] + (EP[DWELL_TAU_TRUTH] <= 0.0)
    truth = EP[DWELL_DF_TRUTH] * (1.0 - np.exp(-tau / td))
    cand = EP[DWELL_A_CAND] * np.maximum(tau, 1e-12) ** EP[DWELL_BETA_CAND] * (EP[DWELL_A_CAND] > 0.0)
    return truth + cand


def lag_rates(v, w, el, FP, EP):
    """(dw/dt, dE/dt) of the friction memory states [m/s^2, N/s].

    Truth: dw/dt = (|v| - w)/T_w (the Stribeck curve sees a lagged speed).
    Candidate: the Stribeck excess force E relaxes towards its steady value with an
    asymmetric memory, dE/dt = ((F_S-F_C) e^{-|v|/v_S} - E)/T, T = T_E (recovery, target
    above E) or T_drop (target below E; T_drop = T_E when not set).
    """
    tw = EP[LAG_T_TRUTH] + (EP[LAG_T_TRUTH] <= 0.0)
    te = EP[LAG_T_CAND] + (EP[LAG_T_CAND] <= 0.0)
    td = EP[LAG_TDOWN_CAND] + (EP[LAG_TDOWN_CAND] <= 0.0) * te
    dw = (np.abs(v) - w) / tw * (EP[LAG_T_TRUTH] > 0.0)
    target = (FP[0] - FP[1]) * np.exp(-np.abs(v) / FP[2])
    up = target > el
    de = (target - el) / (te * up + td * (1.0 - up)) * (EP[LAG_T_CAND] > 0.0)
    return dw, de


# --------------------------------------------------------------------------
# drill string
# --------------------------------------------------------------------------
def string_damping_fx(dv, EP):
    """Extra drill-string tension from damping [N]: truth c_q dv|dv|; candidate c dv.

    ``dv = dz_h + v - v_b`` is the relative velocity across the string.
    """
    return EP[SD_CQ_TRUTH] * dv * np.abs(dv) + EP[SD_C_CAND] * dv
