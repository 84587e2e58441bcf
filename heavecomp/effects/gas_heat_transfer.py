"""``gas_heat_transfer``: the gas is neither at a fixed polytropic index nor lossless (gas spring hook)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.params.core import q
from heavecomp.plants.cmc import A, N, P0ABS, PATM, V0


class GasHeatTransfer(Effect):
    """Effective polytropic index, a linear loss, and the slow warming of the gas under cycling.

    Notes
    -----
    p_gas + p_atm = (1 + theta) (p_0 + p_atm) (V_0 / (V_0 + A s))^{n_eff}, and the cylinder sees
    p_gas - c_g v (the heat-exchange hysteresis as a loss per unit stroke velocity).

    theta is the gas's mean relative temperature rise (a state): each stroke cycle turns work
    into heat in the gas (the hysteresis loss, ~ c_g v^2), which the vessel takes away over
    minutes, so d theta/dt = (w v^2 - theta) / T_w.  Under steady cycling the mean pressure
    creeps up by (p_0 + p_atm) w <v^2> with time constant T_w: the slow mean shift of a warming gas
    (issue 12: most of a heat-exchange gap in WOB is that offset).  theta is a slow state: a
    restarted replay segment carries it on (no ``steady`` value).
    """

    name = "gas_heat_transfer"
    fit = FitSpec(
        candidate=True,
        # the contract's heat exchange; this law is an effective index with a dashpot loss (gas_thermal: the
        # gas temperature relaxing to the wall)
        family="gas_heat_transfer",
        law="effective_index",
        log=("loss_coefficient", "warming", "warming_time"),
        # units of the equation-error coefficients (``features``)
        feature_units={"index": "-", "loss": "Pa s/m", "warming": "s^2/m^2"},
        # warming time constants T_w [s] searched by the equation-error fit
        feature_grid=(60.0, 300.0, 1200.0),
    )
    hook = "gas_spring"
    states = ("warming",)

    @dataclass(frozen=True)
    class Params:
        effective_index: float = q(1.2, "-", bounds=(1.0, 1.67), symbol="n_eff", doc="effective polytropic index")
        loss_coefficient: float = q(1e4, "Pa s/m", bounds=(10.0, 1e7), symbol="c_g",
                                    doc="pressure loss per unit stroke velocity (heat-exchange hysteresis)")
        warming: float = q(0.05, "s^2/m^2", bounds=(1e-4, 10.0), symbol="w",
                           doc="steady relative temperature rise of the gas per squared stroke velocity")
        warming_time: float = q(300.0, "s", bounds=(10.0, 5000.0), symbol="T_w",
                                doc="time constant of the gas's warming (heat capacity over heat loss to the vessel)")

    @classmethod
    def features(cls, sig, shape=None):
        """``gas_spring`` residual (measured minus nominal pressure) [Pa]: ``index``
        p_abs ln(p_abs / p_charge_abs) [Pa] (coefficient (n_eff - n) / n, to first order),
        ``loss`` -v [m/s] (c_g [Pa s/m]), ``warming`` p_abs theta_1 [Pa s^2/m^2] (w [s^2/m^2]);
        p_abs = ``p_gas_abs`` and theta_1 the warming state for w = 1 and T_w = ``shape``, integrated
        from the measured stroke velocity with the effect's own :meth:`rates`."""
        if not all(k in sig for k in ("t", "v", "p_gas_abs", "p_charge_abs")):
            return None
        t, v, pa = (np.asarray(sig[k], dtype=float) for k in ("t", "v", "p_gas_abs"))
        tw = cls.Params().warming_time if shape is None else float(shape)
        theta = np.zeros(t.size)
        dt = np.diff(t)
        for k in range(1, t.size):  # explicit steps (dt << T_w); exact for a steady v^2
            rate = cls.rates(0.0, v[k - 1], 0.0, (theta[k - 1],), None, None, 1.0, 0.0, 1.0, tw)[0]
            theta[k] = theta[k - 1] + dt[k - 1] * rate
        return {"index": pa * np.log(pa / float(sig["p_charge_abs"])), "loss": -v, "warming": pa * theta}

    @staticmethod
    def gas(s, v, p, x, PP, effective_index, loss_coefficient, warming, warming_time):
        pe = PP[P0ABS] * (PP[V0] / (PP[V0] + PP[A] * s)) ** effective_index - PP[PATM]
        return pe + x[0] * (pe + PP[PATM])

    @staticmethod
    def line(v, p, x, PP, effective_index, loss_coefficient, warming, warming_time):
        return p - loss_coefficient * v

    @staticmethod
    def rates(s, v, p, x, PP, FP, effective_index, loss_coefficient, warming, warming_time):
        return ((warming * v * v - x[0]) / warming_time,)

    @staticmethod
    def initial(FP, PP, effective_index, loss_coefficient, warming, warming_time):
        return (0.0,)

    @classmethod
    def null(cls, plant):
        """The nominal gas law: n_eff at the plant's index, no loss, no warming.  Without a ``plant``
        (None: what :meth:`~heavecomp.effects.base.Effect.null_like` and a calibrated file's missing
        parameters ask for) the values that need none: n_eff, the plant's own, is left out."""
        out = {"loss_coefficient": 0.0, "warming": 0.0, "warming_time": 300.0}
        if plant is not None:
            out = {"effective_index": float(plant.PP[N]), **out}
        return out


EFFECT = GasHeatTransfer
