"""``flow_loss``: pressure drop in the line between cylinder and gas bank (line hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.params.core import q


class FlowLoss(Effect):
    """Laminar line: p_cyl = p_gas - R v.

    Flow out of the cylinder (v < 0, plunger pushed in) raises the cylinder pressure.
    """

    name = "flow_loss"
    fit = FitSpec(
        candidate=True,
        # the replay fit's start: the resistance R [Pa s/m] is the ``flow_loss`` coefficient itself (the
        # feature is the kernel's drop per unit -v)
        coefficients={"flow_loss": "resistance"},
        log=("resistance",),
        # units of the equation-error coefficients (``features``)
        feature_units={"flow_loss": "Pa s/m"},
    )
    hook = "line"

    @dataclass(frozen=True)
    class Params:
        resistance: float = q(3e4, "Pa s/m", bounds=(10.0, 1e7), symbol="R",
                              doc="line pressure drop per unit stroke velocity")

    @classmethod
    def features(cls, sig, shape=None):
        """``flow_line`` residual (measured minus nominal cylinder pressure) [Pa]: ``flow_loss``
        -v [m/s] (coefficient R [Pa s/m]): the drop with the flow A v out of the cylinder."""
        if "v" not in sig:
            return None
        return {"flow_loss": -np.asarray(sig["v"], dtype=float)}

    @staticmethod
    def line(v, p, x, PP, resistance):
        return p - resistance * v

    @classmethod
    def null(cls, plant):
        return {"resistance": 0.0}


EFFECT = FlowLoss
