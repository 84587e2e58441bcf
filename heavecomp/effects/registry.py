"""The effect library: one line per effect (its module in :mod:`heavecomp.effects`).

Each module defines one :class:`heavecomp.effects.base.Effect` subclass and names it ``EFFECT``.
Adding an effect is one file plus one line here (``docs/DEVELOPING.md``).
"""

from __future__ import annotations

import importlib

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.effects.base import Effect

MODULES = (
    "friction_lag",
    "dwell_stiction",
    "pressure_friction",
    "gas_heat_transfer",
    "flow_loss",
    "line_inertia",
    "string_hysteresis",
    "string_damping",
    "sensor_delay",
    "charge_drift",
    "asymmetric_friction",
    "position_friction",
    "gas_leak",
    "sensor_gain",
    "sensor_offset",
    "heave_reference",
    "friction_memory",
    "gas_thermal",
)

_LIBRARY: dict = {}


def library() -> dict:
    """name -> Effect class of every registered effect, in registry order."""
    if not _LIBRARY:
        for mod in MODULES:
            cls = importlib.import_module(f"heavecomp.effects.{mod}").EFFECT
            _LIBRARY[cls.name] = cls
    return _LIBRARY


def effect_class(name: str) -> type:
    """The registered effect class of ``name`` (ParameterError naming the known ones).

    Parameters
    ----------
    name : str
        Registered effect name (e.g. ``"dwell_stiction"``).
    """
    lib = library()
    try:
        return lib[name]
    except KeyError:
        raise ParameterError(f"unknown effect {name!r}{did_you_mean(name, lib)}; known: {', '.join(lib)}") from None


def resolve(effects) -> list:
    """Effect instances from a list of instances, names (default parameters) or
    ``(name, {parameter: value})`` pairs.

    Parameters
    ----------
    effects : iterable or None
        Effect instances, names or classes (default parameters), or ``(name or class, {parameter:
        value [SI]})`` pairs; None: no effect.
    """

    out = []
    for e in effects or ():
        if isinstance(e, Effect):
            out.append(e)
        elif isinstance(e, str):
            out.append(effect_class(e)())
        elif isinstance(e, type) and issubclass(e, Effect):
            out.append(e())
        else:
            name, values = e
            cls = name if isinstance(name, type) else effect_class(name)
            out.append(cls(**values))
    return out


def split_effects(effects):
    """``(plant, heave, sensor)`` effects of the instances ``effects``: terms at the plant's hooks
    (the stepper), the heave the plant sees (``kind = "heave"``), the recorded channels
    (``kind = "output"``).  A nominal refit (``parameter_mismatch``) is no submodel: ParameterError.

    Parameters
    ----------
    effects : iterable of heavecomp.effects.base.Effect
        Effect instances.
    """
    out = {"plant": [], "heave": [], "output": []}
    for e in effects:
        if e.kind not in out:
            raise ParameterError(f"effect {e.name} is no submodel (kind {e.kind!r}): apply its parameters to the "
                                 "parameter set instead")
        out[e.kind].append(e)
    return out["plant"], out["heave"], out["output"]
