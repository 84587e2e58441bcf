"""Drilling-system log formats for the one reader (:mod:`heavecomp.io.series`): WITSML 1.4.1.1 ``log``
objects and LAS 2.0 files, indexed by time.

Contract: ``docs/contracts/measured-run.md`` (section *Drilling logs*).  A drilling data system hands
over channels by **mnemonic** (``HKLD``, ``WOB``, ...) in **rig units** (klbf, kkgf, ft, psi, ...).
This module turns such a file into the reader's table: one column per mnemonic, headed
``MNEMONIC [unit]`` so the reader's own unit table converts it (and records the conversion), and a
default mapping of mnemonics to contract columns (:data:`MNEMONICS`) that ``--columns`` /
``[measurement] columns`` override name by name.

- **WITSML 1.4.1.1** (``<logs><log>``, namespace ``http://www.witsml.org/schemas/1series``): read with
  the standard library's ``xml.etree.ElementTree``.  The channels are the ``logData``'s
  ``mnemonicList`` and ``unitList`` (falling back on each ``logCurveInfo``'s ``unit``), the rows its
  comma-separated ``data`` elements; the ``nullValue`` of the log or of a curve reads as a dropout.
  The index is the ``indexCurve``: ``indexType`` ``date time`` (ISO 8601 timestamps) or
  ``elapsed time`` (a number in its unit); a depth index is refused.  No library was adopted:
  ``komle-plus`` (the maintained fork of komle; last release 2024-03) pulls PyXB-X bindings, a SOAP
  client and 65 MB of generated schema classes to read what ElementTree reads in a page.
- **WITSML 2.0** channel sets are refused with a one-line hint (export 1.4.1.1 or LAS): no maintained,
  light Python library reads them (``energyml-witsml2-0`` is types without a reader; ``fesapi`` a
  SWIG binding for EPC/HDF5 packages).
- **LAS 2.0** through ``lasio`` (imported only for a LAS file; ``pip install 'heavecomp[logs]'``): the
  ``~Curve`` section's mnemonics and units, the ``~A`` data, ``NULL`` as dropouts; the first curve is
  the index, which must be time (``TIME``/``ETIM``... in s, ms, min or h), not depth.

Rows are named by their data row (first row: 1) in messages.
"""

from __future__ import annotations

import io
import re

import numpy as np

from heavecomp.errors import DataError

#: default mnemonic table: contract column -> mnemonics, first present wins (``--columns`` overrides).
#: What a crown-mounted compensator's log carries: the MRU's heave, the compensator's stroke (its
#: position) and cylinder pressure, the WOB and the hook load.  ``SPPA`` (standpipe pressure: the
#: mud pumps' pressure) and ``BPOS`` (block position: the travelling block's height from the
#: drawworks encoder) are not compensator channels and are never mapped by default; they are carried
#: along under their mnemonic (map one with ``--columns`` where a rig logs the compensator under it).
MNEMONICS = {
    "heave": ("HEAVE", "RIG_HEAVE", "RIGHEAVE", "MRU_HEAVE", "MRUHEAVE", "HEAV", "HVE"),
    "stroke": ("CMC_POS", "CMCPOS", "CMC_STROKE", "CMCSTRK", "CMC_STRK", "COMP_POS", "COMPPOS", "CMPS"),
    "pressure": ("CMC_PRES", "CMCPRES", "CMC_PRESS", "CMCP", "COMP_PRES", "COMPPRES", "CMPP"),
    "wob": ("WOB", "SWOB", "WOBA"),
    "hook_load": ("HKLD", "HKLA"),
    "pitch": ("PITCH", "PTCH", "RIG_PITCH"),
}
#: WITSML 1.4.1.1 index types read as time (the others are depths)
TIME_INDEX = ("date time", "elapsed time")
#: LAS index mnemonics that are depths
DEPTH_MNEMONICS = ("DEPT", "DEPTH", "MD", "TVD", "BDEP", "HDTH")
#: LAS index mnemonics that are elapsed time
TIME_MNEMONICS = ("TIME", "ETIM", "ETIME", "ELAPSED_TIME", "T")


