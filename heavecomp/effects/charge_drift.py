"""``charge_drift``: the gas charge is off by a relative amount (gas spring hook)."""

from __future__ import annotations

from dataclasses import dataclass

from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.plants.cmc import PATM


class ChargeDrift(Effect):
    """p_gas + p_atm -> (1 + delta_c)(p_gas + p_atm): a charge leak or a wrong pre-charge."""

    name = "charge_drift"
    hook = "gas_spring"

    @dataclass(frozen=True)
    class Params:
        charge_error: float = q(0.05, "-", bounds=(-0.5, 0.5), symbol="delta_c",
                                doc="relative error of the gas charge (absolute pressure)")

    @staticmethod
    def gas(s, v, p, x, PP, charge_error):
        return p + charge_error * (p + PP[PATM])

    @classmethod
    def null(cls, plant):
        return {"charge_error": 0.0}


EFFECT = ChargeDrift
