"""line_inertance (a law of flow_loss), as generated: the oil column's inertance,
p_cyl = p_gas - I A dv/dt, dv/dt from a fast first-order follower w of the piston speed
(dw/dt = (v - w)/T_i)."""

from __future__ import annotations

from dataclasses import dataclass

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.plants.cmc import A


class TruthLineInertance(Effect):
    """A law of flow_loss (the library's line_inertia carries it, by an exact added mass): the oil column's inertance, p_cyl = p_gas - I A dv/dt, with dv/dt taken
    from a fast first-order follower w of the piston speed (dw/dt = (v - w)/T_i)."""

    name = "line_inertance"
    hook = "line"
    states = ("w",)

    @dataclass(frozen=True)
    class Params:
        inertance: float = q(2e5, "Pa s^2/m^3", bounds=(0.0, 1e9), symbol="I", doc="line inertance (per flow)")
        t_i: float = q(0.05, "s", bounds=(0.0, 1.0), open_low=True, symbol="T_i", doc="follower time constant")

    @staticmethod
    def line(v, p, x, PP, inertance, t_i):
        return p - inertance * PP[A] * (v - x[0]) / t_i

    @staticmethod
    def rates(s, v, p, x, PP, FP, inertance, t_i):
        return ((v - x[0]) / t_i,)

    @staticmethod
    def initial(FP, PP, inertance, t_i):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, inertance, t_i):
        return (v,)


def draw(rng, setting):
    """I 1-3 x 10^5 Pa s^2/m^3, T_i 0.05 s; its size is I, at most 5 x 10^6.

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
    return Draw({"inertance": rng.uniform(1e5, 3e5), "t_i": 0.05}, "inertance", 5e6)


# a law of the contract's flow_loss since the library carries the line's inertance (line_inertia, law
# "inertance"; issue 30 item 4): outside every name until then
LAW = TruthLaw("line_inertance", "flow_line", draw, plant=TruthLineInertance, answer="flow_loss")
