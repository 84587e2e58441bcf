"""asymmetric_friction, as generated: seal friction J (1 + alpha d) with d a lagged direction of
motion, dd/dt = (v/(|v| + v_e) - d)/T_d (the seal lip flips over).

The candidate (fitted, :mod:`heavecomp.effects`) is a different law of the direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class TruthLaggedDirection(Effect):
    """Direction-asymmetric seal friction: J (1 + alpha d) with d a lagged direction of motion."""

    name = "asymmetric_friction"
    hook = "seal_friction"
    states = ("d",)

    @dataclass(frozen=True)
    class Params:
        alpha: float = q(0.2, "-", bounds=(-0.9, 0.9), symbol="alpha", doc="friction asymmetry (extending +)")
        t_flip: float = q(0.1, "s", bounds=(0.0, 10.0), open_low=True, symbol="T_d", doc="seal lip flip time")
        v_e: float = q(2e-3, "m/s", bounds=(0.0, 1.0), open_low=True, symbol="v_e", doc="direction smoothing speed")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, alpha, t_flip, v_e):
        return J * (1.0 + alpha * x[0])

    @staticmethod
    def rates(s, v, p, x, PP, FP, alpha, t_flip, v_e):
        return ((v / (np.abs(v) + v_e) - x[0]) / t_flip,)

    @staticmethod
    def initial(FP, PP, alpha, t_flip, v_e):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, alpha, t_flip, v_e):
        return (v / (abs(v) + v_e),)


def draw(rng, setting):
    """alpha +-0.15-0.35, T_d 0.05-0.2 s; its size is |alpha|, at most 0.8.

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
    return Draw({"alpha": float(rng.choice([-1, 1]) * rng.uniform(0.15, 0.35)), "t_flip": rng.uniform(0.05, 0.2),
                 "v_e": 2e-3}, "alpha", 0.8)


LAW = TruthLaw("asymmetric_friction", "friction", draw, plant=TruthLaggedDirection)
