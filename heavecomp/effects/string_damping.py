"""``string_damping``: extra drill-string damping (string hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.params.core import q


#: reference relative speed of the power law [m/s]: the damping's force at this speed is c v_r whatever the
#: exponent (near the string's relative speeds, 0.05-0.5 m/s, so that c and n are fitted nearly independently)
V_REF = 0.1


class StringDamping(Effect):
    """A dashpot c dv |dv / v_r|^(n - 1) added to the drill-string tension, dv = dz_h + v - v_b.

    Notes
    -----
    The law's shape is carried, not only its slope: n = 1 is the linear dashpot c dv (the fit starts
    there), n = 2 a quadratic drag (mud, a stabiliser in a tight hole), n < 1 a friction-like drag.  The
    exponent is fitted last (``FitSpec.released_last``): c alone as before, then c and n together from
    that optimum, so the fit part never ends up worse than the linear dashpot's.
    """

    name = "string_damping"
    fit = FitSpec(
        candidate=True,
        # the lower-mass balance missed a string damping whose WOB gap was 3.3x its noise (tuning set):
        # its residual is too noisy to rule it out
        screened=False,
        # the score test's probes (diagnosis.score_test): a damping of 1e5 N s/m (a smooth term: its
        # replay is near-linear in it) at a friction-like, a linear and a quadratic law
        probes=tuple((("damping", 1e5), ("exponent", n)) for n in (0.5, 1.0, 2.0)),
        log=("damping",),
        # a smooth term (no stick event's timing jumps with c or n): fitted by Gauss-Newton, not by a grid and
        # Nelder-Mead (bench_600s: 50 replays of its configuration, 2 per fit-part replay on the library stepper)
        smooth=True,
        # the law's shape refines the linear dashpot: fitted from its optimum, never worse on the fit part
        released_last=("exponent",),
        # a file written before the exponent existed reads a linear dashpot (n = 1)
        optional=("exponent",),
        # exponents n searched by the equation-error fit
        feature_grid=(0.2, 0.5, 1.0, 1.5, 2.0, 3.0),
        # name and unit of the equation-error shape parameter
        feature_shape=("exponent", "-"),
        # units of the equation-error coefficients (``features``)
        feature_units={"string_damping": "N s/m"},
    )
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        damping: float = q(3e4, "N s/m", bounds=(10.0, 2e6), symbol="c",
                           doc="extra drill-string damping (the force at the reference speed v_r over v_r)")
        exponent: float = q(1.0, "-", bounds=(0.1, 3.0), symbol="n",
                            doc="exponent of the damping law (1: a linear dashpot, 2: a quadratic drag)")

    @classmethod
    def features(cls, sig, shape=None):
        """``string_formation`` residual (measured minus nominal WOB) [N]: ``string_damping``
        -r |r / v_r|^(n - 1) [m/s] (coefficient c [N s/m]), r = d(dz)/dt the string's extension rate
        (``dz``) and n = ``shape`` (default 1): the dashpot's tension takes that much off the bit."""
        if not all(k in sig for k in ("t", "dz")):
            return None
        r = np.gradient(np.asarray(sig["dz"], dtype=float), np.asarray(sig["t"], dtype=float))
        n = 1.0 if shape is None else float(shape)
        return {"string_damping": -r * np.maximum(np.abs(r) / V_REF, 1e-6) ** (n - 1.0)}

    @classmethod
    def from_equation_error(cls, fit, sig):
        """The damping c [N s/m]: the ``string_damping`` coefficient (the force at the reference speed
        over v_r, as in the kernel: :data:`V_REF` makes it nearly independent of n), inside its bounds;
        the exponent n: the grid value the fit picked (``shape``; 1 when it has none)."""
        c = cls.coefficient_value(fit, "string_damping", "damping")
        if c is None:
            return None
        return {"damping": c, "exponent": 1.0 if fit.get("shape") is None else float(fit["shape"])}

    @staticmethod
    def string(dv, T, x, PP, damping, exponent):
        # c dv |dv / v_r|^(n - 1): at n = 1 exactly the linear dashpot c dv (x^0 = 1), and its slope at dv = 0
        # stays c there (the linearised model keeps the damping); floored so that n < 1 stays finite at rest
        return T + damping * dv * np.maximum(np.abs(dv) / V_REF, 1e-6) ** (exponent - 1.0)

    @classmethod
    def null(cls, plant):
        return {"damping": 0.0, "exponent": 1.0}


EFFECT = StringDamping
