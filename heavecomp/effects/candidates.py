"""The candidate unmodelled effects, one class each, with the contract's names.

Every candidate has

- ``name`` — the contract name (``diagnosis-contract.md``);
- ``Params`` — a frozen dataclass whose fields carry unit, bounds and the
  initial guess of the fit (``field.metadata``; the default is the guess);
- ``states`` — the extra states it adds to the plant;
- ``kind`` — ``"plant"`` (terms in the effect-aware stepper, written into the
  effect-parameter vector ``EP`` by :meth:`write_ep`), ``"output"`` (acts on a
  measured channel: ``sensor_delay``) or ``"nominal"`` (refits nominal
  parameters: ``parameter_mismatch``);
- ``log`` — the fields fitted on a log scale.

The equations are in :mod:`heavecomp.effects.terms` (the ``cand_*`` side of
each pair); the withheld-effect generator uses the ``truth`` side.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from heavecomp.effects import terms as T
from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.params.core import q


class Candidate:
    """Base class: a named effect with a parameter dataclass."""

    name: str = ""
    Params: type = None
    states: tuple = ()
    kind: str = "plant"
    log: tuple = ()
    term: str = ""

    @classmethod
    def fields(cls):
        return dataclasses.fields(cls.Params)

    @classmethod
    def n_params(cls) -> int:
        return len(cls.fields())

    @classmethod
    def describe(cls) -> list[dict]:
        """Name, unit, bounds and initial guess of every parameter."""
        return [{"name": f.name, "unit": f.metadata["unit"], "bounds": list(f.metadata["bounds"]),
                 "initial": f.default, "doc": f.metadata.get("doc", "")} for f in cls.fields()]

    # --- mapping between the fit vector x and named values ------------------
    @classmethod
    def x0(cls) -> np.ndarray:
        return cls.to_x({f.name: f.default for f in cls.fields()})

    @classmethod
    def bounds_x(cls):
        lo, hi = [], []
        for f in cls.fields():
            a, b = f.metadata["bounds"]
            if f.name in cls.log:
                a, b = np.log(a), np.log(b)
            lo.append(a)
            hi.append(b)
        return np.array(lo), np.array(hi)

    @classmethod
    def to_x(cls, values: dict) -> np.ndarray:
        return np.array([np.log(values[f.name]) if f.name in cls.log else values[f.name] for f in cls.fields()])

    @classmethod
    def from_x(cls, x) -> dict:
        return {f.name: float(np.exp(xi) if f.name in cls.log else xi) for f, xi in zip(cls.fields(), x)}

    @classmethod
    def write_ep(cls, values: dict, EP: np.ndarray) -> None:  # pragma: no cover - overridden
        raise NotImplementedError


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class FrictionLagParams:
    lag_time: float = q(1.0, "s", bounds=(0.01, 100.0), symbol="T_E",
                        doc="recovery time of the Stribeck excess force (rising towards its steady value)")
    drop_time: float = q(0.05, "s", bounds=(0.001, 10.0), symbol="T_drop",
                         doc="relaxation time of the Stribeck excess force while it falls")


class FrictionLag(Candidate):
    """``friction_lag``: frictional memory.

    The Stribeck excess (F_S - F_C) e^{-|v|/v_S} of paper A eq. 4 is replaced by a
    state E that follows it with an asymmetric first-order memory,
    dE/dt = ((F_S-F_C) e^{-|v|/v_S} - E)/T with T = T_E while E rises and T_drop while
    it falls (:func:`heavecomp.effects.terms.lag_rates`).  Accelerating, E stays high
    (Stribeck-like); decelerating, it stays low (viscous-like) — the hysteresis of
    paper A Fig. 7.  The static limit at rest is F_C + E + C_p|p|.
    """

    name = "friction_lag"
    Params = FrictionLagParams
    states = ("E",)
    log = ("lag_time", "drop_time")
    term = "friction_magnitude_fx, lag_rates"

    @classmethod
    def write_ep(cls, values, EP):
        EP[T.LAG_T_CAND] = values["lag_time"]
        EP[T.LAG_TDOWN_CAND] = values["drop_time"]


@dataclass(frozen=True)
class DwellParams:
    gain: float = q(2e3, "N/s^beta", bounds=(1.0, 2e5), symbol="a", doc="static-friction gain after 1 s at rest")
    exponent: float = q(0.5, "-", bounds=(0.05, 1.0), symbol="beta", doc="power of the dwell time")


class DwellStiction(Candidate):
    """``dwell_stiction``: static friction grows with the time at rest.

    Static limit F_S + C_p|p| + a tau^beta, tau = time since the cylinder stuck
    (:func:`heavecomp.effects.terms.dwell_gain`; paper B: "static friction grows
    with the time at rest").
    """

    name = "dwell_stiction"
    Params = DwellParams
    states = ("tau",)
    log = ("gain",)
    term = "dwell_gain"

    @classmethod
    def write_ep(cls, values, EP):
        EP[T.DWELL_A_CAND] = values["gain"]
        EP[T.DWELL_BETA_CAND] = values["exponent"]


@dataclass(frozen=True)
class PressureFrictionParams:
    extra_pressure_coefficient: float = q(1e-3, "N/Pa", bounds=(1e-6, 0.05), symbol="dC_p",
                                          doc="seal friction added per pascal of cylinder pressure")


class PressureFriction(Candidate):
    """``pressure_friction``: seal friction grows with pressure, J += dC_p |p| (paper A eq. 4's C_p term)."""

    name = "pressure_friction"
    Params = PressureFrictionParams
    log = ("extra_pressure_coefficient",)
    term = "pressure_friction_fx"

    @classmethod
    def write_ep(cls, values, EP):
        EP[T.PF_DCP_CAND] = values["extra_pressure_coefficient"]


@dataclass(frozen=True)
class GasParams:
    effective_index: float = q(1.2, "-", bounds=(1.0, 1.67), symbol="n_eff", doc="effective polytropic index")
    loss_coefficient: float = q(1e4, "Pa s/m", bounds=(10.0, 1e7), symbol="c_g",
                                doc="pressure loss per unit stroke velocity (heat-exchange hysteresis)")


class GasHeatTransfer(Candidate):
    """``gas_heat_transfer``: neither a fixed polytropic index nor lossless.

    Effective polytropic p + p_atm = (p_0+p_atm)(V_0/(V_0 + A s))^{n_eff} plus a
    linear loss p -= c_g v (:func:`heavecomp.effects.terms.gas_pressure_fx`,
    :func:`heavecomp.effects.terms.line_drop`).
    """

    name = "gas_heat_transfer"
    Params = GasParams
    log = ("loss_coefficient",)
    term = "gas_pressure_fx, line_drop"

    @classmethod
    def write_ep(cls, values, EP):
        EP[T.GAS_N_CAND] = values["effective_index"]
        EP[T.GAS_LOSS_CAND] = values["loss_coefficient"]


@dataclass(frozen=True)
class FlowLossParams:
    resistance: float = q(3e4, "Pa s/m", bounds=(10.0, 1e7), symbol="R",
                          doc="line pressure drop per unit stroke velocity")


class FlowLoss(Candidate):
    """``flow_loss``: pressure drop between cylinder and gas bank, p_cyl = p_gas - R v (laminar line)."""

    name = "flow_loss"
    Params = FlowLossParams
    log = ("resistance",)
    term = "line_drop"

    @classmethod
    def write_ep(cls, values, EP):
        EP[T.FLOW_R_CAND] = values["resistance"]


@dataclass(frozen=True)
class StringDampingParams:
    damping: float = q(3e4, "N s/m", bounds=(10.0, 2e6), symbol="c", doc="extra drill-string damping")


class StringDamping(Candidate):
    """``string_damping``: a linear dashpot c (dz_h + v - v_b) added to the drill-string tension."""

    name = "string_damping"
    Params = StringDampingParams
    log = ("damping",)
    term = "string_damping_fx"

    @classmethod
    def write_ep(cls, values, EP):
        EP[T.SD_C_CAND] = values["damping"]


@dataclass(frozen=True)
class SensorDelayParams:
    delay: float = q(0.2, "s", bounds=(0.0, 3.0), symbol="t_d", doc="transport delay of the lagging channel")


class SensorDelay(Candidate):
    """``sensor_delay``: one measured channel lags the others by a pure delay t_d.

    y_meas(t) = y(t - t_d) for the channel that gains most (wob, stroke or
    pressure); the fitted ``channel`` is reported with the delay.
    """

    name = "sensor_delay"
    Params = SensorDelayParams
    kind = "output"
    term = "shift by linear interpolation"


#: nominal parameters refitted by ``parameter_mismatch``: (name in the report, table, key)
MISMATCH_KEYS = (("compensator.gas_stiffness", "compensator", "gas_stiffness"),
                 ("friction.static_force", "friction", "static_force"),
                 ("friction.coulomb_force", "friction", "coulomb_force"),
                 ("friction.viscous_coefficient", "friction", "viscous_coefficient"),
                 ("drill_string.stiffness", "drill_string", "stiffness"),
                 ("formation.stiffness", "formation", "stiffness"))


@dataclass(frozen=True)
class MismatchParams:
    gas_stiffness: float = q(1.0, "x nominal", bounds=(0.2, 5.0))
    static_force: float = q(1.0, "x nominal", bounds=(0.2, 5.0))
    coulomb_force: float = q(1.0, "x nominal", bounds=(0.2, 5.0))
    viscous_coefficient: float = q(1.0, "x nominal", bounds=(0.05, 20.0))
    drill_string_stiffness: float = q(1.0, "x nominal", bounds=(0.05, 5.0))
    formation_stiffness: float = q(1.0, "x nominal", bounds=(0.1, 10.0))


class ParameterMismatch(Candidate):
    """``parameter_mismatch``: no missing physics; the nominal parameters are off.

    Refits multipliers of six nominal parameters (:data:`MISMATCH_KEYS`); the
    report gives the refitted values and names those that moved.
    """

    name = "parameter_mismatch"
    Params = MismatchParams
    kind = "nominal"
    log = tuple(f.name for f in dataclasses.fields(MismatchParams))
    term = "nominal plant with refitted parameters"

    @classmethod
    def apply(cls, params, values):
        """The nominal parameter set with the multipliers applied (F_C clipped to <= F_S)."""
        mult = list(values.values())
        ch: dict = {}
        for (label, table, key), m in zip(MISMATCH_KEYS, mult):
            base = getattr(getattr(params, table), key)
            if base is None:
                continue
            ch.setdefault(table, {})[key] = base * m
        fr = ch.get("friction", {})
        if "static_force" in fr and "coulomb_force" in fr:
            fr["coulomb_force"] = min(fr["coulomb_force"], fr["static_force"])
        if params.friction.model == "none":
            ch.pop("friction", None)
        return params.replace(**ch)

    @classmethod
    def named_values(cls, params, values) -> dict:
        """Refitted values under their parameter-file names [SI]."""
        out = {}
        for (label, table, key), m in zip(MISMATCH_KEYS, values.values()):
            base = getattr(getattr(params, table), key)
            if base is not None:
                out[label] = float(base * m)
        return out


CANDIDATES = {c.name: c for c in (FrictionLag, DwellStiction, PressureFriction, GasHeatTransfer, FlowLoss,
                                  StringDamping, SensorDelay, ParameterMismatch)}
EFFECT_NAMES = tuple(CANDIDATES)


def get(name: str) -> type:
    """The candidate class for a contract effect name (ParameterError naming the known ones)."""
    try:
        return CANDIDATES[name]
    except KeyError:
        raise ParameterError(f"unknown effect {name!r}{did_you_mean(name, CANDIDATES)}; known: "
                             f"{', '.join(CANDIDATES)}") from None
