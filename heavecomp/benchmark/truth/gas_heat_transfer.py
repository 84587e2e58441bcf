"""gas_heat_transfer, as generated: a thermal state theta = T/T_0, adiabatic compression with a fixed
gamma and heat exchange to the wall by conduction and natural convection: the heat-transfer coefficient
grows with the temperature difference as Nu = Nu_0 + c Ra^(1/3) (turbulent natural convection in a gas
accumulator: Pourmovahed and Otis 1990), so the exchange's time constant depends on how far the gas is
from the wall's temperature.

The candidates (fitted, :mod:`heavecomp.effects`) are an effective polytropic index n_eff plus a
linear loss c_g v (``gas_heat_transfer``) and the thermal-time-constant law with one constant heat-transfer
coefficient (``gas_thermal``): neither is this law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.plants.cmc import A, P0ABS, PATM, V0


class TruthThermalGas(Effect):
    """Ideal gas with a temperature state theta = T/T_0: adiabatic compression, heat exchange by
    conduction and natural convection.

    Notes
    -----
    p_abs = (p_0 + p_atm) theta V_0 / (V_0 + A s);
    dtheta/dt = -(gamma - 1) theta A v / (V_0 + A s)
                + (1 - theta) (K0 + (1 - K0) (|1 - theta| / DTHETA)^(1/3)) / tau_th:
    tau_th is the exchange's time constant at a temperature difference DTHETA = 0.01 (3 K at 300 K); near
    the wall's temperature conduction alone is left, K0 = 0.25 of it.
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
        d = 1.0 - x[0]
        return (-(gamma - 1.0) * x[0] * PP[A] * v / (PP[V0] + PP[A] * s)
                + d * (0.25 + 0.75 * (np.abs(d) / 0.01) ** (1.0 / 3.0)) / tau_th,)

    @staticmethod
    def initial(FP, PP, gamma, tau_th):
        return (1.0,)

    @staticmethod
    def steady(v, FP, PP, gamma, tau_th):
        return (1.0,)


def draw(rng, setting):
    """Nitrogen: gamma fixed at 1.4, tau_th 2-8 s; no size knob (only a redraw changes it).

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads none of it (the signature every draw shares).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    return Draw({"gamma": 1.4, "tau_th": rng.uniform(2.0, 8.0)})


LAW = TruthLaw("gas_heat_transfer", "gas_spring", draw, plant=TruthThermalGas)
