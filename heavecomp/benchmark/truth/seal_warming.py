"""seal_warming (outside every name), as generated: the seal warms with cycling and its friction
drops, J (1 - beta theta), dtheta/dt = (|v|/v_ref - theta)/T_th."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class TruthSealWarming(Effect):
    """Out of every name: the seal warms with cycling and its friction drops, J (1 - beta theta),
    dtheta/dt = (|v|/v_ref - theta)/T_th."""

    name = "seal_warming"
    hook = "seal_friction"
    states = ("theta",)

    @dataclass(frozen=True)
    class Params:
        beta: float = q(0.2, "-", bounds=(0.0, 0.9), symbol="beta", doc="friction drop at the reference speed")
        v_ref: float = q(0.3, "m/s", bounds=(0.0, 10.0), open_low=True, symbol="v_ref", doc="reference mean speed")
        t_th: float = q(120.0, "s", bounds=(0.0, 1e5), open_low=True, symbol="T_th", doc="seal thermal time")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, beta, v_ref, t_th):
        return J * (1.0 - beta * np.minimum(x[0], 1.0))

    @staticmethod
    def rates(s, v, p, x, PP, FP, beta, v_ref, t_th):
        return ((np.abs(v) / v_ref - x[0]) / t_th,)

    @staticmethod
    def initial(FP, PP, beta, v_ref, t_th):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, beta, v_ref, t_th):
        return (0.0,)


def draw(rng, setting):
    """beta 0.15-0.3 at v_ref 0.3 m/s, T_th 60-200 s; its size is beta, at most 0.8.

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
    return Draw({"beta": rng.uniform(0.15, 0.3), "v_ref": 0.3, "t_th": rng.uniform(60.0, 200.0)}, "beta", 0.8)


LAW = TruthLaw("seal_warming", "friction", draw, plant=TruthSealWarming, named=False)