def sniff(head: bytes) -> str | None:
    """``"witsml"``, ``"las"`` or None from the first (decompressed) bytes of a file.

    Parameters
    ----------
    head : bytes
        The file's first bytes (after decompression).
    """
    text = head[:4096].lstrip(b"\xef\xbb\xbf").lstrip()
    if text.startswith(b"<"):
        return "witsml"
    lines = [ln.strip() for ln in text.splitlines() if ln.strip() and not ln.strip().startswith(b"#")]
    if lines and lines[0][:2].upper() == b"~V":
        return "las"
    return None


def _tag(el) -> str:
    return el.tag.rsplit("}", 1)[-1] if isinstance(el.tag, str) else ""


def _child(el, name):
    return next((c for c in el if _tag(c) == name), None)


def _text(el, name, default=None):
    c = _child(el, name)
    return c.text.strip() if c is not None and c.text is not None else default


def _header(mnemonics, units) -> list:
    """``MNEMONIC [unit]`` headers (no brackets where the unit is empty or dimensionless)."""
    out = []
    for m, u in zip(mnemonics, units):
        u = (u or "").strip()
        out.append(m if not u or u.lower() in ("unitless", "none", "euc", "-", "n/a", "dimensionless")
                   else f"{m} [{u}]")
    return out


def witsml_table(raw: bytes, src: str, info: dict):
    """``(header, columns, rows, index mnemonic)`` of a WITSML 1.4.1.1 ``log`` (see the module docstring).

    Parameters
    ----------
    raw : bytes
        The file's (decompressed) content.
    src : str
        The file, for messages.
    info : dict
        The reader's ``measurement`` (gets ``format``, ``index_type``, ``log``).
    """
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(raw)
    except ET.ParseError as exc:
        raise DataError(f"{src}: not well-formed XML ({exc}); expected a WITSML 1.4.1.1 log") from None
    top = _tag(root)
    ns = root.tag[1:].split("}", 1)[0] if root.tag.startswith("{") else ""
    if top in ("ChannelSet", "Channel", "Log") and ("energistics" in ns or "witsmlv2" in ns.lower()) \
            or "witsmlv2" in ns.lower():
        raise DataError(f"{src}: a WITSML 2.0 {top}: not read (no maintained Python reader of channel sets); "
                        "export the log as WITSML 1.4.1.1 or LAS 2.0")
    logs = [root] if top == "log" else [c for c in root if _tag(c) == "log"] if top == "logs" else []
    if not logs:
        raise DataError(f"{src}: XML without a WITSML 1.4.1.1 log (root element <{top}>); expected <logs><log>")
    if len(logs) > 1:
        raise DataError(f"{src}: {len(logs)} WITSML log objects in one file; export one log per file")
    lg = logs[0]
    version = root.get("version") or "1.4.1.1"
    info.update(format=f"witsml {version}", log=lg.get("uid") or _text(lg, "name") or "")
    index_type = (_text(lg, "indexType") or "").lower()
    index = _text(lg, "indexCurve")
    info["index_type"] = index_type
    if index_type not in TIME_INDEX:
        raise DataError(f"{src}: column {index!r} (the WITSML index curve) is "
                        f"{index_type or 'of an undeclared index type'!r}: a time index is needed (date time or "
                        "elapsed time); export the log by time")
    curves = {}
    for ci in lg:
        if _tag(ci) == "logCurveInfo":
            m = _text(ci, "mnemonic")
            if m:
                curves[m] = (_text(ci, "unit"), _text(ci, "nullValue"))
    blocks = [c for c in lg if _tag(c) == "logData"]
    if not blocks:
        raise DataError(f"{src}: WITSML log without logData")
    mnemonics = units = None
    rows: list[str] = []
    for block in blocks:
        ml = _text(block, "mnemonicList")
        if ml is None:
            raise DataError(f"{src}: WITSML logData without a mnemonicList")
        mn = [m.strip() for m in ml.split(",")]
        ul = _text(block, "unitList")
        un = [u.strip() for u in ul.split(",")] if ul is not None else [curves.get(m, (None,))[0] for m in mn]
        if len(un) != len(mn):
            raise DataError(f"{src}: WITSML unitList has {len(un)} units for {len(mn)} mnemonics")
        if mnemonics is None:
            mnemonics, units = mn, un
        elif mn != mnemonics:
            raise DataError(f"{src}: WITSML logData blocks with different mnemonicLists; export one block")
        rows.extend(d.text or "" for d in block if _tag(d) == "data")
    if index is None:
        index = mnemonics[0]
    if index not in mnemonics:
        raise DataError(f"{src}: WITSML index curve {index!r} is not in the mnemonicList ({', '.join(mnemonics)})")
    if index_type == "date time":
        units[mnemonics.index(index)] = ""
    n = len(mnemonics)
    cells = []
    for k, r in enumerate(rows):
        c = r.split(",")
        if len(c) != n:
            raise DataError(f"{src}: WITSML data row {k + 1} has {len(c)} values, the mnemonicList {n}")
        cells.append(c)
    cols = [[row[j].strip() for row in cells] for j in range(n)]
    nulls = {lg_null.strip() for lg_null in [_text(lg, "nullValue")] if lg_null}
    for j, m in enumerate(mnemonics):
        null = nulls | ({curves[m][1]} if m in curves and curves[m][1] else set())
        if null:
            cols[j] = ["" if v in null else v for v in cols[j]]
    return _header(mnemonics, units), cols, np.arange(1, len(rows) + 1), index


