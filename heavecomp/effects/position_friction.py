"""``position_friction``: seal friction depends on where along the stroke the piston is (seal friction hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.effects.features import need
from heavecomp.params.core import q

#: width of the band's edges as a share of its width (tanh ramps: smooth, so the stepper's event
#: location and casadi's derivatives hold)
EDGE = 0.1


class PositionFriction(Effect):
    """J += dF b(s): extra friction inside a band of the stroke (a worn or scored bore, a seal
    that binds along part of its travel).

    Notes
    -----
    b(s) = (tanh((s - s_c + w/2) / e) - tanh((s - s_c - w/2) / e)) / 2 with edges e = 0.1 w:
    1 inside the band centred at s_c of width w, 0 outside.  It adds to the part of the
    friction that jumps with sign(v), so it also raises the static limit in the band; with
    dF >= 0 the friction still opposes the motion.
    """

    name = "position_friction"
    fit = FitSpec(
        candidate=True,
        log=("extra_force",),
        # bands searched by the equation-error fit: (centre, width) as shares of the travelled span
        feature_grid=tuple((c, w) for w in (0.1, 0.2, 0.4) for c in np.arange(0.1, 0.95, 0.1).round(2)),
        # name and unit of the equation-error shape parameter
        feature_shape=("band_centre_width", "share of the travelled span"),
        # units of the feature coefficients [SI]
        feature_units={"position_friction": "N", "band_centre_width": "share of the travelled span"},
    )
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        extra_force: float = q(3e3, "N", bounds=(10.0, 1e5), symbol="dF", doc="friction added inside the band")
        centre: float = q(0.0, "m", bounds=(-2.0, 2.0), symbol="s_c", doc="stroke at the centre of the band")
        width: float = q(0.3, "m", bounds=(0.02, 3.0), symbol="w", doc="width of the band along the stroke")

    @classmethod
    def features(cls, sig, shape=None):
        """``position_friction`` sign(v) b(x) [-] (coefficient dF [N]) for the band ``shape`` =
        (centre, width) given as shares of the travelled span min(x) .. max(x) (plant-independent),
        b from :meth:`band` (the kernel term's own equation)."""
        if not need(sig, "v", "x") or shape is None:
            return None
        x = np.asarray(sig["x"], dtype=float)
        x0, span = float(x.min()), float(x.max() - x.min())
        if span <= 0:
            return None
        c, w = shape
        return {"position_friction": np.sign(sig["v"]) * cls.band(x, x0 + c * span, w * span)}

    @classmethod
    def from_equation_error(cls, fit, sig):
        """The band (``shape``: centre and width as shares of the travelled span of ``sig["x"]``) in
        metres of stroke, and its coefficient as the extra force (at least the lower bound) [SI]."""
        if fit is None or fit.get("shape") is None or not need(sig, "x"):
            return None
        x = np.asarray(sig["x"], dtype=float)
        x0, span = float(np.nanmin(x)), float(np.nanmax(x) - np.nanmin(x))
        c, w = fit["shape"]
        return {"extra_force": cls.coefficient_value(fit, "position_friction", "extra_force"),
                "centre": x0 + float(c) * span, "width": float(w) * span}

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, extra_force, centre, width):
        e = EDGE * width
        return J + extra_force * 0.5 * (np.tanh((s - centre + 0.5 * width) / e) - np.tanh((s - centre - 0.5 * width) / e))

    @classmethod
    def band(cls, s, centre, width):
        """b(s): the smooth indicator of the band (0..1) [-], from :meth:`jump` itself."""
        return cls.jump(0, 0.0, 0.0, 0.0, np.asarray(s, dtype=float), 1.0, (), None, 1.0, centre, width)

    @classmethod
    def null(cls, plant):
        return {"extra_force": 0.0, "centre": 0.0, "width": 0.3}


EFFECT = PositionFriction
