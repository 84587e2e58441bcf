"""gas_leak, as generated: the gas charge leaks through a laminar path, mass fraction mu,
dmu/dt = -mu p/(p_0 T_l), p_gas + p_atm = (p + p_atm) mu^n.

The candidate (fitted, :mod:`heavecomp.effects`) is a drift of the spring's preload.
"""

from __future__ import annotations

from dataclasses import dataclass

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.plants.cmc import N, P0ABS, PATM


class TruthLaminarLeak(Effect):
    """Gas charge leaking through a laminar path: mass fraction mu, dmu/dt = -mu p / (p_0 T_l)."""

    name = "gas_leak"
    hook = "gas_spring"
    states = ("mu",)

    @dataclass(frozen=True)
    class Params:
        leak_rate: float = q(2.5e-5, "1/s", bounds=(0.0, 1.0), symbol="1/T_l", doc="leak rate at the charge pressure")

    @staticmethod
    def gas(s, v, p, x, PP, leak_rate):
        return (p + PP[PATM]) * x[0] ** PP[N] - PP[PATM]

    @staticmethod
    def rates(s, v, p, x, PP, FP, leak_rate):
        return (-x[0] * leak_rate * p / (PP[P0ABS] - PP[PATM]),)

    @staticmethod
    def initial(FP, PP, leak_rate):
        return (1.0,)

    @staticmethod
    def steady(v, FP, PP, leak_rate):
        return (1.0,)


def draw(rng, setting):
    """1-3 % of the charge lost over the run; its size is the leak rate, at most 15 % over the run.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads the run length ``duration`` [s] (the leak rate is a share of
        the charge over it).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    return Draw({"leak_rate": rng.uniform(0.01, 0.03) / setting.duration}, "leak_rate", 0.15 / setting.duration)


LAW = TruthLaw("gas_leak", "gas_spring", draw, plant=TruthLaminarLeak)
