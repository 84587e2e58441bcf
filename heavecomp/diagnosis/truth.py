"""The withheld-effect benchmark's truth laws: the generator's own effect classes.

They plug into the plant's hooks through the same mechanism as the library's effects
(:mod:`heavecomp.effects.base`), but they are **not** registered and share no equation with the
candidates the diagnosis fits (:mod:`heavecomp.effects`): a benchmark whose generator used the
candidates' equations would prove nothing.  ``tests/test_effects.py`` checks that each truth law
differs from its candidate.

============================  ===========================================  =============================================
effect                        truth law (here)                             candidate (fitted, heavecomp.effects)
============================  ===========================================  =============================================
friction_lag                  Stribeck curve evaluated at a first-order    asymmetric memory of the Stribeck *excess force*
                              lagged *speed* w, dw/dt = (|v| - w)/T_w
dwell_stiction                dF (1 - exp(-tau/tau_d)), tau = dwell time   power law a tau^beta
pressure_friction             k max(p - p_th, 0) (energised seal)           dC_p |p| (linear in pressure)
gas_heat_transfer             thermal state theta = T/T_0, adiabatic        effective polytropic index n_eff plus a
                              gamma, Newton heat exchange, tau_th           linear loss c_g v
flow_loss                     orifice, dp = K v|v| (turbulent)              laminar line, dp = R v
string_damping                quadratic drag c_q dv|dv| in the tension      linear dashpot c dv
============================  ===========================================  =============================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.effects.compose import composition
from heavecomp.friction.laws import FC, FS, STRIBECK, VS, stribeck_excess
from heavecomp.params.core import q
from heavecomp.plants.cmc import A, P0ABS, PATM, V0


class TruthSpeedLag(Effect):
    """The Stribeck curve of paper A eq. 4 evaluated at a lagged speed w, dw/dt = (|v| - w)/T_w."""

    name = "friction_lag"
    hook = "seal_friction"
    states = ("w",)

    @dataclass(frozen=True)
    class Params:
        lag_time_speed: float = q(1.0, "s", bounds=(0.0, 100.0), open_low=True, symbol="T_w",
                                  doc="lag of the speed the Stribeck curve sees")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, lag_time_speed):
        if code == STRIBECK:
            return J - stribeck_excess(np.maximum(a, 0.0), FP[FS], FP[FC], FP[VS]) + stribeck_excess(
                x[0], FP[FS], FP[FC], FP[VS])
        return J

    @staticmethod
    def rates(s, v, p, x, PP, FP, lag_time_speed):
        return ((np.abs(v) - x[0]) / lag_time_speed,)

    @staticmethod
    def initial(FP, PP, lag_time_speed):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, lag_time_speed):
        return (abs(v),)


class TruthDwell(Effect):
    """Static friction grows with the dwell time tau and saturates: + dF (1 - exp(-tau/tau_d))."""

    name = "dwell_stiction"
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        dF: float = q(1e4, "N", bounds=(0.0, 1e7), symbol="dF", doc="saturated static-friction gain")
        tau_d: float = q(1.0, "s", bounds=(0.0, 100.0), open_low=True, symbol="tau_d", doc="dwell time constant")

    @staticmethod
    def static(code, p, lim, tau, s, d, x, FP, dF, tau_d):
        return lim + dF * (1.0 - np.exp(-tau / tau_d))


class TruthEnergisedSeal(Effect):
    """An energised seal: extra friction k max(p - p_th, 0) above a threshold pressure."""

    name = "pressure_friction"
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        k: float = q(0.03, "N/Pa", bounds=(0.0, 1.0), symbol="k", doc="friction per pascal above p_th")
        p_th: float = q(2e6, "Pa", bounds=(0.0, 1e8), symbol="p_th", doc="threshold pressure")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, k, p_th):
        return J + k * np.maximum(p - p_th, 0.0)


class TruthThermalGas(Effect):
    """Ideal gas with a temperature state theta = T/T_0: adiabatic compression, Newton heat exchange.

    Notes
    -----
    p_abs = (p_0 + p_atm) theta V_0 / (V_0 + A s);
    dtheta/dt = -(gamma - 1) theta A v / (V_0 + A s) + (1 - theta) / tau_th.
    """

    name = "gas_heat_transfer"
    hook = "gas_spring"
    states = ("theta",)

    @dataclass(frozen=True)
    class Params:
        gamma: float = q(1.4, "-", bounds=(1.0, 1.67), symbol="gamma", doc="adiabatic index of the gas")
        tau_th: float = q(4.0, "s", bounds=(0.0, 1e3), open_low=True, symbol="tau_th", doc="heat exchange time")

    @staticmethod
    def gas(s, v, p, x, PP, gamma, tau_th):
        return PP[P0ABS] * x[0] * (PP[V0] / (PP[V0] + PP[A] * s)) - PP[PATM]

    @staticmethod
    def rates(s, v, p, x, PP, FP, gamma, tau_th):
        return (-(gamma - 1.0) * x[0] * PP[A] * v / (PP[V0] + PP[A] * s) + (1.0 - x[0]) / tau_th,)

    @staticmethod
    def initial(FP, PP, gamma, tau_th):
        return (1.0,)

    @staticmethod
    def steady(v, FP, PP, gamma, tau_th):
        return (1.0,)


class TruthOrifice(Effect):
    """Turbulent line loss: p_cyl = p_gas - K v|v|."""

    name = "flow_loss"
    hook = "line"

    @dataclass(frozen=True)
    class Params:
        K: float = q(3e5, "Pa s^2/m^2", bounds=(0.0, 1e9), symbol="K", doc="orifice coefficient")

    @staticmethod
    def line(v, p, x, PP, K):
        return p - K * v * np.abs(v)


class TruthQuadraticDrag(Effect):
    """Quadratic drag in the string: T_ds += c_q dv|dv|, dv = dz_h + v - v_b."""

    name = "string_damping"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        c_q: float = q(5e5, "N s^2/m^2", bounds=(0.0, 1e9), symbol="c_q", doc="quadratic drag coefficient")

    @staticmethod
    def string(dv, T, x, PP, c_q):
        return T + c_q * dv * np.abs(dv)


#: effect name -> truth class
TRUTH = {c.name: c for c in (TruthSpeedLag, TruthDwell, TruthEnergisedSeal, TruthThermalGas, TruthOrifice,
                              TruthQuadraticDrag)}


def truth_composition():
    """One compiled stepper for every truth law (switched on per run)."""
    return composition(tuple(TRUTH.values()))
