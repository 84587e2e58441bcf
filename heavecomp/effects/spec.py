"""``[[effects]]`` of a parameter file, checked against the effect classes; plant and reading effects.

The params layer keeps the file's ``[[effects]]`` as raw ``(name, {parameter: value})`` specs
(:mod:`heavecomp.params.effects`: it sits below the effects and cannot know them).  This module, in
the effects layer, is where they become effects, strictly, like every other key of the file:

- an unknown effect or parameter is a :class:`~heavecomp.errors.ParameterError` with a "did you mean";
- every parameter is checked against its ``q()`` field (number, finite, bounds, unit in the message);
- a channel effect (``sensor_gain``, ``sensor_offset``, ``sensor_delay``) must name its ``channel``
  (one of :data:`heavecomp.effects.base.SENSOR_CHANNELS`); an effect without one must not;
- a parameter may be left out only where the effect lists it as ``optional`` (it is then at its
  null value, e.g. ``sensor_offset.drift = 0``); every other one is required.

Who calls it: every command reads a parameter file with :func:`load` (``heavecomp.params.load`` plus
:func:`check`), so a bad ``[[effects]]`` entry fails before any work; the API entries that use the
effects (``simulate``, ``linearise``, the closed loop, ``load_run``) resolve ``params.effects`` with
the same :func:`check` at their start.

What the effects mean in a file: **plant** effects (``kind = "plant"``: terms at the plant's hooks)
change the model every command simulates, linearises or controls.  **Reading** effects (a channel
effect or ``heave_reference``) say how the rig's sensors misread; they do not change the plant:
:func:`correct` undoes them when a measured log is read (:func:`heavecomp.diagnosis.data.load_run`),
so the plant stays right and the log is read right.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from heavecomp.effects.base import ChannelEffect, Effect, HeaveEffect, SENSOR_CHANNELS
from heavecomp.effects.discovered_term import DiscoveredTerm
from heavecomp.effects.hook_term import BY_COMPONENT as HOOK_TERMS
from heavecomp.effects.sensor_lag import SensorLag
from heavecomp.effects.sensor_term import SensorTerm
from heavecomp.effects.registry import library, resolve
from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.params import load as load_params
from heavecomp.params.core import check_value


def classes() -> dict:
    """name -> effect class of every effect a parameter file may name: the registry's, plus
    the open search's terms (not candidates, not registered; in the superset composition compiled at install): ``discovered_term`` at the
    seal-friction hook, ``line_term``, ``gas_term``, ``string_term`` at the line, gas-spring and string
    hooks (:mod:`heavecomp.effects.hook_term`) and ``sensor_term`` on a channel's reading; and the calibrated
    model's ``sensor_lag`` (a reading with its own dynamics, :mod:`heavecomp.effects.sensor_lag`)."""
    return {**library(), DiscoveredTerm.name: DiscoveredTerm, SensorTerm.name: SensorTerm, SensorLag.name: SensorLag,
            **{c.name: c for c in HOOK_TERMS.values()}}