def las_table(text: str, src: str, info: dict, unit_kind=lambda u: None):
    """``(header, columns, rows, index mnemonic)`` of a LAS 2.0 file read by ``lasio``.

    Parameters
    ----------
    text : str
        The file's text.
    src : str
        The file, for messages.
    info : dict
        The reader's ``measurement`` (gets ``format``).
    unit_kind : callable
        ``unit_kind(unit) -> kind or None`` (the reader's unit table: a length-indexed log is a depth log).
    """
    try:
        import lasio
    except ImportError:
        raise DataError(f"{src}: LAS files need lasio: pip install 'heavecomp[logs]'") from None
    try:
        las = lasio.read(io.StringIO(text), ignore_header_errors=False, engine="normal")
    except Exception as exc:  # noqa: BLE001 - lasio raises many types for a malformed file
        raise DataError(f"{src}: unreadable LAS file ({type(exc).__name__}: {str(exc).splitlines()[0][:80] if str(exc) else ''})") from None
    vers = str(las.version["VERS"].value) if "VERS" in las.version else "?"
    info["format"] = f"las {vers}"
    if not las.curves:
        raise DataError(f"{src}: LAS file without a ~Curve section")
    mnemonics = [c.mnemonic for c in las.curves]
    units = [c.unit for c in las.curves]
    index, iunit = mnemonics[0], (units[0] or "").strip()
    kind = unit_kind(iunit)
    if index.upper().split(":")[0] in DEPTH_MNEMONICS or kind == "length":
        raise DataError(f"{src}: column {index!r} (the LAS index curve, {iunit or 'no unit'}) is a depth: a time "
                        "index is needed; export the log by time")
    if index.upper().split(":")[0] not in TIME_MNEMONICS and kind != "time":
        raise DataError(f"{src}: column {index!r} (the LAS index curve, {iunit or 'no unit'}) is not a time; a time index "
                        f"({', '.join(TIME_MNEMONICS)} in s, ms, min or h) is needed")
    cols = []
    for c in las.curves:
        d = np.asarray(c.data)
        cols.append(np.asarray(d, dtype=float) if d.dtype.kind in "iuf" else [str(v) for v in d.tolist()])
    n = len(cols[0]) if cols else 0
    return _header(mnemonics, units), cols, np.arange(1, n + 1), index


