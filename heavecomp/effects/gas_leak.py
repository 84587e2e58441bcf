"""``gas_leak``: the gas charge drifts during the run (gas spring hook, one slow state)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.params.core import q
from heavecomp.plants.cmc import PATM


class GasLeak(Effect):
    """p_gas + p_atm -> (1 + delta(t)) (p_gas + p_atm), d delta/dt = r: the charge (the spring's
    preload) moves linearly in time from its nominal value at the start of the log.

    Notes
    -----
    A leak, or the gas bank slowly warming or cooling with the weather, moves the mass of gas or
    its temperature; at the time scale of a log both show as a linear drift of the absolute
    pressure at a given stroke.  ``delta`` is a state (slot of the stepper's state vector), so a
    restarted segment carries it on (no ``steady`` value).  Different from ``charge_drift``, a
    constant error of the charge (not a candidate: the nominal refit covers it).
    """

    name = "gas_leak"
    fit = FitSpec(
        candidate=True,
        # the replay fit's start: r [1/s] is the ``gas_leak`` coefficient itself
        coefficients={"gas_leak": "leak_rate"},
        # units of the equation-error coefficients (``features``)
        feature_units={"gas_leak": "1/s"},
    )
    hook = "gas_spring"
    states = ("charge_change",)

    @dataclass(frozen=True)
    class Params:
        leak_rate: float = q(-2e-5, "1/s", bounds=(-1e-3, 1e-3), symbol="r",
                             doc="relative change of the gas charge per second (negative: a leak)")

    @classmethod
    def features(cls, sig, shape=None):
        """``gas_spring`` residual (measured minus nominal pressure) [Pa]: ``gas_leak``
        t p_gas_abs [Pa s] (coefficient r [1/s]): the charge change r t on the nominal absolute
        pressure at the measured stroke, t from the start of the log."""
        if not all(k in sig for k in ("t", "p_gas_abs")):
            return None
        return {"gas_leak": np.asarray(sig["t"], dtype=float) * np.asarray(sig["p_gas_abs"], dtype=float)}

    @staticmethod
    def gas(s, v, p, x, PP, leak_rate):
        return p + x[0] * (p + PP[PATM])

    @staticmethod
    def rates(s, v, p, x, PP, FP, leak_rate):
        return (leak_rate + 0.0 * v,)

    @staticmethod
    def initial(FP, PP, leak_rate):
        return (0.0,)

    @classmethod
    def null(cls, plant):
        return {"leak_rate": 0.0}


EFFECT = GasLeak