def build(name: str, values: dict, where: str = "effects") -> Effect:
    """One effect instance from a file entry, checked strictly (see the module docstring).

    ``where`` prefixes the messages (``effects[0]``).

    Parameters
    ----------
    name : str
        The effect's name (a key of :func:`classes`).
    values : dict
        Its parameters from the file (SI), with ``channel`` for a channel effect.
    where : str
        Prefix of the error messages (the entry's place in the file).
    """
    lib = classes()
    if name not in lib:
        raise ParameterError(f"{where}.name = {name!r}: unknown effect{did_you_mean(name, lib)}; known: "
                             f"{', '.join(lib)}")
    cls = lib[name]
    if getattr(cls, "kind", "plant") == "nominal":  # pragma: no cover - no registered effect is one
        raise ParameterError(f"{where}.name = {name!r}: a refit of the nominal parameters; write the values into "
                             "their tables instead")
    values = dict(values)
    fields = {f.name: f for f in cls.fields()}
    channel = values.pop("channel", None)
    if issubclass(cls, ChannelEffect):
        if channel is None:
            raise ParameterError(f"{where}.channel: missing required key for effect {name!r} (one of "
                                 f"{', '.join(SENSOR_CHANNELS)})")
        if channel not in SENSOR_CHANNELS:
            raise ParameterError(f"{where}.channel = {channel!r}: not a measured channel"
                                 f"{did_you_mean(channel, SENSOR_CHANNELS)}; channels: {', '.join(SENSOR_CHANNELS)}")
    elif channel is not None:
        raise ParameterError(f"{where}.channel: effect {name!r} acts on no channel (it is a "
                             f"{'heave input' if issubclass(cls, HeaveEffect) else 'plant'} effect); remove the key")
    for key in values:
        if key not in fields:
            known = list(fields) + (["channel"] if issubclass(cls, ChannelEffect) else [])
            raise ParameterError(f"{where}.{key}: unknown parameter of effect {name!r}{did_you_mean(key, known)}; "
                                 f"parameters: {', '.join(known)}")
    null = cls.null(None) if cls.optional else {}
    checked = {}
    for key, f in fields.items():
        if key in values:
            checked[key] = check_value(f"{where}.{key}", f, values[key])
        elif key in cls.optional and key in (null or {}):
            checked[key] = null[key]
        else:
            unit = f.metadata.get("unit", "")
            raise ParameterError(f"{where}.{key}: missing required key of effect {name!r}"
                                 + (f" [{unit}]" if unit and unit != "-" else ""))
    for key in ("factor", "scale"):  # a reading of zero carries nothing: there is no misreading to undo
        if checked.get(key) == 0.0 and issubclass(cls, (ChannelEffect, HeaveEffect)):
            what = ("the compensator would see no heave motion at all" if issubclass(cls, HeaveEffect) else
                    f"the {channel} channel would read 0 whatever the rig does (a dead sensor is a missing column)")
            raise ParameterError(f"{where}.{key} = 0: {what}; a reading's {key} is non-zero (1: read right)")
    try:
        e = cls(channel=channel, **checked) if issubclass(cls, ChannelEffect) else cls(**checked)
    except ParameterError as exc:  # the effect's own check across its values: said with the entry's place
        raise ParameterError(f"{where}: {exc}") from None
    e.where = where  # the entry's place in the file, for messages that come later (a channel the log lacks)
    return e


def check(params) -> list:
    """The effect instances of ``params.effects`` (a file's ``[[effects]]``), checked strictly.

    Parameters
    ----------
    params : CMCParams
        Parameters whose ``effects`` (the file's ``[[effects]]`` specs) are read.
    """
    out, seen = [], {}
    for i, (name, values) in enumerate(getattr(params, "effects", ())):
        e = build(name, values, f"effects[{i}]")
        key = (name, getattr(e, "channel", None))
        if key in seen:  # applied twice, a WOB gain of 1.08 read as 1.1664: one entry per effect (and channel)
            on = f" on {key[1]!r}" if key[1] else ""
            raise ParameterError(f"effects[{i}]: duplicates effects[{seen[key]}] ({name}{on}); one entry per effect"
                                 f"{' and channel' if key[1] else ''}: write the combined value in one entry")
        seen[key] = i
        if hasattr(e, "check_size"):  # a term bounded by the open search's range, not the rig's
            e.check_size(params, f"effects[{i}]")
        out.append(e)
    return out


def load(path, *, heave_file=True):
    """Read a parameter file (:func:`heavecomp.params.load`) and check its ``[[effects]]``: the
    commands' reader; one-line :class:`ParameterError` for any bad key, before any work.

    Parameters
    ----------
    path : str or Path
        The TOML parameter file.
    heave_file : bool
        As :func:`heavecomp.params.load`: False for a command that takes no heave from the file.

    Returns
    -------
    CMCParams
    """
    params = load_params(path, heave_file=heave_file)
    check(params)
    return params


def plant_effects(params) -> list:
    """The plant effects of ``params``' ``[[effects]]`` (the terms at the plant's hooks), checked.

    Parameters
    ----------
    params : CMCParams
        Parameters whose ``effects`` (the file's ``[[effects]]`` specs) are read.
    """
    return [e for e in check(params) if e.kind == "plant"]


