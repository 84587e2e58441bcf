"""``heave_reference``: the heave signal is not the heave the compensator sees (heave-input hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import HeaveEffect
from heavecomp.params.core import q


class HeaveReference(HeaveEffect):
    """z_seen(t) = g z_meas(t - t_d): the heave the compensator sees is the measured heave
    scaled and shifted in time.

    Notes
    -----
    Covers a motion reference unit that scales (a calibration or a wrong lever arm in its
    configuration: g != 1) or filters its output (its filter's group delay: t_d < 0, the
    measurement comes late), and a heave measured away from the crown block.  There
    z_meas = z_crown + L theta (lever arm L times pitch or roll theta).  With no pitch channel in
    the log, theta cannot be separated from the heave; but a vessel's pitch is driven by the same
    waves, so in the narrow wave band theta ~ c z_crown shifted by a phase phi (the vessel's
    response, near-constant over the band).  Then z_meas ~ z_crown (1 + L c e^{i phi}): a gain and
    a phase, and a phase that is near-constant over a narrow band is a time shift t_d = phi /
    omega_peak.  So the lever-arm case shows as a gain plus a delay (negative t_d: a lead).
    Acts on the heave input, outside the stepper (the heave samples the stepper interpolates).
    """

    name = "heave_reference"
    candidate = True

    #: units of the equation-error coefficients (``features``)
    feature_units = {"gain": "-", "delay": "-"}
    @dataclass(frozen=True)
    class Params:
        scale: float = q(1.0, "-", bounds=(-1.5, 1.5), symbol="g",
                         doc="factor from the measured to the seen heave (negative: the heave logged with the wrong sign)")
        delay: float = q(0.0, "s", bounds=(-2.0, 2.0), symbol="t_d",
                         doc="time by which the seen heave lags the measured one (negative: leads)")

    #: delays t_d [s] searched by the equation-error fit
    feature_grid = (-1.0, -0.5, -0.2, -0.1, 0.0, 0.1, 0.2, 0.5)

    @classmethod
    def features(cls, sig, shape=None):
        """``heave_input`` residual (the heave the plant saw, from the other channels, minus the
        measured ``heave``) [m]: ``gain`` z (coefficient g - 1) and ``delay`` z(t - t_d) - z(t)
        (coefficient g) for t_d = ``shape``: g z(t - t_d) - z(t), the seen heave by :meth:`seen`."""
        if not all(k in sig for k in ("t", "heave")):
            return None
        t, z = np.asarray(sig["t"], dtype=float), np.asarray(sig["heave"], dtype=float)
        d = cls.Params().delay if shape is None else float(shape)
        return {"gain": z, "delay": cls.seen(t, z, 1.0, d) - z}

    @staticmethod
    def seen(t, z, scale, delay):
        """The seen heave (or its derivative) on the uniform grid ``t`` [s] from the measured ``z``
        (linear interpolation; held at the ends)."""
        return scale * np.interp(t - delay, t, z)

    @classmethod
    def null(cls, plant):
        return {"scale": 1.0, "delay": 0.0}


EFFECT = HeaveReference
