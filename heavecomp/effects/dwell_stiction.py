"""``dwell_stiction``: static friction grows with the time at rest (seal friction hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class DwellStiction(Effect):
    """Static limit F_S + C_p |p| + a tau^beta, tau the time since the cylinder stuck.

    Notes
    -----
    Paper B: "static friction grows with the time at rest".  The dwell time tau is kept by
    the stepper (it is the stick event's clock), so the effect has no state of its own.
    """

    name = "dwell_stiction"
    candidate = True
    hook = "seal_friction"
    adds_stiction = True
    log = ("gain",)

    @dataclass(frozen=True)
    class Params:
        gain: float = q(2e3, "N/s^beta", bounds=(1.0, 2e5), symbol="a", doc="static-friction gain after 1 s at rest")
        exponent: float = q(0.5, "-", bounds=(0.05, 1.0), symbol="beta", doc="power of the dwell time")

    @staticmethod
    def static(code, p, lim, tau, s, d, x, FP, gain, exponent):
        return lim + gain * np.maximum(tau, 1e-12) ** exponent

    @classmethod
    def null(cls, plant):
        return {"gain": 0.0, "exponent": 0.5}


EFFECT = DwellStiction
