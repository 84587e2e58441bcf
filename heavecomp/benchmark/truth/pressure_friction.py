"""pressure_friction, as generated: an energised seal, extra friction k max(p - p_th, 0) above a
threshold pressure p_th = 0.9 p_0.

The candidate (fitted, :mod:`heavecomp.effects`) is linear in pressure, dC_p |p|.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class TruthEnergisedSeal(Effect):
    """An energised seal: extra friction k max(p - p_th, 0) above a threshold pressure."""

    name = "pressure_friction"
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        k: float = q(0.03, "N/Pa", bounds=(0.0, 1.0), symbol="k", doc="friction per pascal above p_th")
        p_th: float = q(2e6, "Pa", bounds=(0.0, 1e8), symbol="p_th", doc="threshold pressure")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, k, p_th):
        return J + k * np.maximum(p - p_th, 0.0)


def draw(rng, setting):
    """k 0.02-0.04 N/Pa above 0.9 p_0; its size is k, at most 0.1 N/Pa.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads the nominal precharge pressure ``nominal.p0`` [Pa] (the
        threshold is 0.9 of it).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    return Draw({"k": rng.uniform(0.02, 0.04), "p_th": 0.9 * setting.nominal.p0}, "k", 0.1)


LAW = TruthLaw("pressure_friction", "friction", draw, plant=TruthEnergisedSeal)