def table(raw: bytes, kind: str, src: str, info: dict, decode, unit_kind):
    """The reader's ``(header, iterator of one (cols, rows), hints)`` of a drilling log: ``hints`` holds
    ``_mnemonics`` (contract name -> ``(header, mnemonic)`` of the default table, the index as ``t``).

    Parameters
    ----------
    raw : bytes
        The file's (decompressed) content.
    kind : str
        ``"witsml"`` or ``"las"`` (:func:`sniff`).
    src : str
        The file, for messages.
    info : dict
        The reader's ``measurement``.
    decode : callable
        ``decode(raw) -> str`` (the reader's text decoding, for LAS).
    unit_kind : callable
        ``unit_kind(unit) -> kind or None`` (the reader's unit table).
    """
    if kind == "witsml":
        header, cols, rows, index = witsml_table(raw, src, info)
    else:
        header, cols, rows, index = las_table(decode(raw), src, info, unit_kind)
    mn = [re.split(r"\s*\[", h, maxsplit=1)[0] for h in header]
    defaults = {"t": (header[mn.index(index)], index)}
    upper = {m.upper(): j for j, m in reversed(list(enumerate(mn)))}
    for name, table_ in MNEMONICS.items():
        hit = next((upper[m] for m in table_ if m in upper), None)
        if hit is not None:
            defaults[name] = (header[hit], mn[hit])
    return header, iter([(cols, rows)]), {"_mnemonics": defaults}


def mapping(defaults: dict, columns: dict, required, optional) -> tuple[dict, list]:
    """The column mapping of a drilling log: the default table's (:data:`MNEMONICS`, the index as ``t``)
    under the user's ``columns`` name by name, and one ``conversions`` line per contract column mapped.

    Parameters
    ----------
    defaults : dict
        Contract name -> ``(header, mnemonic)`` found by :func:`table`.
    columns : dict
        The user's mapping (contract name -> mnemonic or header), which wins.
    required, optional : tuple of str
        The contract names the caller reads.
    """
    out, notes = dict(columns), []
    taken = set(columns.values())
    for name in tuple(required) + tuple(optional):
        if name in columns:
            notes.append(f"mnemonic {columns[name]} -> {name} (mapped)")
        elif name in defaults and defaults[name][1] not in taken and defaults[name][0] not in taken:
            out[name] = defaults[name][0]
            what = "index curve" if name == "t" else "default mnemonic table"
            notes.append(f"mnemonic {defaults[name][1]} -> {name} ({what})")
    return out, notes


# ---------------------------------------------------------------- writers (test helpers, exports)
def _fmt(v) -> str:
    return "" if not np.isfinite(v) else f"{v:.9g}"


