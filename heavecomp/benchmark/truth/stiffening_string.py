"""stiffening_string (outside every name), as generated: a string that stiffens with stretch,
T += k_3 e^3, the stretch e = (T - T_0 - c_ds dv)/k_ds recovered from the nominal tension."""

from __future__ import annotations

from dataclasses import dataclass

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.plants.cmc import CDS, KDS, T0


class TruthStiffeningString(Effect):
    """Out of every name: a string that stiffens with stretch, T += k_3 e^3 with the stretch
    e = (T - T_0 - c_ds dv)/k_ds recovered from the nominal tension."""

    name = "stiffening_string"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        k3: float = q(1e8, "N/m^3", bounds=(0.0, 1e14), symbol="k_3", doc="cubic stiffness")

    @staticmethod
    def string(dv, T, x, PP, k3):
        e = (T - PP[T0] - PP[CDS] * dv) / PP[KDS]
        return T + k3 * e * e * e


def draw(rng, setting):
    """k_3 0.5-2 x 10^9 N/m^3; its size is k_3, at most 10^12.

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
    return Draw({"k3": rng.uniform(0.5e9, 2e9)}, "k3", 1e12)


LAW = TruthLaw("stiffening_string", "string_formation", draw, plant=TruthStiffeningString,
               named=False)
