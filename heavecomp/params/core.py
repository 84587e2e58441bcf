"""Parameter machinery: fields that carry unit, bounds and symbol; strict parsing.

A parameter table is a frozen dataclass whose fields are declared with :func:`q`
(a number with unit and bounds) or :func:`choice` (a string from a fixed set).
:func:`from_table` builds one from a mapping (a TOML table) and raises
:class:`~heavecomp.errors.ParameterError` with a one-line message naming the
key for every problem: unknown key (with a "did you mean"), missing key, wrong
type, NaN/inf, value out of bounds.  There is no silent default: a field has a
default only where its metadata documents one.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Mapping

from heavecomp.errors import ParameterError, did_you_mean

G = 9.81  #: gravity [m/s^2] (contract value)
P_ATM = 101325.0  #: atmospheric pressure [Pa] (contract value)

_MISSING = dataclasses.MISSING


def q(default=_MISSING, unit: str = "-", *, bounds=(-math.inf, math.inf), symbol: str = "",
      doc: str = "", open_low: bool = False, integer: bool = False, why: str = "",
      unit_low: str = "", unit_high: str = ""):
    """A numeric parameter field.

    Parameters
    ----------
    default : float, optional
        Documented default; omit for a required key.
    unit : str
        SI unit shown in messages and docs.
    bounds : (float, float)
        Physically possible range (inclusive unless ``open_low``).
    symbol : str
        Symbol used in the papers (e.g. ``"F_S"``).
    doc : str
        One-line meaning of the key, with its default (the documentation rows, :func:`describe`).
    open_low : bool
        Lower bound is exclusive (e.g. masses must be > 0).
    integer : bool
        Value must be a whole number (e.g. a random seed).
    why : str
        Why the bounds are where they are (physical plausibility; shown in the docs).
    unit_low, unit_high : str
        The unit a value below / above the bounds was most likely written in
        (e.g. ``"kN"`` for a WOB of 98.1): the message asks "is it in kN?".
    """
    meta = dict(kind="number", unit=unit, bounds=bounds, symbol=symbol, doc=doc,
                open_low=open_low, integer=integer, why=why, unit_low=unit_low, unit_high=unit_high)
    if default is _MISSING:
        return dataclasses.field(metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def choice(options, default=_MISSING, *, doc: str = ""):
    """A string parameter restricted to ``options``.

    Parameters
    ----------
    options : iterable of str
        The allowed values.
    default : str, optional
        Documented default; omit for a required key.
    doc : str
        One-line meaning of the key (the documentation rows, :func:`describe`).
    """
    meta = dict(kind="choice", options=tuple(options), doc=doc, unit="", symbol="")
    if default is _MISSING:
        return dataclasses.field(metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def text(default=_MISSING, *, doc: str = ""):
    """A free string parameter (e.g. a file path).

    Parameters
    ----------
    default : str, optional
        Documented default; omit for a required key.
    doc : str
        One-line meaning of the key (the documentation rows, :func:`describe`).
    """
    meta = dict(kind="text", doc=doc, unit="", symbol="")
    if default is _MISSING:
        return dataclasses.field(metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def _fmt(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def unit_hint(meta: Mapping[str, Any], value: float) -> str:
    """``"; is it in kN? (SI: N)"`` for a value outside the bounds on a side with a likely unit.

    Parameters
    ----------
    meta : Mapping[str, Any]
        A numeric field's metadata (:func:`q`: ``bounds``, ``unit``, ``unit_low``, ``unit_high``).
    value : float [the field's SI unit]
        The value outside the bounds.
    """
    lo, hi = meta["bounds"]
    unit = meta.get("unit", "")
    likely = meta.get("unit_low") if 0 < value <= lo else meta.get("unit_high") if value > hi else ""
    if likely:
        return f"; is it in {likely}? (SI: {unit})"
    if unit not in ("-", "") and (value > hi or 0 < value < lo):
        return " (wrong unit?)"
    return ""


def check_value(name: str, f: dataclasses.Field, value: Any) -> Any:
    """Validate one value against its field metadata; return the normalised value.

    Parameters
    ----------
    name : str
        The key as the message names it (``table.key``).
    f : dataclasses.Field
        Its field, with the metadata of :func:`q`, :func:`choice` or :func:`text`.
    value : Any
        The value read from the file.
    """
    meta = f.metadata
    kind = meta.get("kind")
    if kind == "number":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"{name}: expected a number in {meta['unit']}, got {type(value).__name__} {value!r}")
        try:
            finite = math.isfinite(value)
        except OverflowError:  # an integer literal beyond any float
            raise ParameterError(f"{name}: must be finite, got an integer of {len(str(abs(value)))} digits") from None
        if not finite:
            raise ParameterError(f"{name}: must be finite, got {value}")
        if meta.get("integer") and float(value) != int(value):
            raise ParameterError(f"{name}: expected a whole number, got {value!r}")
        value = int(value) if meta.get("integer") else float(value)
        lo, hi = meta["bounds"]
        too_low = value <= lo if meta.get("open_low") else value < lo
        if too_low or value > hi:
            lo_s = ("(" if meta.get("open_low") else "[") + _fmt(lo)
            unit = meta["unit"]
            raise ParameterError(
                f"{name} = {_fmt(value)} {unit} is outside the possible range {lo_s}, {_fmt(hi)}] {unit}"
                + unit_hint(meta, value))
        return value
    if kind == "choice":
        if not isinstance(value, str) or value not in meta["options"]:
            raise ParameterError(
                f"{name} = {value!r} is not one of {', '.join(meta['options'])}{did_you_mean(value, meta['options'])}")
        return value
    if kind == "text":
        if not isinstance(value, str):
            raise ParameterError(f"{name}: expected a string, got {type(value).__name__} {value!r}")
        return value
    raise TypeError(f"field {name} has no parameter metadata")  # programming error


def from_table(cls, table: Mapping[str, Any] | None, prefix: str, *, required: set[str] | None = None):
    """Build the dataclass ``cls`` from a TOML table, strictly.

    ``required`` overrides which keys must be present (default: every field
    without a default).  Keys of ``cls`` that are not in ``required`` and have no
    default are filled with ``None`` (the caller documents when that is allowed).

    Parameters
    ----------
    cls : type
        A parameter table's dataclass (fields made by :func:`q`, :func:`choice`, :func:`text`).
    table : Mapping[str, Any] or None
        The TOML table (SI values); None: an empty table.
    prefix : str
        The table's name, prefixed to the keys in messages.
    required : set of str, optional
        Keys that must be present.
    """
    table = dict(table or {})
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in table:
        if key not in fields:
            raise ParameterError(f"{prefix}.{key}: unknown key{did_you_mean(key, fields)}; "
                                 f"known keys: {', '.join(fields)}")
    if required is None:
        required = {n for n, f in fields.items()
                    if f.default is _MISSING and f.default_factory is _MISSING}
    kwargs = {}
    for name, f in fields.items():
        full = f"{prefix}.{name}"
        if name in table:
            kwargs[name] = check_value(full, f, table[name])
        elif name in required:
            unit = f.metadata.get("unit", "")
            raise ParameterError(f"{full}: missing required key" + (f" [{unit}]" if unit and unit != "-" else ""))
        elif f.default is _MISSING:
            kwargs[name] = None
    return cls(**kwargs)


def to_table(obj) -> dict[str, Any]:
    """Dataclass -> plain dict (``None`` values dropped), for TOML output.

    Parameters
    ----------
    obj : dataclass instance
        A parameter table.
    """
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj) if getattr(obj, f.name) is not None}


def describe(cls) -> list[tuple[str, str, str, str, str]]:
    """(key, unit, symbol, default, doc) rows for documentation.

    Parameters
    ----------
    cls : type
        A parameter table's dataclass (fields made by :func:`q`, :func:`choice`, :func:`text`).
    """
    rows = []
    for f in dataclasses.fields(cls):
        m = f.metadata
        default = "required" if f.default is _MISSING else repr(f.default)
        rows.append((f.name, m.get("unit", ""), m.get("symbol", ""), default, m.get("doc", "")))
    return rows


def bounds_rows(cls, prefix: str) -> list[str]:
    """Markdown rows ``| key | unit | plausible range | why |`` of a parameter table's numeric fields (docs).

    Parameters
    ----------
    cls : type
        A parameter table's dataclass (fields made by :func:`q`, :func:`choice`, :func:`text`).
    prefix : str
        The table's name, prefixed to the keys (empty: bare keys).
    """
    rows = []
    for f in dataclasses.fields(cls):
        m = f.metadata
        if m.get("kind") != "number":
            continue
        lo, hi = m["bounds"]
        rng = ("(" if m.get("open_low") else "[") + f"{_fmt(lo)}, {_fmt(hi)}]"
        key = f"{prefix}.{f.name}" if prefix else f.name
        rows.append(f"| `{key}` | {m['unit']} | {rng} | {m.get('why', '')} |")
    return rows


def read_text(path, what: str = "parameter file") -> str:
    """A user's text file (UTF-8, a UTF-8 byte-order mark is dropped), or a one-line
    :class:`ParameterError` naming it and, for other encodings, where and what they are.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file is, for messages (e.g. ``"parameter file"``).
    """
    from pathlib import Path

    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise ParameterError(f"{path}: {what} not found") from None
    except (IsADirectoryError, PermissionError, OSError) as exc:
        raise ParameterError(f"{path}: cannot read {what} ({type(exc).__name__})") from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")) or (len(raw) > 1 and (raw[0] == 0) != (raw[1] == 0)):
        raise ParameterError(f"{path}: {what} is UTF-16 encoded; save it as UTF-8 (TOML files are UTF-8)")
    if raw.startswith(b"\xef\xbb\xbf"):  # a BOM some editors write: harmless, dropped
        raw = raw[3:]
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        col = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ParameterError(f"{path}: {what} is not UTF-8 (byte 0x{raw[exc.start]:02x} at line {line}, column {col}; "
                             f"latin-1/Windows text?); save it as UTF-8") from None


def toml_error_message(text_: str, exc: Exception, source: str) -> str:
    """One line for a TOML syntax error: the file, the key (``table.key``) on the offending line, the parser's
    message and, for ``0,72``, the hint that TOML numbers use a decimal point.

    Parameters
    ----------
    text_ : str
        The TOML text that failed to parse.
    exc : Exception
        The parser's error (``tomllib.TOMLDecodeError`` or ``ValueError``).
    source : str
        Name of the text in the message (the file's path).
    """
    import re

    msg = str(exc)
    lines = text_.splitlines()
    m = re.search(r"at line (\d+)", msg)
    if m is None and "digits" in msg:  # int() refused a huge literal: no position in the message
        msg = "an integer literal of more than 4300 digits"
        m = next((re.match(r"(\d+)", str(i + 1)) for i, ln in enumerate(lines) if re.search(r"\d{4301}", ln)), None)
    where, hint = "", ""
    if m:
        n = int(m.group(1))
        line = lines[n - 1] if 0 < n <= len(lines) else ""
        table = ""
        for prev in lines[:n]:
            h = re.match(r"\s*\[+\s*([^\]]*?)\s*\]", prev)
            if h:
                table = h.group(1)
        k = re.match(r"\s*([A-Za-z0-9_\-]+)\s*=", line)
        if k:
            where = f" at {table + '.' if table else ''}{k.group(1)}"
        if re.search(r"=\s*[-+]?\d+,\d", line):
            hint = " (a decimal comma? TOML numbers use a point, e.g. 0.72)"
    return f"{source}: not valid TOML{where}: {msg}{hint}"


def dump_toml(tables: Mapping[str, Mapping[str, Any]], header: str = "") -> str:
    """Write nested ``{table: {key: value}}`` as TOML (numbers, strings, bools).

    Parameters
    ----------
    tables : Mapping[str, Mapping[str, Any]]
        Table name -> key -> value (SI).
    header : str
        Comment lines put at the top (empty: none).
    """
    out = [f"# {line}" if line else "#" for line in header.splitlines()] if header else []
    for tname, table in tables.items():
        if out:
            out.append("")
        out.append(f"[{tname}]")
        for key, value in table.items():
            if isinstance(value, bool):
                s = "true" if value else "false"
            elif isinstance(value, int):
                s = str(value)
            elif isinstance(value, float):
                s = repr(value)
            elif isinstance(value, str):
                s = '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
            elif isinstance(value, Mapping) and all(isinstance(v, str) for v in value.values()):
                # inline table of strings ([measurement] columns / units)
                s = "{ " + ", ".join(f'{k} = "' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
                                     for k, v in value.items()) + " }"
            else:
                raise TypeError(f"cannot write {tname}.{key} of type {type(value).__name__} to TOML")
            out.append(f"{key} = {s}")
    return "\n".join(out) + "\n"