def write_witsml(path, channels: dict, units: dict, *, index: str = "TIME", start: str | None = None,
                 uid: str = "cmc-log", null: str | None = None) -> None:
    """Write a WITSML 1.4.1.1 ``log`` (one ``<logs><log>``, one ``logData``) of time-indexed channels.

    Parameters
    ----------
    path : str or Path
        File written.
    channels : dict of str to array
        Mnemonic -> values, the index first (elapsed time [``units[index]``]).
    units : dict of str to str
        Mnemonic -> unit as written (``unitList``, ``logCurveInfo/unit``).
    index : str
        The index curve's mnemonic (a key of ``channels``).
    start : str, optional
        ISO 8601 time of the first sample: the index is written as ``date time`` timestamps
        (``indexType`` date time); None: ``elapsed time`` in its unit.
    uid : str
        The log's uid.
    null : str, optional
        The log's ``nullValue`` (NaN written as it; None: NaN as an empty cell).
    """
    from pathlib import Path
    from xml.sax.saxutils import escape

    names = list(channels)
    t = np.asarray(channels[index], dtype=float)
    if start is not None:
        import pandas as pd

        scale = {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}[units.get(index, "s")]
        stamps = (pd.Timestamp(start) + pd.to_timedelta(np.round(t * scale * 1e6).astype("int64"), unit="us"))
        idx = [s.isoformat(timespec="microseconds") for s in stamps]
    cols = [np.asarray(channels[m], dtype=float) for m in names]
    ns = "http://www.witsml.org/schemas/1series"
    out = [f'<?xml version="1.0" encoding="UTF-8"?>', f'<logs xmlns="{ns}" version="1.4.1.1">',
           f'  <log uidWell="w1" uidWellbore="wb1" uid="{escape(uid)}">', "    <nameWell>heavecomp</nameWell>",
           "    <nameWellbore>heavecomp</nameWellbore>", f"    <name>{escape(uid)}</name>",
           f"    <indexType>{'date time' if start is not None else 'elapsed time'}</indexType>",
           f"    <indexCurve>{escape(index)}</indexCurve>"]
    if null is not None:
        out.append(f"    <nullValue>{escape(null)}</nullValue>")
    unit_of = {m: ("" if (m == index and start is not None) else units.get(m, "")) for m in names}
    for m in names:
        out.append(f'    <logCurveInfo uid="{escape(m)}"><mnemonic>{escape(m)}</mnemonic>'
                   + (f"<unit>{escape(unit_of[m])}</unit>" if unit_of[m] else "")
                   + f"<typeLogData>{'date time' if (m == index and start is not None) else 'double'}</typeLogData>"
                   "</logCurveInfo>")
    out.append("    <logData>")
    out.append(f"      <mnemonicList>{escape(','.join(names))}</mnemonicList>")
    out.append(f"      <unitList>{escape(','.join(unit_of[m] for m in names))}</unitList>")
    nul = "" if null is None else null
    for i in range(t.size):
        cells = [idx[i] if (m == index and start is not None) else
                 (_fmt(c[i]) if np.isfinite(c[i]) else nul) for m, c in zip(names, cols)]
        out.append(f"      <data>{','.join(cells)}</data>")
    out += ["    </logData>", "  </log>", "</logs>", ""]
    Path(path).write_text("\n".join(out), encoding="utf-8")


def write_las(path, channels: dict, units: dict, *, index: str = "TIME", null: float = -999.25,
              well: str = "heavecomp") -> None:
    """Write a LAS 2.0 file of time-indexed channels (the index first, elapsed time in its unit).

    Parameters
    ----------
    path : str or Path
        File written.
    channels : dict of str to array
        Mnemonic -> values; the index is ``channels[index]``.
    units : dict of str to str
        Mnemonic -> unit as written in the ``~Curve`` section.
    index : str
        The index curve's mnemonic.
    null : float
        The ``NULL`` value NaN is written as.
    well : str
        The ``WELL`` entry.
    """
    from pathlib import Path

    names = [index] + [m for m in channels if m != index]
    cols = [np.asarray(channels[m], dtype=float) for m in names]
    t = cols[0]
    iu = units.get(index, "s")
    out = ["~Version information", " VERS.   2.0 : CWLS LOG ASCII STANDARD - VERSION 2.0",
           " WRAP.   NO  : One line per index step", "~Well information",
           f" STRT.{iu} {t[0]:.9g} : START", f" STOP.{iu} {t[-1]:.9g} : STOP",
           f" STEP.{iu} {(t[1] - t[0]) if t.size > 1 else 0:.9g} : STEP", f" NULL.   {null:g} : NULL VALUE",
           f" WELL.   {well} : WELL", "~Curve information"]
    for m in names:
        out.append(f" {m}.{units.get(m, '')} : {m}")
    out.append("~A " + " ".join(names))
    for i in range(t.size):
        out.append(" ".join(f"{c[i]:.9g}" if np.isfinite(c[i]) else f"{null:g}" for c in cols))
    out.append("")
    Path(path).write_text("\n".join(out), encoding="utf-8")
