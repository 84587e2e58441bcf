"""``pressure_friction``: seal friction grows with pressure (seal friction hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.effects.features import need
from heavecomp.params.core import q


class PressureFriction(Effect):
    """J += dC_p |p|: more of paper A eq. 4's C_p term (the seal is energised by the pressure)."""

    name = "pressure_friction"
    fit = FitSpec(
        candidate=True,
        # the replay fit's start: dC_p [N/Pa] is the ``pressure_friction`` coefficient itself
        coefficients={"pressure_friction": "extra_pressure_coefficient"},
        log=("extra_pressure_coefficient",),
        # units of the feature coefficients [SI]
        feature_units={"pressure_friction": "N/Pa"},
    )
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        extra_pressure_coefficient: float = q(1e-3, "N/Pa", bounds=(1e-6, 0.05), symbol="dC_p",
                                              doc="seal friction added per pascal of cylinder pressure")

    @classmethod
    def features(cls, sig, shape=None):
        """``pressure_friction``: sign(v) |p| [Pa] (coefficient: ``extra_pressure_coefficient`` [N/Pa]);
        None on a plant without a pressure."""
        if not need(sig, "v", "p"):
            return None
        return {"pressure_friction": np.sign(sig["v"]) * np.abs(sig["p"])}

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, extra_pressure_coefficient):
        return J + extra_pressure_coefficient * np.abs(p)

    @classmethod
    def null(cls, plant):
        return {"extra_pressure_coefficient": 0.0}


EFFECT = PressureFriction
