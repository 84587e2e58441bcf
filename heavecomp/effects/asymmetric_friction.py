"""``asymmetric_friction``: seal friction differs between extending and retracting strokes (seal friction hook)."""

from __future__ import annotations

from dataclasses import dataclass

from heavecomp.effects.base import Effect
from heavecomp.params.core import q


class AsymmetricFriction(Effect):
    """J -> (1 + a d) J: the friction law's jump scaled up in one direction and down in the other.

    Notes
    -----
    ``d`` is the direction of the (impending) motion (+1 extending, v > 0; -1 retracting); a lip
    seal or a chevron pack is usually stiffer one way.  With |a| < 1 the friction keeps the sign
    of the velocity (F v >= 0): the force is J (1 + a) extending and J (1 - a) retracting, their
    ratio (1 + a) / (1 - a).  At rest the static limit is taken in the direction the holding
    force pushes.
    """

    name = "asymmetric_friction"
    candidate = True
    hook = "seal_friction"

    @dataclass(frozen=True)
    class Params:
        asymmetry: float = q(0.1, "-", bounds=(-0.9, 0.9), symbol="a",
                             doc="relative friction excess extending (+) over retracting (-): J (1 + a sign(v))")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, asymmetry):
        return J * (1.0 + asymmetry * d)

    @classmethod
    def null(cls, plant):
        return {"asymmetry": 0.0}


EFFECT = AsymmetricFriction
