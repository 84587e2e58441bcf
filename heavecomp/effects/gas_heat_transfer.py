"""``gas_heat_transfer``: the gas is neither at a fixed polytropic index nor lossless (gas spring hook)."""

from __future__ import annotations

from dataclasses import dataclass

from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.plants.cmc import A, N, P0ABS, PATM, V0


class GasHeatTransfer(Effect):
    """Effective polytropic index plus a linear loss.

    Notes
    -----
    p_gas + p_atm = (p_0 + p_atm) (V_0 / (V_0 + A s))^{n_eff}, and the cylinder sees
    p_gas - c_g v (the heat-exchange hysteresis as a loss per unit stroke velocity).
    """

    name = "gas_heat_transfer"
    candidate = True
    hook = "gas_spring"
    log = ("loss_coefficient",)

    @dataclass(frozen=True)
    class Params:
        effective_index: float = q(1.2, "-", bounds=(1.0, 1.67), symbol="n_eff", doc="effective polytropic index")
        loss_coefficient: float = q(1e4, "Pa s/m", bounds=(10.0, 1e7), symbol="c_g",
                                    doc="pressure loss per unit stroke velocity (heat-exchange hysteresis)")

    @staticmethod
    def gas(s, v, p, x, PP, effective_index, loss_coefficient):
        return PP[P0ABS] * (PP[V0] / (PP[V0] + PP[A] * s)) ** effective_index - PP[PATM]

    @staticmethod
    def line(v, p, x, PP, effective_index, loss_coefficient):
        return p - loss_coefficient * v

    @classmethod
    def null(cls, plant):
        return {"effective_index": float(plant.PP[N]), "loss_coefficient": 0.0}


EFFECT = GasHeatTransfer
