"""``discovered_term``: the open search's term carried into a model (seal friction hook).

The gap diagnosis' open search (:func:`heavecomp.diagnosis.equation_error.open_search`) fits a
sparse sum of features to a component's equation residual when no named effect explains the gap
(``verdict.discovered``: features and coefficients).  On the ``friction`` component (the top-mass
force balance: measured minus nominal seal friction, N) the features that are friction, i.e. odd in
the velocity and memoryless, have a fixed form at the seal-friction hook; this effect adds them to
the friction magnitude J, with the open search's coefficients as its parameters:

==============  =====================  ===========  ==========================================
parameter       open-search feature     unit         term added to J (F_f = J sign(v) + ...)
==============  =====================  ===========  ==========================================
``sign_v_pos``  sign(v)*(v>0)           N            c when extending (d = +1)
``sign_v_neg``  sign(v)*(v<0)           N            c when retracting (d = -1)
``v``           v                       N s/m        c |v|
``v_abs_v``     v*|v|                   N s^2/m^2    c v^2
``p_sign_v``    p*sign(v)               N/Pa         c p
==============  =====================  ===========  ==========================================

J stays >= 0 (a negative sum is clipped: friction never pushes).  Not a diagnosis candidate and
not registered: a parameter file names it in ``[[effects]]`` (:mod:`heavecomp.effects.spec`).  It is
part of the superset composition compiled at install
(:func:`heavecomp.effects.compose.library_composition`), applied first at the seal-friction hook (on
the law's J, the nominal friction its features were fitted on, :func:`heavecomp.effects.compose.hook_order`),
so a simulation that uses it compiles nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.params.core import q

#: open-search features this effect carries (its parameters, in order)
FEATURES = ("sign_v_pos", "sign_v_neg", "v", "v_abs_v", "p_sign_v")
#: the model component whose open-search term it carries
COMPONENT = "friction"


class DiscoveredTerm(Effect):
    """J -> max(J + c+ max(d, 0) + c- max(-d, 0) + c_v |v| + c_vv v^2 + c_p p, 0)."""

    name = "discovered_term"
    hook = "seal_friction"
    adds_stiction = True
    #: a file may leave out the features the term does not use (0)
    optional = FEATURES

    @dataclass(frozen=True)
    class Params:
        sign_v_pos: float = q(0.0, "N", bounds=(-5e6, 5e6), symbol="c_+",
                              doc="friction added while extending (feature sign(v)*(v>0))")
        sign_v_neg: float = q(0.0, "N", bounds=(-5e6, 5e6), symbol="c_-",
                              doc="friction added while retracting (feature sign(v)*(v<0))")
        v: float = q(0.0, "N s/m", bounds=(-1e8, 1e8), symbol="c_v", doc="viscous friction added (feature v)")
        v_abs_v: float = q(0.0, "N s^2/m^2", bounds=(-1e9, 1e9), symbol="c_vv",
                           doc="quadratic friction added (feature v*|v|)")
        p_sign_v: float = q(0.0, "N/Pa", bounds=(-0.1, 0.1), symbol="c_p",
                            doc="pressure-dependent friction added (feature p*sign(v))")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, sign_v_pos, sign_v_neg, v, v_abs_v, p_sign_v):
        return np.maximum(J + sign_v_pos * np.maximum(d, 0.0) + sign_v_neg * np.maximum(-d, 0.0) + v * a
                          + v_abs_v * a * a + p_sign_v * p, 0.0)

    @classmethod
    def null(cls, plant):
        return {f: 0.0 for f in FEATURES}


EFFECT = DiscoveredTerm
