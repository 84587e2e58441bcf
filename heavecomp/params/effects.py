"""``[[effects]]``: effects in the parameter file, as the params layer keeps them (raw specs).

An array of tables, one per effect, in SI units; ``name`` is a registered effect
(:mod:`heavecomp.effects.registry`), the other keys its parameters, and a channel effect names its
``channel``::

    [[effects]]
    name = "string_damping"
    damping = 4.7e4            # N s/m

    [[effects]]
    name = "sensor_gain"
    channel = "wob"
    factor = 1.08

Layers: this module sits in the params layer, *below* the effects, so it checks the shape only
(an array of tables, a string ``name``, numbers or strings as values) and keeps each entry as
``(name, {parameter: value})`` in :attr:`heavecomp.params.CMCParams.effects`.  Whether the name is
a registered effect, whether its parameters exist and are within their bounds and whether a
channel is one of the measured channels is checked by the effects layer
(:func:`heavecomp.effects.spec.check`), which owns the effect classes; every command reads the
file through :func:`heavecomp.effects.spec.load` and every API entry that uses the effects
(``simulate``, ``linearise``, the closed loop, ``load_run``) resolves them with the same strict
check before any work.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

from heavecomp.errors import ParameterError
from heavecomp.params.core import dump_toml

#: the key of an entry that names the effect (every other key is a parameter of it)
NAME = "name"


def parse(value: Any) -> tuple:
    """The ``[[effects]]`` array of a parsed TOML file -> ``((name, {key: value}), ...)``.

    Raises :class:`ParameterError` (one line naming ``effects[i]`` and the key) for a value that is
    not an array of tables, an entry without a string ``name``, or a value that is neither a finite
    number nor a string.
    """
    if isinstance(value, Mapping):
        raise ParameterError("effects: expected an array of tables [[effects]] (one per effect), got a table "
                             "[effects]; write [[effects]] with two brackets")
    if not isinstance(value, (list, tuple)):
        raise ParameterError(f"effects: expected an array of tables [[effects]], got a {type(value).__name__}")
    out = []
    for i, entry in enumerate(value):
        where = f"effects[{i}]"
        if not isinstance(entry, Mapping):
            raise ParameterError(f"{where}: expected a table with a name and the effect's parameters, "
                                 f"got a {type(entry).__name__}")
        name = entry.get(NAME)
        if name is None:
            raise ParameterError(f"{where}.{NAME}: missing required key (the effect, e.g. \"string_damping\")")
        if not isinstance(name, str):
            raise ParameterError(f"{where}.{NAME}: expected a string, got {type(name).__name__} {name!r}")
        values = {}
        for key, v in entry.items():
            if key == NAME:
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                raise ParameterError(f"{where}.{key}: expected a number (SI) or a string, got {type(v).__name__} {v!r}")
            if isinstance(v, (int, float)):
                try:
                    ok = math.isfinite(v)
                except OverflowError:
                    ok = False
                if not ok:
                    raise ParameterError(f"{where}.{key}: must be finite, got {v!r}")
                v = float(v)
            values[key] = v
        out.append((name, values))
    return tuple(out)


def to_tables(specs) -> list[dict]:
    """``[{name: ..., key: value}, ...]`` of raw specs (for TOML output and ``to_dict``)."""
    return [{NAME: name, **dict(values)} for name, values in specs]


def dump(specs) -> str:
    """TOML text of the ``[[effects]]`` array (empty string for no effects)."""
    out = []
    for table in to_tables(specs):
        body = dump_toml({"effects": table}).split("\n", 1)[1]  # the keys, without the [effects] header
        out.append("[[effects]]\n" + body)
    return "\n".join(out)
