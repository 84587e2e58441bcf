"""flow_loss, as generated: a turbulent orifice, p_cyl = p_gas - K v|v|.

The candidate (fitted, :mod:`heavecomp.effects`) is a laminar line, dp = R v.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class TruthOrifice(Effect):
    """Turbulent line loss: p_cyl = p_gas - K v|v|."""

    name = "flow_loss"
    hook = "line"

    @dataclass(frozen=True)
    class Params:
        K: float = q(3e5, "Pa s^2/m^2", bounds=(0.0, 1e9), symbol="K", doc="orifice coefficient")

    @staticmethod
    def line(v, p, x, PP, K):
        return p - K * v * np.abs(v)


def draw(rng, setting):
    """K 1.5-4 x 10^5 Pa s^2/m^2; its size is K, at most 10^6.

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
    return Draw({"K": rng.uniform(1.5e5, 4e5)}, "K", 1e6)


LAW = TruthLaw("flow_loss", "flow_line", draw, plant=TruthOrifice)
