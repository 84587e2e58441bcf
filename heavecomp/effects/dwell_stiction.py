"""``dwell_stiction``: static friction grows with the time at rest (seal friction hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.effects.features import breakaway_dwell, need
from heavecomp.params.core import q


class DwellStiction(Effect):
    """Static limit F_S + C_p |p| + a tau^beta, tau the time since the cylinder stuck.

    Notes
    -----
    Paper B: "static friction grows with the time at rest".  The dwell time tau is kept by
    the stepper (it is the stick event's clock), so the effect has no state of its own.
    """

    name = "dwell_stiction"
    fit = FitSpec(
        candidate=True,
        # the top-mass balance is blind at breakaway (the static force is whatever holds the piston)
        screened=False,
        # the score test's probes (diagnosis.score_test): half the tuning set's planted 10 kN excess, at
        # three exponents over the range
        probes=tuple((("gain", 5e3), ("exponent", b)) for b in (0.25, 0.5, 1.0)),
        log=("gain",),
        # exponents beta [-] searched by the equation-error fit
        feature_grid=(0.25, 0.5, 0.75, 1.0),
        # name and unit of the equation-error shape parameter
        feature_shape=("exponent", "-"),
        # units of the feature coefficients [SI]
        feature_units={"breakaway_excess": "N/s^beta", "exponent": "-"},
    )
    hook = "seal_friction"
    adds_stiction = True
    #: how long after a breakaway the excess static friction is counted [s] (equation error only)
    breakaway_window = 0.05

    @dataclass(frozen=True)
    class Params:
        gain: float = q(2e3, "N/s^beta", bounds=(1.0, 2e5), symbol="a", doc="static-friction gain after 1 s at rest")
        exponent: float = q(0.5, "-", bounds=(0.05, 1.0), symbol="beta", doc="power of the dwell time")

    @classmethod
    def features(cls, sig, shape=None):
        """``breakaway_excess``: sign(v) tau^beta during the first :attr:`breakaway_window` of each
        sliding phase, tau the rest that preceded it [s^beta] (coefficient: ``gain`` a [N/s^beta]).

        Notes
        -----
        The static limit a tau^beta is crossed at breakaway, so its equation-error trace is a force
        in the direction of motion just after the axis leaves rest, growing with how long it rested
        (``dwell``); ``shape`` is beta.
        """
        if not need(sig, "t", "v", "dwell"):
            return None
        tau = breakaway_dwell(sig["t"], sig["dwell"], cls.breakaway_window)
        return {"breakaway_excess": np.sign(sig["v"]) * tau ** float(shape)}

    @staticmethod
    def static(code, p, lim, tau, s, d, x, FP, gain, exponent):
        return lim + gain * np.maximum(tau, 1e-12) ** exponent

    @classmethod
    def null(cls, plant):
        return {"gain": 0.0, "exponent": 0.5}


EFFECT = DwellStiction