def reading_effects(params) -> list:
    """The reading effects of ``params``' ``[[effects]]``: how the sensors misread (channel effects and
    ``heave_reference``), checked; :func:`correct` undoes them on a log.

    Parameters
    ----------
    params : CMCParams
        Parameters whose ``effects`` (the file's ``[[effects]]`` specs) are read.
    """
    return [e for e in check(params) if e.kind in ("output", "heave")]


def effects_for(params, effects=None) -> list:
    """The effect instances a model of ``params`` runs with: ``effects`` when given (instances, names or
    ``(name, values)`` pairs, :func:`heavecomp.effects.registry.resolve`), else the plant effects of the
    file's ``[[effects]]`` (its reading effects correct a log, not the plant: :func:`correct`).

    Parameters
    ----------
    params : CMCParams
        Parameters whose ``effects`` (the file's ``[[effects]]`` specs) are read.
    effects : sequence, optional
        Effects to run instead: instances, names or ``(name, values)`` pairs; None: the file's plant effects.
    """
    return plant_effects(params) if effects is None else resolve(effects)


def correct(effects, t, columns: dict) -> tuple[dict, list]:
    """Undo the reading effects ``effects`` (instances) on the measured ``columns`` at times ``t`` [s].

    A channel effect's reading is inverted on its channel (gain and offset exactly, a delay by shifting
    the channel back; its last t_d seconds become NaN, a dropout; ``sensor_lag``'s factor and delay only:
    its lag is read on the model side, the diagnosis' replay reads its prediction through it); ``heave_reference`` replaces the
    measured heave by the heave the compensator sees (``seen``, less the lever arm times the logged
    ``pitch`` when there is one).  Plant effects are ignored.

    Parameters
    ----------
    effects : sequence of Effect
        Effect instances (e.g. :func:`reading_effects`); plant effects among them are ignored.
    t : array_like [s]
        Time of each sample.
    columns : dict of str to array_like
        The measured channels by contract name (SI); not modified.

    Returns
    -------
    (columns, notes) : the corrected columns (a new dict) and one line per correction, for the record.
    """
    t = np.asarray(t, dtype=float)
    cols = dict(columns)
    notes = []
    for e in effects:
        if isinstance(e, ChannelEffect):
            if e.channel not in cols:
                raise ParameterError(f"{getattr(e, 'where', 'effects')} ({e.name}): channel {e.channel!r} is not in "
                                     "the log: remove the entry, or map the log's column to it")
            cols[e.channel] = e.undo_reading(t, np.asarray(cols[e.channel], dtype=float), cols)
            notes.append(f"{e.channel} corrected for {e!r}")
        elif isinstance(e, HeaveEffect):
            v = e.values
            z = np.asarray(cols["heave"], dtype=float)
            # by name: the lever arm is left out here (the angle term below applies it), so passed by
            # position the high-pass took its slot in ``seen`` and was dropped
            seen = e.seen(t, z, **{k: float(v[k]) for k in v if k not in e.angle_params})
            L = float(v.get("lever_arm", 0.0))
            if L:
                if "pitch" not in cols:
                    raise ParameterError(f"effect {e.name}: lever_arm = {L:g} m needs a logged 'pitch' column [rad]")
                s = np.sin(np.asarray(cols["pitch"], dtype=float))
                seen = seen - L * (s - s[np.flatnonzero(np.isfinite(s))[0]])
            cols["heave"] = seen
            notes.append(f"heave replaced by the heave the compensator sees, {e!r}")
    return cols, notes


def to_spec(effect: Effect) -> tuple:
    """``(name, {parameter: value})`` of an instance (with its ``channel``), for a parameter file.

    Parameters
    ----------
    effect : Effect
        The instance to write.
    """
    vals = {k: float(v) for k, v in effect.values.items()}
    if isinstance(effect, ChannelEffect):
        vals = {"channel": effect.channel, **vals}
    return effect.name, vals


def field_units(name: str) -> dict:
    """Parameter -> unit of the effect ``name`` (for comments and reports).

    Parameters
    ----------
    name : str
        The effect's name (a key of :func:`classes`).
    """
    return {f.name: f.metadata.get("unit", "") for f in dataclasses.fields(classes()[name].Params)}
