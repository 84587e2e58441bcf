"""``asymmetric_friction``: seal friction differs between extending and retracting strokes (seal friction hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.effects.features import need
from heavecomp.params.core import q


class AsymmetricFriction(Effect):
    """J -> (1 + a d g) J: the friction law's jump scaled up in one direction and down in the other.

    Notes
    -----
    ``d`` is the direction of the (impending) motion (+1 extending, v > 0; -1 retracting); a lip
    seal or a chevron pack is usually stiffer one way.  With |a| < 1 the friction keeps the sign
    of the velocity (F v >= 0): the force is J (1 + a) extending and J (1 - a) retracting, their
    ratio (1 + a) / (1 - a).  At rest the static limit is taken in the direction the holding
    force pushes.

    Whether the breakaway force is as asymmetric as the sliding friction depends on the seal: a
    lip that tilts over only once the rod moves gives a symmetric breakaway and an asymmetry that
    builds up with speed.  g = 1 - (1 - b) exp(-|v| / v_g) carries the share ``breakaway`` b of
    the asymmetry at rest (b = 1: the whole jump scaled in every state; b = 0: a symmetric
    breakaway) and grows to the whole over the speed ``growth_speed`` v_g, fitted: a lip that
    tilts over slowly after a reversal spreads the growth over a wider speed range than the
    friction law's Stribeck speed (which v_g used to be; its default 0.01 m/s is paper A's v_S).
    The equation error, which sees the sliding friction only, fits ``a`` alone; the replay fits
    all three.
    """

    name = "asymmetric_friction"
    fit = FitSpec(
        candidate=True,
        # a breakaway share of 0 or 1 is a physical answer (the search bounds are its range)
        limits=("breakaway",),
        # the speed over which the asymmetry grows spans decades (a lagged lip to an instant one)
        log=("growth_speed",),
        # a growth speed refines the two-parameter law (a, b): fitted from its optimum, never worse on the fit part
        released_last=("growth_speed",),
        # units of the feature coefficients [SI]
        feature_units={"asymmetric_friction": "N", "asymmetric_pressure_friction": "N/Pa", "asymmetric_viscous": "N s/m"},
    )
    hook = "seal_friction"

    @dataclass(frozen=True)
    class Params:
        asymmetry: float = q(0.1, "-", bounds=(-0.9, 0.9), symbol="a",
                             doc="relative friction excess extending (+) over retracting (-): J (1 + a sign(v))")
        breakaway: float = q(1.0, "-", bounds=(0.0, 1.0), symbol="b",
                             doc="share of the asymmetry the static limit carries (0: symmetric breakaway)")
        growth_speed: float = q(0.01, "m/s", bounds=(1e-4, 1.0), symbol="v_g",
                                doc="speed over which the asymmetry grows from its breakaway share to the whole")

    @classmethod
    def features(cls, sig, shape=None):
        """``asymmetric_friction`` |sign v| [-] (coefficient a F_C [N]), with a pressure also
        ``asymmetric_pressure_friction`` |sign v| |p| [Pa] (coefficient a C_p [N/Pa]), and
        ``asymmetric_viscous`` |v| [m/s] (coefficient (F_v+ - F_v-)/2 [N s/m]).

        Notes
        -----
        J (1 + a d) sign(v) = J sign(v) + a J |sign v| while sliding (d = sign v): the direction
        asymmetry is a force of one sign in both directions, a J.  J = F_C + C_p |p| gives the first
        two columns.  The third is the same asymmetry of the viscous part, F_v (1 + a_v d) v =
        F_v v + a_v F_v |v|: the kernel term scales J only, the equation error also looks for the
        viscous asymmetry (on the EMPS axis it is the larger one).  A plant whose nominal has a
        constant force (an offset) already spans the first column: the diagnoser drops it there.
        """
        if not need(sig, "v"):
            return None
        v = np.asarray(sig["v"], dtype=float)
        moving = np.abs(np.sign(v))
        cols = {"asymmetric_friction": moving}
        if need(sig, "p"):
            cols["asymmetric_pressure_friction"] = moving * np.abs(sig["p"])
        cols["asymmetric_viscous"] = np.abs(v)
        return cols

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, asymmetry, breakaway, growth_speed):
        grown = 1.0 - (1.0 - breakaway) * np.exp(-np.maximum(a, 0.0) / growth_speed)
        return J * (1.0 + asymmetry * d * grown)

    @classmethod
    def null(cls, plant):
        return {"asymmetry": 0.0, "breakaway": 1.0, "growth_speed": 0.01}


EFFECT = AsymmetricFriction
