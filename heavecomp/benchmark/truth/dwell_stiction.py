"""dwell_stiction, as generated: static friction grows with the dwell time tau and saturates,
+ dF (1 - exp(-tau/tau_d)).

The candidate (fitted, :mod:`heavecomp.effects`) is a power law a tau^beta.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw
from heavecomp.effects.base import Effect
from heavecomp.params.core import q

#: planted only where the compensator is stuck at least this share of the time (else invisible) [-]
STICK_MIN = 0.15


class TruthDwell(Effect):
    """Static friction grows with the dwell time tau and saturates: + dF (1 - exp(-tau/tau_d))."""

    name = "dwell_stiction"
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        dF: float = q(1e4, "N", bounds=(0.0, 1e7), symbol="dF", doc="saturated static-friction gain")
        tau_d: float = q(1.0, "s", bounds=(0.0, 100.0), open_low=True, symbol="tau_d", doc="dwell time constant")

    @staticmethod
    def static(code, p, lim, tau, s, d, x, FP, dF, tau_d):
        return lim + dF * (1.0 - np.exp(-tau / tau_d))


def draw(rng, setting):
    """dF 35-65 % of the nominal static friction F_S, tau_d 0.5-2 s; its size is dF, at most F_S
    (static friction at most doubles).

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads the nominal static friction
        ``nominal.friction.static_force`` [N].

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    fs = setting.nominal.friction.static_force
    return Draw({"dF": rng.uniform(0.35, 0.65) * fs, "tau_d": rng.uniform(0.5, 2.0)}, "dF", fs)


LAW = TruthLaw("dwell_stiction", "friction", draw, plant=TruthDwell, min_stuck_share=STICK_MIN)
