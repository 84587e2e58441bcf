"""friction_lag, as generated: the Stribeck curve of paper A eq. 4 evaluated at a first-order lagged
*speed* w, dw/dt = (|v| - w)/T_w.

The candidate (fitted, :mod:`heavecomp.effects`) is an asymmetric memory of the Stribeck *excess
force*: a different law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.friction.laws import FC, FS, STRIBECK, VS, stribeck_excess
from heavecomp.params.core import q


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


def draw(rng, setting):
    """T_w 0.8-3 s; its size is the lag, at most 8 s.

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
    return Draw({"lag_time_speed": rng.uniform(0.8, 3.0)}, "lag_time_speed", 8.0)


LAW = TruthLaw("friction_lag", "friction", draw, plant=TruthSpeedLag)
