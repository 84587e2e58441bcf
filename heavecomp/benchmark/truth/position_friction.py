"""position_friction, as generated: friction raised inside a worn band of the stroke, a parabolic
bump J (1 + beta max(0, 1 - ((s - s_c)/w)^2)), the stroke tracked as a state ds/dt = v.

The candidate (fitted, :mod:`heavecomp.effects`) is a different shape of the band.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class TruthWornBand(Effect):
    """Friction raised by up to beta inside a worn band of the stroke, a parabolic bump
    J (1 + beta max(0, 1 - ((s - s_c)/w)^2)), with the stroke s tracked as a state (ds/dt = v)."""

    name = "position_friction"
    hook = "seal_friction"
    states = ("s",)

    @dataclass(frozen=True)
    class Params:
        beta: float = q(0.3, "-", bounds=(-0.9, 5.0), symbol="beta", doc="relative friction change at the centre")
        s_c: float = q(0.0, "m", bounds=(-5.0, 5.0), symbol="s_c", doc="centre of the band")
        w: float = q(0.2, "m", bounds=(0.0, 5.0), open_low=True, symbol="w", doc="half width of the band")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, beta, s_c, w):
        return J * (1.0 + beta * np.maximum(1.0 - ((x[0] - s_c) / w) ** 2, 0.0))

    @staticmethod
    def rates(s, v, p, x, PP, FP, beta, s_c, w):
        return (v,)

    @staticmethod
    def initial(FP, PP, beta, s_c, w):
        return (0.0,)  # the run starts at rest at the operating point, s = 0

    @staticmethod
    def steady(v, FP, PP, beta, s_c, w):
        return (0.0,)


def draw(rng, setting):
    """beta 0.3-0.6 in a band centred -0.3..0.3 m, half width 0.15-0.3 m; its size is beta, at most 3.

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
    return Draw({"beta": rng.uniform(0.3, 0.6), "s_c": rng.uniform(-0.3, 0.3), "w": rng.uniform(0.15, 0.3)},
                "beta", 3.0)


LAW = TruthLaw("position_friction", "friction", draw, plant=TruthWornBand)
