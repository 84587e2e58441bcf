"""The candidates the gap diagnosis fits, with the contract's names.

Every registered effect marked ``candidate`` (:mod:`heavecomp.effects.registry`; one class per
file, its terms at the plant's hooks) is a candidate, plus ``parameter_mismatch``, which is no missing physics but the
nominal parameters being off (``kind = "nominal"``).  The withheld-effect generator
(:mod:`heavecomp.benchmark`) brings its own truth laws, never these.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect, FitSpec
from heavecomp.effects.features import need
from heavecomp.friction.laws import stribeck_excess
from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.params.core import q
from heavecomp.effects.registry import library


#: nominal parameters refitted by ``parameter_mismatch``: (name in the report, table, key)
MISMATCH_KEYS = (("compensator.gas_stiffness", "compensator", "gas_stiffness"),
                 ("friction.static_force", "friction", "static_force"),
                 ("friction.coulomb_force", "friction", "coulomb_force"),
                 ("friction.viscous_coefficient", "friction", "viscous_coefficient"),
                 ("drill_string.stiffness", "drill_string", "stiffness"),
                 ("formation.stiffness", "formation", "stiffness"),
                 ("compensator.moving_mass", "compensator", "moving_mass"))


@dataclass(frozen=True)
class MismatchParams:
    gas_stiffness: float = q(1.0, "x nominal", bounds=(0.2, 5.0))
    static_force: float = q(1.0, "x nominal", bounds=(0.2, 5.0))
    coulomb_force: float = q(1.0, "x nominal", bounds=(0.2, 5.0))
    viscous_coefficient: float = q(1.0, "x nominal", bounds=(0.05, 20.0))
    drill_string_stiffness: float = q(1.0, "x nominal", bounds=(0.05, 5.0))
    formation_stiffness: float = q(1.0, "x nominal", bounds=(0.1, 10.0))
    # a top mass is known to maybe +-30 % (crown block, travelling block, top drive, what hangs on them)
    moving_mass: float = q(1.0, "x nominal", bounds=(0.5, 2.0))


class ParameterMismatch(Effect):
    """``parameter_mismatch``: no missing physics; the nominal parameters are off.

    Refits multipliers of the nominal parameters in :data:`MISMATCH_KEYS`, releasing them
    stepwise (:func:`heavecomp.diagnosis.fitting.stepwise`: those not released stay at 1); the
    report gives the refitted values and names those that moved.

    The top mass M_c is refitted as a rig runs a heavier one: at the driller's WOB set-point (the
    parameter set derives the charge p_0 = ((M_c + m_b) g - W_0) / A from the masses) in the same gas
    bank (:meth:`bank_held`: the gas volume V_0 is the file's, so k_gas rises with the absolute charge).
    The gas stiffness's multiplier scales the bank alone (V_0 / m).
    """

    name = "parameter_mismatch"
    hook = "nominal"
    Params = MismatchParams
    kind = "nominal"
    fit = FitSpec(
        log=tuple(f.name for f in dataclasses.fields(MismatchParams)),
        # multipliers whose fit cost is rugged (stick-slip timing jumps with the breakaway force): the
        # diagnosis scans them over their search box for a second start (heavecomp.diagnosis.fitting.rescan)
        rugged=("static_force",),
        # Stribeck velocities v_S [m/s] searched by the equation-error fit
        feature_grid=tuple(np.geomspace(1e-3, 0.1, 13)),
        # name and unit of the equation-error shape parameter
        feature_shape=("friction.stribeck_velocity", "m/s"),
        # units of the feature coefficients [SI]
        feature_units={"friction.coulomb_force": "N", "friction.viscous_coefficient": "N s/m",
                       "friction.static_force": "N", "friction.stribeck_velocity": "m/s"},
    )

    @classmethod
    def features(cls, sig, shape=None):
        """The nominal friction law's own regressors (paper A eq. 4 without C_p), named by their
        parameter-file keys: ``friction.coulomb_force`` sign(v) [-], ``friction.viscous_coefficient``
        v [m/s] and ``friction.static_force`` exp(-|v|/v_S) sign(v) [-] (coefficient F_S - F_C [N];
        ``shape`` is v_S [m/s]).

        Notes
        -----
        On a component residual (measured minus nominal friction) a coefficient is how far the
        nominal value is off: a term the nominal lacks comes back as its value.  A plant whose base
        columns already hold one of these parameters drops that column (same name).
        """
        if not need(sig, "v"):
            return None
        v = np.asarray(sig["v"], dtype=float)
        return {"friction.coulomb_force": np.sign(v), "friction.viscous_coefficient": v,
                "friction.static_force": stribeck_excess(np.abs(v), 1.0, 0.0, float(shape)) * np.sign(v)}

    @staticmethod
    def bank_held(params, mass) -> float:
        """The factor on k_gas that holds ``params``' gas volume V_0 when the top mass is ``mass`` [kg]
        at the same WOB set-point: k_gas = n (p_0 + p_atm) A^2 / V_0 with p_0 following the mass
        (:attr:`heavecomp.params.CMCParams.gas_volume`), i.e. (p_0' + p_atm) / (p_0 + p_atm) [-]; 1 at
        the file's mass."""
        if mass == params.compensator.moving_mass:
            return 1.0
        return params.replace(compensator={"moving_mass": mass}).gas_volume / params.gas_volume

    @classmethod
    def apply(cls, params, values):
        """The nominal parameter set with the multipliers applied (F_C clipped to <= F_S; a moved top
        mass in the same gas bank, :meth:`bank_held`)."""
        named = cls.named_values(params, values)
        ch: dict = {}
        for label, table, key in MISMATCH_KEYS:
            if label in named:
                ch.setdefault(table, {})[key] = named[label]
        fr = ch.get("friction", {})
        if "static_force" in fr and "coulomb_force" in fr:
            fr["coulomb_force"] = min(fr["coulomb_force"], fr["static_force"])
        if params.friction.model == "none":
            ch.pop("friction", None)
        return params.replace(**ch)

    @classmethod
    def search_box(cls, params):
        """The multipliers' bounds on ``params``, anchored to its ``[anchor]`` values when it has them (a
        calibrated file whose refit moved the nominal values: :class:`heavecomp.params.cmc.Anchor`).

        The multipliers scale the file's values, so a box of 0.2-5 x about a file that is itself a refit
        lets every re-diagnosis step another 5 x (a drift refitted as a constant: 23 -> 4.6 -> 0.92 kN).
        Anchored, the box is 0.2-5 x of the first file's value, written as multipliers of this file's
        (each widened to hold 1: the file's own value stays a valid start).
        """
        lo, hi = cls.bounds_x()
        anchor = params.extra.get("anchor") if params is not None else None
        if anchor is None:
            return lo, hi
        for j, (f, (_, table, key)) in enumerate(zip(cls.fields(), MISMATCH_KEYS)):
            a, base = getattr(anchor, f.name, None), getattr(getattr(params, table), key)
            if not a or not base:
                continue
            shift = np.log(a / base) if f.name in cls.fit.log else 0.0
            lo[j], hi[j] = min(lo[j] + shift, 0.0), max(hi[j] + shift, 0.0)
        return lo, hi

    @classmethod
    def anchor_of(cls, params) -> dict:
        """The ``[anchor]`` table a calibrated file of ``params`` carries: ``params``' own anchor where it
        has one, else its values of the refitted parameters (the first file's)."""
        old = params.extra.get("anchor")
        out = {}
        for f, (_, table, key) in zip(cls.fields(), MISMATCH_KEYS):
            v = getattr(old, f.name, None) if old is not None else None
            v = getattr(getattr(params, table), key) if v is None else v
            if v is not None:
                out[f.name] = float(v)
        return out

    @classmethod
    def effective(cls, params, values) -> dict:
        """The same model with the clip written into the multipliers: F_C's multiplier lowered to
        what :meth:`apply` uses (min(F_C, F_S)).  A scan of F_S then keeps the fitted Coulomb force
        instead of releasing a clipped, meaningless one."""
        out = dict(values)
        fs, fc = params.friction.static_force, params.friction.coulomb_force
        if fs and fc:
            out["coulomb_force"] = min(values["coulomb_force"], values["static_force"] * fs / fc)
        return out

    @classmethod
    def named_values(cls, params, values) -> dict:
        """Refitted values under their parameter-file names [SI] (a moved top mass's gas stiffness in
        the same gas bank, as :meth:`apply`)."""
        out = {}
        for (label, table, key), m in zip(MISMATCH_KEYS, values.values()):
            base = getattr(getattr(params, table), key)
            if base is not None:
                out[label] = float(base * m)
        if out.get("compensator.moving_mass", params.compensator.moving_mass) != params.compensator.moving_mass:
            out["compensator.gas_stiffness"] *= cls.bank_held(params, out["compensator.moving_mass"])
        return out


def _candidates() -> dict:
    return {**{n: c for n, c in library().items() if c.fit.candidate}, ParameterMismatch.name: ParameterMismatch}


#: every candidate the diagnosis fits: the registered effects marked ``candidate`` plus ``parameter_mismatch``
CANDIDATES = _candidates()
EFFECT_NAMES = tuple(CANDIDATES)


def get(name: str) -> type:
    """The class of an effect the diagnosis can fit, by name: a candidate, or any other registered effect
    (:mod:`heavecomp.effects.registry`, e.g. ``charge_drift``); ParameterError naming the known ones.

    Parameters
    ----------
    name : str
        Effect name (e.g. ``"dwell_stiction"``, ``"parameter_mismatch"``).
    """
    known = _known()
    try:
        return known[name]
    except KeyError:
        raise ParameterError(f"unknown effect {name!r}{did_you_mean(name, known)}; known: "
                             f"{', '.join(known)}") from None


def _known() -> dict:
    """name -> class of every effect :func:`get` knows: the candidates and the registered effects."""
    return {**CANDIDATES, **library()}


# ------------------------------------------------------------------ families of laws (issue 30 item 4)
def family_of(name) -> str:
    """The contract's name an effect is reported under: its ``fit.family`` (``friction_memory`` ->
    ``friction_lag``), else the name itself; a channel effect's ``name:channel`` keeps its channel; a name
    that is no effect (``none``, ``inconclusive``, a truth label) is returned as it is.

    Parameters
    ----------
    name : str
        An effect name (``"friction_memory"``, ``"sensor_gain:wob"``) or a verdict word.
    """
    if not isinstance(name, str):
        return name
    base, sep, channel = name.partition(":")
    cls = _known().get(base)
    fam = (cls.fit.family if cls is not None else "") or base
    return fam + sep + channel


def law_of(name) -> str:
    """The law an effect is of its family (``fit.law``: ``"time"``, ``"distance"``), "" when it has none.

    Parameters
    ----------
    name : str
        An effect name.
    """
    cls = _known().get(str(name).partition(":")[0])
    return cls.fit.law if cls is not None else ""


def same_family(a, b) -> bool:
    """Two effect names of one contract class (:func:`family_of`): rivals never, two laws of one answer.

    Parameters
    ----------
    a, b : str
        Effect names.
    """
    return family_of(a) == family_of(b)


def by_family(names) -> list:
    """``names`` with only the first of each family kept, in order (the members that stand for their
    family: the better law first where ``names`` is best first).

    Parameters
    ----------
    names : iterable of str
        Effect names.
    """
    seen, out = set(), []
    for n in names:
        f = family_of(n)
        if f not in seen:
            seen.add(f)
            out.append(n)
    return out
