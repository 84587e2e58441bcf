"""string_damping, as generated: quadratic drag in the string, T_ds += c_q dv|dv|,
dv = dz_h + v - v_b.

The candidate (fitted, :mod:`heavecomp.effects`) is a linear dashpot c dv.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class TruthQuadraticDrag(Effect):
    """Quadratic drag in the string: T_ds += c_q dv|dv|, dv = dz_h + v - v_b."""

    name = "string_damping"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        c_q: float = q(5e5, "N s^2/m^2", bounds=(0.0, 1e9), symbol="c_q", doc="quadratic drag coefficient")

    @staticmethod
    def string(dv, T, x, PP, c_q):
        return T + c_q * dv * np.abs(dv)


def draw(rng, setting):
    """c_q 3-8 x 10^5 N s^2/m^2; its size is c_q, at most 4 x 10^6.

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
    return Draw({"c_q": rng.uniform(3e5, 8e5)}, "c_q", 4e6)


LAW = TruthLaw("string_damping", "string_formation", draw, plant=TruthQuadraticDrag)
