"""``string_damping``: extra drill-string damping (string hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.params.core import q


class StringDamping(Effect):
    """A linear dashpot c (dz_h + v - v_b) added to the drill-string tension."""

    name = "string_damping"
    fit = FitSpec(
        candidate=True,
        # the lower-mass balance missed a string damping whose WOB gap was 3.3x its noise (tuning set):
        # its residual is too noisy to rule it out
        screened=False,
        log=("damping",),
        # units of the equation-error coefficients (``features``)
        feature_units={"string_damping": "N s/m"},
    )
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        damping: float = q(3e4, "N s/m", bounds=(10.0, 2e6), symbol="c", doc="extra drill-string damping")

    @classmethod
    def features(cls, sig, shape=None):
        """``string_formation`` residual (measured minus nominal WOB) [N]: ``string_damping``
        -d(dz)/dt [m/s] (coefficient c [N s/m]): the dashpot's tension c d(dz)/dt on the string's
        extension rate (``dz``) takes that much off the bit."""
        if not all(k in sig for k in ("t", "dz")):
            return None
        return {"string_damping": -np.gradient(np.asarray(sig["dz"], dtype=float), np.asarray(sig["t"], dtype=float))}

    @staticmethod
    def string(dv, T, x, PP, damping):
        return T + damping * dv

    @classmethod
    def null(cls, plant):
        return {"damping": 0.0}


EFFECT = StringDamping
