"""One reader for every measured series: measured runs, heave files, identification data.

Contract: ``docs/contracts/measured-run.md``.  A file in any reasonable shape is read
into named float columns in SI units, and *how* it was read is recorded
(``Series.measurement``: format, delimiter, decimal mark, which source column became
which contract column, the units and every conversion applied), so a result can say
exactly what it was computed from.

Formats, recognised by content (magic bytes), not by the file name:

- text CSV in UTF-8 (with or without a byte-order mark) or, failing that, Latin-1
  (with a warning); any delimiter among ``, ; TAB |`` or runs of spaces; a decimal
  comma; any header case and spacing, units in the header (``Time [s]``, ``wob (kN)``,
  ``pressure_bar``); a file without a header (columns named ``1``, ``2``, ...);
- the same compressed: gzip, bzip2, xz, zip (one member);
- Parquet (pyarrow), MATLAB .mat up to v7 (scipy.io; v7.3/HDF5 is refused with a hint).

Logs of any length are read in chunks (:func:`iter_chunks`; :func:`read_series` joins them): CSV,
plain or compressed, is decompressed and parsed :data:`CHUNK_BYTES` at a time, Parquet by row
groups.  The reader's memory is the float64 arrays of the columns and one chunk, never the file's
text.  A clean chunk (every line a row of the header's field count, no quote, comment or blank line,
counted on its bytes) is parsed by pandas' C parser straight into floats; any other chunk, and any
chunk the C parser complains about, takes the checked path that splits cells in Python and names the
row of every problem, so the messages and row numbers are those of a file read whole.  MATLAB files,
compressed Parquet and UTF-16 text are read whole (at most :data:`MAX_BYTES`).

Time may be seconds, milliseconds (declared) or ISO 8601 timestamps.  Heavy libraries
(pandas, pyarrow, scipy.io) are imported only when a file needs them.

Every problem is one :class:`~heavecomp.errors.DataError` line naming the column (and
the row, as a line number of the file, header = line 1 when there is one): ragged rows
(a stray delimiter), two columns of the same name, a non-numeric cell, an unknown or
wrong-kind unit, time that looks like milliseconds, a binary file of no known format.
"""

from __future__ import annotations

import dataclasses
import io
import logging
import re
from pathlib import Path

import numpy as np

from heavecomp.errors import DataError, InputError
from heavecomp.errors import did_you_mean
from heavecomp.io import logs as _logs

log = logging.getLogger(__name__)

#: contract name -> physical kind (docs/contracts/measured-run.md)
KINDS = {"t": "time", "heave": "length", "stroke": "length", "pressure": "pressure", "wob": "force",
         "pitch": "angle", "hook_load": "force"}
#: SI unit of each kind
SI = {"time": "s", "length": "m", "pressure": "Pa", "force": "N", "angle": "rad"}
P_ATM = 101325.0
#: unit -> (kind, factor to SI, offset added after scaling [SI]); absolute pressures become gauge
UNITS = {
    "s": ("time", 1.0, 0.0), "ms": ("time", 1e-3, 0.0), "us": ("time", 1e-6, 0.0),
    "min": ("time", 60.0, 0.0), "h": ("time", 3600.0, 0.0),
    "m": ("length", 1.0, 0.0), "cm": ("length", 1e-2, 0.0), "mm": ("length", 1e-3, 0.0),
    "in": ("length", 0.0254, 0.0), "ft": ("length", 0.3048, 0.0),
    "pa": ("pressure", 1.0, 0.0), "kpa": ("pressure", 1e3, 0.0), "mpa": ("pressure", 1e6, 0.0),
    "bar": ("pressure", 1e5, 0.0), "barg": ("pressure", 1e5, 0.0), "mbar": ("pressure", 1e2, 0.0),
    "psi": ("pressure", 6894.757, 0.0), "psig": ("pressure", 6894.757, 0.0),
    "bara": ("pressure", 1e5, -P_ATM), "psia": ("pressure", 6894.757, -P_ATM),
    "pa_abs": ("pressure", 1.0, -P_ATM), "kpa_abs": ("pressure", 1e3, -P_ATM),
    "n": ("force", 1.0, 0.0), "kn": ("force", 1e3, 0.0), "mn": ("force", 1e6, 0.0),
    "t": ("force", 9810.0, 0.0), "tonnes": ("force", 9810.0, 0.0), "kip": ("force", 4448.22, 0.0),
    "lbf": ("force", 4.44822, 0.0), "klbf": ("force", 4448.22, 0.0),
    # rig units of drilling logs (WITSML / LAS, docs/contracts/measured-run.md): kilogram-force and its
    # thousand (kkgf, a metric tonne-force by the standard g = 9.80665), decanewton, kpsi, sec
    "kgf": ("force", 9.80665, 0.0), "kkgf": ("force", 9806.65, 0.0), "dan": ("force", 10.0, 0.0),
    "kpsi": ("pressure", 6894757.0, 0.0), "sec": ("time", 1.0, 0.0),
    "rad": ("angle", 1.0, 0.0), "mrad": ("angle", 1e-3, 0.0), "deg": ("angle", np.pi / 180.0, 0.0),
}
#: header spellings of the contract names (after normalisation: lower case, single spaces)
ALIASES = {"t": ("t", "time", "timestamp", "datetime", "date time"), "heave": ("heave", "z_h", "zh"),
           "stroke": ("stroke", "s"), "pressure": ("pressure", "p"), "wob": ("wob", "weight on bit"),
           "pitch": ("pitch",), "hook_load": ("hook_load", "hook load", "hookload")}
#: largest file read (decompressed) [bytes]: a bigger one is refused before it fills the memory
MAX_BYTES = 1 << 30
DELIMITERS = (",", ";", "\t", "|")
NA = {"", "nan", "na", "n/a", "null", "none", "-"}


@dataclasses.dataclass
class Series:
    """Named float columns in SI units, with how they were read.

    Attributes
    ----------
    columns : dict of str to ndarray
        Contract names (``t`` [s] from the first sample's absolute value, ``heave`` [m], ...)
        for the columns found, plus every other numeric column under its header name (raw).
    source : str
        The file (shortened when very long).
    measurement : dict
        ``format``, ``delimiter``, ``decimal``, ``columns`` (contract -> source header),
        ``units`` (contract -> unit as read), ``conversions`` (one string each).
    warnings : list of str
    rows : ndarray of int
        Line number in the file of each sample (for messages).
    """

    columns: dict
    source: str
    measurement: dict
    warnings: list
    rows: np.ndarray

    def __getitem__(self, name):
        return self.columns[name]


def short(path, limit=80) -> str:
    """A path for a one-line message: long ones cut in the middle.

    Parameters
    ----------
    path : str or Path
        The path.
    limit : int
        Most characters kept.
    """
    s = str(path)
    return s if len(s) <= limit else s[: limit // 2 - 2] + "..." + s[-(limit // 2 - 1):]


def parse_mapping(text, option="mapping") -> dict:
    """``"t=Time,heave=MRU_heave"`` -> ``{"t": "Time", "heave": "MRU_heave"}`` (one-line errors).

    Parameters
    ----------
    text : str or None
        Comma-separated ``NAME=VALUE`` pairs; None: an empty mapping.
    option : str
        Where the text came from, named at the start of error messages (the commands pass their
        flag, e.g. ``"--columns"``; the library names no flag of its own).
    """
    out = {}
    if text is None:
        return out
    for part in str(text).split(","):
        if not part.strip():
            continue
        if "=" not in part:
            raise InputError(f"{option}: expected NAME=VALUE, got {part.strip()!r}")
        k, v = (x.strip() for x in part.split("=", 1))
        if not k or not v:
            raise InputError(f"{option}: expected NAME=VALUE, got {part.strip()!r}")
        out[k] = v
    return out


def check_spec(columns: dict | None, units: dict | None, where: str) -> tuple[dict, dict]:
    """Validate a column mapping and units (``[measurement]`` or the command line).

    Keys must be contract names; units must be known and of the contract name's kind.
    ``where`` is ``"cli"`` (messages name ``--units t``) or a table name (``measurement.units.t``).

    Parameters
    ----------
    columns : dict or None
        Contract name -> source column header.
    units : dict or None
        Contract name -> unit of its source column (a key of :data:`UNITS`).
    where : str
        ``"cli"`` or the table's name, for messages.
    """

    columns, units = dict(columns or {}), dict(units or {})

    def key(label, k):
        return f"--{label} {k}" if where == "cli" else f"{where}.{label}.{k}"

    for label, table in (("columns", columns), ("units", units)):
        for k, v in table.items():
            if k not in KINDS:
                raise InputError(f"{key(label, k)}: not a contract column{did_you_mean(k, KINDS)}; "
                                 f"known: {', '.join(KINDS)}")
            if not isinstance(v, str) or not v.strip():
                raise InputError(f"{key(label, k)}: expected a non-empty string, got {v!r}")
    for k, u in units.items():
        spec = UNITS.get(u.strip().lower())
        if spec is None:
            ok = [x for x, s in UNITS.items() if s[0] == KINDS[k]]
            raise InputError(f"{key('units', k)}: unknown unit {u!r}{did_you_mean(u.lower(), ok)}; "
                             f"{KINDS[k]} units: {', '.join(ok)}")
        if spec[0] != KINDS[k]:
            raise InputError(f"{key('units', k)}: {u!r} is a {spec[0]} unit, '{k}' is a {KINDS[k]}")
    return columns, units


# ---------------------------------------------------------------- raw bytes -> table
def _read_bytes(path: Path, src: str) -> bytes:
    try:
        if not path.is_file():
            raise DataError(f"{src}: file not found" if not path.exists() else f"{src}: not a file")
        with path.open("rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise DataError(f"{src}: cannot read ({exc.strerror or type(exc).__name__})") from None
    if len(data) > MAX_BYTES:
        raise DataError(f"{src}: larger than {MAX_BYTES >> 20} MB; cut the log into parts")
    return data


def _inflate(dec, data: bytes, src: str) -> bytes:
    """Run a streaming decompressor with a size cap; a truncated stream is an error."""
    out = dec.decompress(data, MAX_BYTES + 1)
    if len(out) > MAX_BYTES:
        raise DataError(f"{src}: decompresses to more than {MAX_BYTES >> 20} MB")
    if not dec.eof:
        raise DataError(f"{src}: corrupt compressed file (truncated)")
    return out


def _decompress(data: bytes, src: str) -> tuple[bytes, str | None]:
    """(decompressed bytes, method) for gzip / bzip2 / xz / zip content, else ``(data, None)``."""
    import bz2
    import lzma
    import zipfile
    import zlib

    try:
        if data[:2] == b"\x1f\x8b":
            return _inflate(zlib.decompressobj(wbits=47), data, src), "gzip"
        if data[:3] == b"BZh":
            return _inflate(bz2.BZ2Decompressor(), data, src), "bzip2"
        if data[:6] == b"\xfd7zXZ\x00":
            return _inflate(lzma.LZMADecompressor(), data, src), "xz"
        if data[:4] == b"PK\x03\x04":
            with zipfile.ZipFile(io.BytesIO(data)) as zf:
                names = [n for n in zf.namelist() if not n.endswith("/")]
                if any(n.startswith("xl/") for n in names):
                    raise DataError(f"{src}: an Excel workbook; export the sheet as CSV")
                if len(names) != 1:
                    raise DataError(f"{src}: zip archive with {len(names)} files; expected exactly one CSV")
                if zf.getinfo(names[0]).file_size > MAX_BYTES:
                    raise DataError(f"{src}: decompresses to more than {MAX_BYTES >> 20} MB")
                return zf.read(names[0]), "zip"
    except DataError:
        raise
    except (OSError, EOFError, ValueError, zipfile.BadZipFile, lzma.LZMAError, zlib.error) as exc:
        raise DataError(f"{src}: corrupt compressed file ({type(exc).__name__})") from None
    return data, None


def _decode(data: bytes, src: str, warnings: list) -> str:
    head = data[:65536]
    if b"\x00" in head:
        if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
            try:
                text = data.decode("utf-16")
            except UnicodeDecodeError:
                text = ""
            if text and sum(1 for c in text[:4096] if not (c.isprintable() or c in "\r\n\t")) < 0.01 * len(text[:4096]) \
                    and text[:4096].isascii():
                return text
        raise DataError(f"{src}: binary file, not a recognised format (CSV text, gzip/bz2/xz/zip CSV, "
                        "Parquet, MATLAB .mat)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        text = data.decode("latin-1")
        ctrl = sum(1 for c in text[:65536] if ord(c) < 32 and c not in "\r\n\t")
        if ctrl > 0.01 * min(len(text), 65536):
            raise DataError(f"{src}: binary file, not a recognised format (CSV text, gzip/bz2/xz/zip CSV, "
                            "Parquet, MATLAB .mat)") from None
        warnings.append(f"not UTF-8 (byte {exc.start}); read as Latin-1")
        return text


def read_text(path) -> tuple[str, list]:
    """Text of a plain or compressed (gzip/bz2/xz/zip) text file, for readers with their own layout.

    Returns ``(text, warnings)``; a missing, unreadable, binary or corrupt file is a one-line
    :class:`DataError` (never a ``UnicodeDecodeError``).

    Parameters
    ----------
    path : str or Path
        The file.
    """
    path = Path(path)
    src = short(path)
    warnings: list[str] = []
    raw, _ = _decompress(_read_bytes(path, src), src)
    return _decode(raw, src, warnings), warnings


_NUM = re.compile(r"^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$")


def _is_number(cell: str) -> bool:
    c = cell.strip().strip('"')
    return bool(_NUM.match(c)) or c.lower() in ("nan", "inf", "-inf", "+inf")


def _split(line: str, sep: str | None) -> list[str]:
    return line.split() if sep is None else line.split(sep)


def _sniff(lines: list[str]) -> tuple[str | None, str]:
    """(delimiter or None for whitespace, decimal mark) from the first lines."""
    sample = lines[:50]
    best, best_n = None, 0
    for sep in DELIMITERS:
        counts = {ln.count(sep) for ln in sample}
        if len(counts) == 1:
            n = counts.pop()
            if n > best_n:
                best, best_n = sep, n
    if best is None:
        # whitespace separated (or one column)
        counts = {len(ln.split()) for ln in sample[1:] or sample}
        best = None if (len(counts) == 1 and counts.pop() > 1) else ","
        if best == "," and not any("," in ln for ln in sample):
            best = None
    decimal = "."
    if best != ",":
        body = [c.strip() for ln in sample[1:] for c in _split(ln, best)]
        commas = sum(1 for c in body if re.match(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$", c))
        dots = sum(1 for c in body if re.match(r"^[+-]?\d*\.\d+([eE][+-]?\d+)?$", c))
        if commas > dots:
            decimal = ","
    return best, decimal


_UNIT_RE = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]*)\s*[\])]\s*$")


def split_header(name: str) -> tuple[str, str | None]:
    """``"Time [ms]"`` -> ``("time", "ms")``; ``"WOB_kN"`` -> ``("wob", "kN")``; ``"Heave"`` -> ``("heave", None)``.

    Parameters
    ----------
    name : str
        A column header as written in the file.
    """
    raw = " ".join(str(name).replace("\ufeff", "").split())
    m = _UNIT_RE.match(raw)
    base, unit = (m.group(1), m.group(2).strip()) if m else (raw, None)
    base = base.strip().lower()
    if unit is None:
        for sep in ("_", " "):
            if sep in base:
                head, tail = base.rsplit(sep, 1)
                if tail in UNITS and head:
                    orig = raw.rsplit(sep, 1)[1]
                    return head.strip(), orig
    return base, (unit or None)


def _head(content: list, src: str):
    """(delimiter, decimal mark, header names, whether the first content line is a header) from the
    first content lines (non-blank, not ``#``)."""
    sep, decimal = _sniff(content)
    first = [c.strip().strip('"') for c in _split(content[0], sep)]
    has_header = not all(_is_number(c) for c in first if c)
    header = first if has_header else [str(i + 1) for i in range(len(first))]
    return sep, decimal, header, has_header


def _cells(body: list, body_lines, sep, n: int, src: str, quoted: bool) -> list:
    """Rows split into cells; a row of another field count than the header is a DataError naming its
    line (``body_lines``: the file line of each row)."""
    if sep is not None and quoted:  # quoted cells may hold the delimiter: let csv split them
        import csv

        cells = [next(csv.reader([ln], delimiter=sep)) for ln in body]
    else:
        cells = [_split(ln, sep) for ln in body]
    for k, row in enumerate(cells):
        if len(row) != n:
            line = body_lines[k]
            extra = ("a stray delimiter or a decimal comma in a comma-separated file?" if len(row) > n
                     else "a cell or delimiter missing?")
            shown = repr(sep) if sep else "whitespace"
            raise DataError(f"{src}: row {line} has {len(row)} fields, the header has {n} ({shown} separated; "
                            f"{extra})")
    return cells


def _text_table(text: str, src: str):
    """Header names, raw string columns (one list per column), line numbers, delimiter, decimal."""
    lines = text.splitlines()
    content = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    if not content:
        raise DataError(f"{src}: empty file (no header, no data)")
    sep, decimal, header, has_header = _head(content, src)
    # the whole text is the checked path's one chunk (a quote anywhere in it lets csv split the rows)
    cols, body_lines = _checked_chunk(lines, 0, sep, len(header), src, skip_first=has_header, quoted='"' in text)
    return header, cols, body_lines, sep, decimal


def _to_float(values, name, lines, src, decimal, required):
    """Strings -> floats; NaN for empty / NA; other text: DataError naming ``name`` (quoted label) if
    ``required``, else None (a text column carried along is dropped)."""
    import pandas as pd

    s = pd.Series(values, dtype="string").str.strip()
    if decimal == ",":
        s = s.str.replace(",", ".", regex=False)
    num = pd.to_numeric(s, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
    bad = np.isnan(num) & ~s.str.lower().isin(NA).to_numpy(dtype=bool, na_value=True)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        cell = str(values[k]).strip()
        if not required:
            return None
        hint = ""
        if re.match(r"^[+-]?\d+,\d+$", cell):
            hint = " (a decimal comma? use a ';' or tab delimiter, or a decimal point)"
        elif cell.startswith("\ufeff"):
            hint = " (a byte-order mark inside the file)"
        raise DataError(f"{src}: column {name}, row {lines[k]}: not a number: {cell[:40]!r}{hint}")
    return num


def _time_from_strings(values, name, lines, src):
    """ISO 8601 timestamps -> ns since the epoch (UTC, int64), or None if they are not timestamps."""
    import pandas as pd

    s = pd.Series(values, dtype="string").str.strip()
    try:
        ts = pd.to_datetime(s, format="ISO8601", errors="coerce", utc=True)
    except (ValueError, TypeError):
        return None
    ok = ts.notna().to_numpy()
    if ok.sum() < max(1, 0.5 * len(values)):
        return None
    if not ok.all():
        k = int(np.flatnonzero(~ok)[0])
        raise DataError(f"{src}: column '{name}', row {lines[k]}: not a timestamp: {str(values[k])[:40]!r}")
    return ts.to_numpy(dtype="datetime64[ns]").astype("int64")


def _parquet_table(data: bytes, src: str):
    try:
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - pyarrow is a dependency
        raise DataError(f"{src}: Parquet needs pyarrow (pip install pyarrow)") from None
    try:
        table = pq.read_table(io.BytesIO(data))
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types for a bad file
        raise DataError(f"{src}: unreadable Parquet file ({type(exc).__name__})") from None
    header = list(table.column_names)
    cols = []
    for j, name in enumerate(header):
        col = table.column(j)
        import pyarrow as pa

        if pa.types.is_timestamp(col.type) or pa.types.is_date(col.type):
            cols.append(np.asarray(col.cast(pa.timestamp("ns")).to_numpy(zero_copy_only=False)).astype("datetime64[ns]"))
        elif pa.types.is_integer(col.type) or pa.types.is_floating(col.type) or pa.types.is_boolean(col.type):
            cols.append(np.asarray(col.to_numpy(zero_copy_only=False), dtype=float))
        else:
            cols.append([None if v is None else str(v) for v in col.to_pylist()])
    return header, cols


def _mat_table(data: bytes, src: str):
    if data[:4] == b"\x89HDF" or data[512:516] == b"\x89HDF":
        raise DataError(f"{src}: MATLAB v7.3 (HDF5) file; save it with save(..., '-v7') or export CSV")
    import scipy.io

    try:
        mat = scipy.io.loadmat(io.BytesIO(data), squeeze_me=False)
    except Exception as exc:  # noqa: BLE001 - scipy raises several types for a bad file
        raise DataError(f"{src}: unreadable MATLAB file ({type(exc).__name__})") from None
    header = _mat_columns({k: v.shape for k, v in mat.items()
                           if not k.startswith("__") and isinstance(v, np.ndarray) and v.dtype.kind in "iufb"}, src)
    return header, [np.asarray(mat[k], dtype=float).ravel() for k in header], \
        {k: v for k, v in mat.items() if not k.startswith("__")}


#: MATLAB classes of numeric variables (``scipy.io.whosmat``'s third field)
MAT_NUMERIC = ("double", "single", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64",
               "logical")


def _mat_columns(shapes: dict, src: str) -> list:
    """The variables of a MATLAB file that are its columns: numeric vectors (``shapes``: name -> shape of each
    numeric variable) of the most common length."""
    vecs = {k: int(np.prod(sh)) for k, sh in shapes.items() if len(sh) == 2 and 1 in sh and int(np.prod(sh)) > 1}
    if not vecs:
        raise DataError(f"{src}: MATLAB file without any numeric vector variable")
    lengths = list(vecs.values())
    n = max(set(lengths), key=lengths.count)
    return [k for k, m in vecs.items() if m == n]


def _mat_header(path: Path, src: str) -> list:
    """The column variables of a MATLAB file from its variable headers (``scipy.io.whosmat``), no data read."""
    with path.open("rb") as fh:
        data = fh.read(516)
    if data[:4] == b"\x89HDF" or data[512:516] == b"\x89HDF":
        raise DataError(f"{src}: MATLAB v7.3 (HDF5) file; save it with save(..., '-v7') or export CSV")
    import scipy.io

    try:
        info = scipy.io.whosmat(str(path))
    except Exception as exc:  # noqa: BLE001 - scipy raises several types for a bad file
        raise DataError(f"{src}: unreadable MATLAB file ({type(exc).__name__})") from None
    return _mat_columns({name: tuple(shape) for name, shape, cls in info if cls in MAT_NUMERIC}, src)


# ---------------------------------------------------------------- streamed reading
#: decompressed text parsed per chunk [bytes]: with the float arrays of the columns, the reader's memory
CHUNK_BYTES = 4 << 20
#: the first chunk [bytes] (the header is sniffed from it; it takes the checked, cell-by-cell path)
FIRST_CHUNK_BYTES = 256 << 10
#: rows per chunk of a Parquet file
PARQUET_ROWS = 200_000
#: rows of a Parquet file's head (:func:`iter_chunks` ``head``): about as many as a text log's first chunk holds
HEAD_ROWS = 5000
#: largest float arrays the reader builds [bytes] (rows x (columns + 1 line number) x 8)
MAX_ARRAY_BYTES = 1 << 30


def _open(path: Path, src: str):
    """(binary stream of the file's decompressed content, compression method or None, first raw bytes)."""
    import bz2
    import gzip
    import lzma
    import zipfile

    try:
        if not path.is_file():
            raise DataError(f"{src}: file not found" if not path.exists() else f"{src}: not a file")
        with path.open("rb") as fh:
            magic = fh.read(32)
        if magic[:2] == b"\x1f\x8b":
            return gzip.open(path, "rb"), "gzip", magic
        if magic[:3] == b"BZh":
            return bz2.open(path, "rb"), "bzip2", magic
        if magic[:6] == b"\xfd7zXZ\x00":
            return lzma.open(path, "rb"), "xz", magic
        if magic[:4] == b"PK\x03\x04":
            try:
                zf = zipfile.ZipFile(path)
                names = [n for n in zf.namelist() if not n.endswith("/")]
            except (zipfile.BadZipFile, EOFError, ValueError) as exc:
                raise DataError(f"{src}: corrupt compressed file ({type(exc).__name__})") from None
            if any(n.startswith("xl/") for n in names):
                raise DataError(f"{src}: an Excel workbook; export the sheet as CSV")
            if len(names) != 1:
                raise DataError(f"{src}: zip archive with {len(names)} files; expected exactly one CSV")
            return zf.open(names[0]), "zip", magic
        return path.open("rb"), None, magic
    except OSError as exc:
        raise DataError(f"{src}: cannot read ({exc.strerror or type(exc).__name__})") from None


def _read(stream, size: int, src: str, comp) -> bytes:
    """``stream.read(size)``; a decompressor's or the file system's exception is one DataError line."""
    import lzma
    import zipfile
    import zlib

    try:
        return stream.read(size)
    except EOFError:
        raise DataError(f"{src}: corrupt compressed file (truncated)") from None
    except (lzma.LZMAError, zlib.error, zipfile.BadZipFile, ValueError) as exc:
        raise DataError(f"{src}: corrupt compressed file ({type(exc).__name__})") from None
    except OSError as exc:
        if comp and not exc.strerror:  # gzip's BadGzipFile
            raise DataError(f"{src}: corrupt compressed file ({type(exc).__name__})") from None
        raise DataError(f"{src}: cannot read ({exc.strerror or type(exc).__name__})") from None


class _NotUTF8(Exception):
    """The text is not UTF-8 (``byte``: the first bad byte of the decompressed file): read it as Latin-1."""

    def __init__(self, byte):
        super().__init__(byte)
        self.byte = byte


def _text_chunks(stream, src: str, encoding: str, comp):
    """Yield ``(raw, text)`` chunks of whole lines, about :data:`CHUNK_BYTES` each (``raw`` the bytes,
    ``text`` decoded); the file is never held whole."""
    import codecs

    dec = codecs.getincrementaldecoder(encoding)()
    rest, offset = b"", 0
    size = FIRST_CHUNK_BYTES  # the first chunk (header, sniffing) takes the checked path: keep it small
    while True:
        block = _read(stream, size, src, comp)
        size = CHUNK_BYTES
        data = rest + block
        if not block:
            if data:
                yield data, _decoded(dec, data, offset, True)
            return
        cut = data.rfind(b"\n") + 1
        if cut == 0:
            rest = data
            continue
        raw, rest = data[:cut], data[cut:]
        yield raw, _decoded(dec, raw, offset, False)
        offset += len(raw)


def _decoded(dec, raw: bytes, offset: int, final: bool) -> str:
    try:
        return dec.decode(raw, final)
    except UnicodeDecodeError as exc:
        raise _NotUTF8(offset + exc.start) from None


#: NA spellings given to the C parser (the checked path compares in lower case, after stripping)
_NA_PARSER = sorted({v for x in NA for v in (x, x.upper(), x.title())})


#: line breaks other than LF and CRLF (``str.splitlines`` splits at them; the C parser does not)
_ODD_BREAKS = ("\x0b", "\x0c", "\x1c", "\x1d", "\x1e", "\x85", "\u2028", "\u2029")


def _fast_chunk(raw: bytes, text: str, sep, decimal, n: int, kinds: list, encoding: str):
    """Parse a clean chunk without Python strings (pandas' C parser, float64): every line a data row of
    exactly ``n`` fields, no quote, no comment, no blank line.  Otherwise, or on any parser complaint,
    None: the chunk takes the checked path, which names the row of every problem.  ``kinds`` per column:
    ``"float"``, ``"text"`` (ISO time) or ``"drop"`` (a text column carried nowhere).  Returns
    ``(columns, rows)``."""
    if sep is None or n < 2 or '"' in text or "#" in text or text.count("\r") != text.count("\r\n") \
            or any(c in text for c in _ODD_BREAKS):
        return None
    b = np.frombuffer(raw, dtype=np.uint8)
    nl = np.flatnonzero(b == 10)
    rows = nl.size + (1 if raw[-1:] != b"\n" else 0)
    if rows == 0:
        return None
    ends = np.append(nl, b.size) if rows > nl.size else nl
    seps = np.flatnonzero(b == ord(sep))
    per_line = np.diff(np.searchsorted(seps, np.concatenate([[0], ends])))
    if not (per_line == n - 1).all():
        return None
    import csv
    import pandas as pd

    use = [j for j, k in enumerate(kinds) if k != "drop"]
    try:
        df = pd.read_csv(io.BytesIO(raw), encoding="utf-8" if encoding == "utf-8-sig" else encoding, sep=sep, header=None, names=list(range(n)), usecols=use,
                         dtype={j: (np.float64 if kinds[j] == "float" else object) for j in use},
                         decimal=decimal, keep_default_na=False, na_values=_NA_PARSER, engine="c",
                         skip_blank_lines=False, quoting=csv.QUOTE_NONE)
    except (ValueError, TypeError, OverflowError, pd.errors.ParserError):
        return None
    if len(df) != rows:
        return None
    return [None if kinds[j] == "drop" else
            df[j].to_numpy(dtype=np.float64) if kinds[j] == "float" else df[j].astype(str).tolist()
            for j in range(n)], rows


def _checked_chunk(lines, base: int, sep, n: int, src: str, skip_first: bool = False, quoted=None):
    """The checked path of one chunk: cells split in Python, a ragged row named by its line
    (``base``: lines of the file before the chunk; ``quoted``: split by csv, None: if a row holds a quote)."""
    idx = [i for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")]
    if skip_first:
        idx = idx[1:]
    body = [lines[i] for i in idx]
    body_lines = base + 1 + np.asarray(idx, dtype=int)
    cells = _cells(body, body_lines, sep, n, src, any('"' in ln for ln in body) if quoted is None else quoted)
    return [[row[j] for row in cells] for j in range(n)], body_lines


def _csv_chunks(stream, src: str, info: dict, comp, encoding: str, kinds: list):
    """``(header, iterator of (cols, lines))`` of (compressed) CSV text read in chunks.  ``cols``: per column
    a float64 array (a clean chunk, :func:`_fast_chunk`) or a list of cell strings; ``lines``: the file
    line of each row.  ``kinds`` is filled by the caller after the first chunk (see :func:`_fast_chunk`)."""
    chunks = _text_chunks(stream, src, encoding, comp)
    base = 0
    for raw, text in chunks:
        lines = text.splitlines()
        content = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
        if content:
            break
        base += len(lines)
    else:
        raise DataError(f"{src}: empty file (no header, no data)")
    sep, decimal, header, has_header = _head(content, src)
    info.update(delimiter="whitespace" if sep is None else sep, decimal=decimal)
    n = len(header)

    def rows():
        nonlocal base
        yield _checked_chunk(lines, base, sep, n, src, skip_first=has_header)
        base += len(lines)
        for raw_k, text_k in chunks:
            got = _fast_chunk(raw_k, text_k, sep, decimal, n, kinds, encoding) if kinds else None
            if got is not None:
                cols, count = got
                yield cols, base + 1 + np.arange(count)
            else:
                lines_k = text_k.splitlines()
                count = len(lines_k)
                yield _checked_chunk(lines_k, base, sep, n, src)
                del lines_k
            base += count

    return header, rows()


def _parquet_chunks(path: Path, src: str, size: int = 0):
    """``(header, iterator of (cols, lines))`` of a Parquet file read ``size`` (default :data:`PARQUET_ROWS`)
    rows at a time."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - pyarrow is a dependency
        raise DataError(f"{src}: Parquet needs pyarrow (pip install pyarrow)") from None
    try:
        pf = pq.ParquetFile(path)
        header = list(pf.schema_arrow.names)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types for a bad file
        raise DataError(f"{src}: unreadable Parquet file ({type(exc).__name__})") from None

    def rows():
        done = 0
        try:
            for batch in pf.iter_batches(batch_size=size or PARQUET_ROWS):
                yield [_arrow_column(batch.column(j), pa) for j in range(len(header))], done + 1 + np.arange(batch.num_rows)
                done += batch.num_rows
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several types for a bad file
            raise DataError(f"{src}: unreadable Parquet file ({type(exc).__name__})") from None
        if done == 0:
            yield [np.zeros(0) for _ in header], np.zeros(0, dtype=int)

    return header, rows()


def _arrow_column(col, pa):
    """One pyarrow column as the reader's column: datetime64[ns], float64, or a list of strings."""
    if pa.types.is_timestamp(col.type) or pa.types.is_date(col.type):
        return np.asarray(col.cast(pa.timestamp("ns")).to_numpy(zero_copy_only=False)).astype("datetime64[ns]")
    if pa.types.is_integer(col.type) or pa.types.is_floating(col.type) or pa.types.is_boolean(col.type):
        return np.asarray(col.to_numpy(zero_copy_only=False), dtype=float)
    return [None if v is None else str(v) for v in col.to_pylist()]


FRAME = "<DataFrame>"  #: the source name of a pandas DataFrame read as a series


def is_frame(obj) -> bool:
    """Whether ``obj`` is a table handed over in memory (a pandas DataFrame), not a file name.

    Parameters
    ----------
    obj : object
        What a reader was given.
    """
    return hasattr(obj, "columns") and hasattr(obj, "index") and not isinstance(obj, (str, bytes, Path))


def _frame_column(values):
    """A frame's column (or index) as the reader's column: float64, datetime64[ns] or a list of strings."""
    v = np.asarray(values)
    if v.dtype.kind in "iufb":
        return v.astype(float)
    if v.dtype.kind == "M":
        return v.astype("datetime64[ns]")
    return [None if x is None or (isinstance(x, float) and x != x) else str(x) for x in v.tolist()]


def _frame_table(df, info: dict):
    """``(header, one chunk, {})`` of a pandas DataFrame, as a file with the same header would be read: its
    columns, and first its index when that is named and no column has its name (time as the index, as
    ``SimulationResult.to_pandas()`` gives it).  Row numbers as for a file with a header line (first row: 2)."""
    info["format"] = "pandas.DataFrame"
    names = [str(c) for c in df.columns]
    header, cols = [], []
    if df.index.name is not None and str(df.index.name) not in names:
        header.append(str(df.index.name))
        cols.append(_frame_column(df.index))
    for j, name in enumerate(names):
        header.append(name)
        cols.append(_frame_column(df.iloc[:, j]))
    return header, iter([(cols, np.arange(len(df)) + 2)]), {}


def _table(path: Path, src: str, info: dict, warnings: list, kinds: list, encoding: str = "utf-8-sig",
           start_only: bool = False):
    """``(header, iterator of (cols, lines), MATLAB scalars)`` of any supported file (a streamed CSV's
    open stream under ``"_stream"`` in the third, for the caller to close): Parquet and
    (compressed) CSV streamed in chunks; MATLAB, compressed Parquet and UTF-16 text read whole (one chunk);
    a pandas DataFrame (:func:`is_frame`) as one chunk.  ``start_only`` (:func:`iter_chunks`' ``head``): Parquet in chunks of
    :data:`HEAD_ROWS`, and of a MATLAB file only its variable headers (:func:`_mat_header`; one chunk without rows)."""
    if is_frame(path):
        return _frame_table(path, info)
    stream, comp, magic = _open(path, src)
    with stream:
        head = _read(stream, 65536, src, comp)
    if magic[:4] == b"PAR1":
        info["format"] = "parquet"
        header, it = _parquet_chunks(path, src, HEAD_ROWS if start_only else 0)
        return header, it, {}
    if magic[:19] == b"MATLAB 5.0 MAT-file" or magic[:4] == b"\x89HDF" or path.suffix.lower() == ".mat":
        info["format"] = "mat"
        if start_only:
            header = _mat_header(path, src)
            return header, iter([([np.zeros(0) for _ in header], np.zeros(0, dtype=int))]), {}
        header, cols, scalars = _mat_table(_read_bytes(path, src), src)
        return header, iter([(cols, np.arange(cols[0].size) + 1)]), scalars
    if comp:
        info["compression"] = comp
    kind = _logs.sniff(head)
    if kind is not None:  # a drilling log (WITSML 1.4.1.1, LAS 2.0): read whole, mapped by mnemonic
        raw, _ = _decompress(_read_bytes(path, src), src)
        return _logs.table(raw, kind, src, info, lambda b: _decode(b, src, warnings),
                           lambda u: UNITS.get(u.strip().lower(), (None,))[0])
    if head[:4] == b"PAR1" or b"\x00" in head:  # compressed Parquet, UTF-16 or binary: read whole
        raw, _ = _decompress(_read_bytes(path, src), src)
        if raw[:4] == b"PAR1":
            info["format"] = "parquet"
            header, cols = _parquet_table(raw, src)
            return header, iter([(cols, np.arange(len(cols[0]) if cols else 0) + 1)]), {}
        header, cols, lines, sep, decimal = _text_table(_decode(raw, src, warnings), src)
        info.update(delimiter="whitespace" if sep is None else sep, decimal=decimal)
        return header, iter([(cols, lines)]), {}
    if encoding == "latin-1":
        text = head.decode("latin-1")
        ctrl = sum(1 for c in text if ord(c) < 32 and c not in "\r\n\t")
        if ctrl > 0.01 * min(len(text), 65536):
                raise DataError(f"{src}: binary file, not a recognised format (CSV text, gzip/bz2/xz/zip CSV, "
                            "Parquet, MATLAB .mat)")
    stream, comp, _ = _open(path, src)
    try:
        header, it = _csv_chunks(stream, src, info, comp, encoding, kinds)
    except BaseException:
        stream.close()
        raise
    return header, it, {"_stream": stream}


# ---------------------------------------------------------------- table -> Series
def _source(path):
    """``(what to read, its name for messages)``: a file's path, or a DataFrame as it is (:data:`FRAME`)."""
    if is_frame(path):
        return path, FRAME
    path = Path(path)
    return path, short(path)


def read_series(path, required=("t",), *, optional=(), columns=None, units=None, what="measured series") -> Series:
    """Read a measured series from a file in any supported format (see the module docstring).

    CSV (plain or compressed) and Parquet are read in chunks (:data:`CHUNK_BYTES` of text,
    :data:`PARQUET_ROWS` rows): the memory is the float64 arrays of the columns (8 bytes per value,
    plus 8 per row for its line number) and one chunk, never the file's text.  A pandas DataFrame is
    read as a file with its header would be (its named index first, when no column has that name).

    Parameters
    ----------
    path : str or Path, or pandas.DataFrame
    required : tuple of str
        Contract names that must be present (``t``, ``heave``, ``stroke``, ``pressure``, ``wob``).
    optional : tuple of str
        Contract names used when present.
    columns : dict, optional
        Contract name -> header of the source column (``--columns`` / ``[measurement] columns``).
    units : dict, optional
        Contract name -> unit of the source column (``--units`` / ``[measurement] units``);
        a unit in the header (``Time [ms]``) counts as declared too.
    what : str
        What the file is, for messages.

    Returns
    -------
    Series
        ``t`` in s as read (timestamps: from the first sample), other contract columns in SI units.

    Raises
    ------
    DataError
        One line naming the column (and row) for every problem.
    """
    path, src = _source(path)
    columns, units = check_spec(columns, units, "measurement")
    byte = None
    for encoding in ("utf-8-sig", "latin-1"):  # text not UTF-8 past the first chunk: read again as Latin-1
        warnings: list[str] = [] if byte is None else [f"not UTF-8 (byte {byte}); read as Latin-1"]
        parts, rows, meta, state = {}, [], None, {}
        total = 0
        try:
            for s in _chunks(path, src, tuple(required), tuple(optional), columns, units, encoding, warnings, state):
                meta = s
                for k in list(parts):
                    if k not in s.columns:  # a carried column that turned out to hold text: dropped whole
                        del parts[k]
                for k, v in s.columns.items():
                    parts.setdefault(k, []).append(v)
                rows.append(s.rows)
                total += s.rows.size
                need = 8 * total * (len(s.columns) + 1)
                if need > MAX_ARRAY_BYTES:
                    raise DataError(f"{s.source}: more than {MAX_ARRAY_BYTES >> 20} MB of samples by row "
                                    f"{int(s.rows[-1])} ({len(s.columns)} columns); cut the log into parts")
            break
        except _NotUTF8 as exc:
            byte = exc.byte
    out = {}
    for k in list(parts):  # one column at a time, its chunks freed as it is joined
        v = parts.pop(k)
        out[k] = v[0] if len(v) == 1 else np.concatenate(v)
        del v
    lines = rows[0] if len(rows) == 1 else np.concatenate(rows)
    del rows
    info = meta.measurement
    if "t" in out:
        _check_time_unit(out["t"], state["t_declared"], meta.source, info["columns"]["t"])
    return Series(columns=out, source=meta.source, measurement=info, warnings=meta.warnings, rows=np.asarray(lines))


def iter_chunks(path, required=("t",), *, optional=(), columns=None, units=None, what="measured series",
                check_time=True, head=False):
    """Read a measured series chunk by chunk: :func:`read_series`'s reading, checks and messages, one
    :class:`Series` per chunk (consecutive rows; ``t`` of timestamps from the file's first sample; every
    chunk's ``measurement`` the same dict, complete once the file is read).

    For a pass over a log of any length in bounded memory: only one chunk's arrays are held.  A carried
    (non-contract) column that holds text in a later chunk is left out from there on.  ``head`` reads the
    log's start only, for the checks before any work (:func:`heavecomp.diagnosis.data.check_head`, a
    fleet's :func:`heavecomp.campaign.fleet.check_log`): one chunk, of a MATLAB file without rows.

    Parameters
    ----------
    path : str or Path
        The file.
    required : tuple of str
        Contract names that must be present (as :func:`read_series`).
    optional : tuple of str
        Contract names used when present.
    columns : dict, optional
        Contract name -> header of the source column.
    units : dict, optional
        Contract name -> unit of the source column.
    what : str
        What the file is, for messages.
    check_time : bool
        Check on the first chunk that undeclared time does not look like milliseconds (interval and
        span; :func:`read_series` checks the whole column instead).
    head : bool
        Yield the first chunk only: a text log's first :data:`FIRST_CHUNK_BYTES`, a Parquet file's first
        :data:`HEAD_ROWS` rows, a MATLAB file's columns from its variable headers (``scipy.io.whosmat``:
        the mapping and units checked, no samples read; arrays of length 0).

    Yields
    ------
    Series
        The next rows, contract columns in SI units, ``rows`` their file lines.
    """
    path, src = _source(path)
    columns, units = check_spec(columns, units, "measurement")
    byte = None
    for encoding in ("utf-8-sig", "latin-1"):
        warnings: list[str] = [] if byte is None else [f"not UTF-8 (byte {byte}); read as Latin-1"]
        started, state = False, {}
        try:
            for s in _chunks(path, src, tuple(required), tuple(optional), columns, units, encoding, warnings, state,
                             head):
                if check_time and not started and "t" in s.columns:
                    _check_time_unit(s.columns["t"], state["t_declared"], src, s.measurement["columns"]["t"])
                started = True
                yield s
                if head:
                    return
            return
        except _NotUTF8 as exc:
            if started:  # the caller holds rows read as UTF-8 already: they cannot be read again
                raise DataError(f"{src}: not UTF-8 at byte {exc.byte}, after rows read as UTF-8; save the file "
                                "as UTF-8 (or read it whole)") from None
            byte = exc.byte


def _chunks(path, src, required, optional, columns, units, encoding, warnings, state, head=False):
    """The Series of each chunk (see :func:`iter_chunks`); ``state`` receives what the reader itself
    needs and the caller is not shown (``t_declared``: the time column's unit was declared or read)."""
    info = {"format": "csv"}
    kinds: list = []
    header, chunks, scalars = _table(path, src, info, warnings, kinds, encoding, head)
    stream = scalars.pop("_stream", None)
    notes: list = []
    if "_mnemonics" in scalars:  # a drilling log: its default mnemonic table under the user's mapping
        columns, notes = _logs.mapping(scalars.pop("_mnemonics"), columns, required, optional)
    try:
        yield from _converted(header, chunks, scalars, info, src, required, optional, columns, units, warnings,
                              kinds, state, notes)
    finally:
        if stream is not None:
            stream.close()


def _converted(header, chunks, scalars, info, src, required, optional, columns, units, warnings, kinds, state,
               notes=()):
    """The chunks' columns mapped, converted to SI and checked (see :func:`iter_chunks`); ``state`` as
    :func:`_chunks`'s (kept out of ``info``, the ``measurement`` every caller sees)."""
    decimal = info.get("decimal", ".")
    chosen, norm = _choose(header, required, optional, columns, src)
    used_units, conversions, scale = _units(header, norm, chosen, units, src)
    carried = [j for j, h in enumerate(header) if j not in chosen.values() and str(h) not in chosen]
    info["columns"] = {name: str(header[j]) for name, j in chosen.items()}
    info["units"] = used_units
    info["conversions"] = conversions
    conversions[:0] = notes  # a drilling log's mnemonic -> contract column lines
    if scalars:
        info["mat_scalars"] = sorted(k for k, v in scalars.items()
                                     if isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "iuf")
    if warnings:
        for w in warnings:
            log.warning("%s: %s", src, w)
    origin = None  # the first timestamp [ns]
    dropped: set = set()
    first = True
    for cols, lines in chunks:
        out: dict[str, np.ndarray] = {}
        for name, j in chosen.items():
            vals, kind = cols[j], None
            if isinstance(vals, np.ndarray) and vals.dtype.kind == "M":
                if name != "t":
                    raise DataError(f"{src}: column '{name}': timestamps, expected numbers")
                ns = vals.astype("int64")
                kind = "timestamps -> s from the first sample"
            elif isinstance(vals, np.ndarray):
                arr = np.asarray(vals, dtype=float)
            else:
                ns = None
                if name == "t" and (used_units.get("t") == "timestamp" if not first else
                                    not all(_is_number(str(v)) or str(v).strip().lower() in NA for v in vals[:20])):
                    ns = _time_from_strings(vals, header[j], lines, src)
                    if ns is None and not first:
                        raise DataError(f"{src}: column '{header[j]}', row {lines[0]}: not a timestamp: "
                                        f"{str(vals[0])[:40]!r}")
                    kind = "ISO 8601 timestamps -> s from the first sample"
                if ns is None:
                    kind = None
                    label = f"'{name}'" if str(header[j]) == name else f"'{name}' ({str(header[j])!r})"
                    arr = _to_float(vals, label, lines, src, decimal, True)
            if kind is not None:
                if origin is None and ns.size:
                    origin = int(ns[0])
                arr = (ns - (origin or 0)) / 1e9
                if first:  # a unit in the header of a timestamp column converts nothing
                    conversions[:] = [c for c in conversions if not c.startswith("t: ")]
                    conversions.insert(0, f"t: {kind}")
                    used_units["t"] = "timestamp"
            elif name in scale:
                factor, offset = scale[name]
                arr = arr * factor + offset
            out[name] = arr
        for j in carried:
            if j in dropped:
                continue
            vals = cols[j]
            if isinstance(vals, np.ndarray):
                arr = np.asarray(vals, dtype=float) if vals.dtype.kind != "M" else None
            elif vals is None:
                arr = None
            else:
                arr = _to_float(vals, repr(str(header[j])), lines, src, decimal, False)
            if arr is None:
                dropped.add(j)
                continue
            out[str(header[j])] = arr
        if first:
            for name in list(used_units):
                if used_units[name] is None:
                    used_units[name] = f"{SI[KINDS[name]]} (assumed)"
            state["t_declared"] = "t" in chosen and ("t" in units or norm[chosen["t"]][1] is not None
                                                    or used_units["t"] == "timestamp")
            kinds[:] = ["drop"] * len(header)
            for name, j in chosen.items():
                kinds[j] = "text" if (name == "t" and used_units["t"] == "timestamp") else "float"
            for j in carried:
                if j not in dropped:
                    kinds[j] = "float"
            first = False
        yield Series(columns=out, source=src, measurement=info, warnings=warnings, rows=np.asarray(lines))


def _choose(header, required, optional, columns, src):
    """Which source column is each contract column: ``({name: index}, normalised headers)``; duplicate
    headers, unknown mappings and ambiguous or missing columns are DataErrors."""
    seen = {}
    for j, h in enumerate(header):
        key = str(h).strip()
        if key in seen:
            raise DataError(f"{src}: column '{key}' appears twice in the header (columns {seen[key] + 1} and {j + 1}); "
                            "rename one")
        seen[key] = j
    norm = [split_header(h) for h in header]
    chosen: dict[str, int] = {}
    for name in tuple(required) + tuple(optional):
        if name in columns:
            want = columns[name]
            hits = [j for j, h in enumerate(header) if str(h).strip() == want]
            if not hits:
                wb, _ = split_header(want)
                hits = [j for j, (b, _u) in enumerate(norm) if b == wb]
            if not hits:

                raise DataError(f"{src}: column '{name}' mapped to {want!r}: no such column"
                                f"{did_you_mean(want, [str(h) for h in header])}; header: {_hdr(header)}")
            if len(hits) > 1:
                raise DataError(f"{src}: column '{name}' mapped to {want!r} matches columns "
                                f"{', '.join(repr(str(header[j])) for j in hits)}; name one exactly")
        else:
            hits = [j for j, (b, _u) in enumerate(norm) if b in ALIASES[name] and j not in chosen.values()]
            if len(hits) > 1:
                raise DataError(f"{src}: columns {', '.join(repr(str(header[j])) for j in hits)} all look like "
                                f"'{name}'; choose one in a column mapping, {name}=NAME ([measurement] columns)",
                                option="columns", example=f"{name}=NAME")
        if not hits:
            if name in required:
                hint = ""
                if len(header) == 1:
                    hint = " (only one column found: delimiter not recognised?)"
                raise DataError(f"{src}: missing column '{name}' (header: {_hdr(header)}); map it in a column "
                                f"mapping, {name}=NAME ([measurement] columns){hint}", option="columns",
                                example=f"{name}=NAME")
            continue
        chosen[name] = hits[0]
    return chosen, norm


def _units(header, norm, chosen, units, src):
    """Each chosen column's unit (declared or from its header), checked before any value is read:
    ``(units used, conversions, {name: (factor, offset)} of the columns scaled to SI)``."""
    used_units: dict = {}
    conversions: list[str] = []
    scale: dict = {}
    for name, j in chosen.items():
        head_unit = norm[j][1]
        decl = units.get(name)
        if decl and head_unit and UNITS.get(head_unit.lower(), (None,))[0] == KINDS[name] \
                and UNITS[head_unit.lower()][1:] != UNITS[decl.lower()][1:]:
            raise DataError(f"{src}: column '{name}' ({header[j]!r}): the header says {head_unit}, "
                            f"the declared unit is {decl}; drop one")
        unit = decl or head_unit
        if unit is not None and unit.lower() not in UNITS:
            raise DataError(f"{src}: column '{name}' ({header[j]!r}): unknown unit {unit!r} in the header; "
                            f"declare its unit, {name}=UNIT ([measurement] units)", option="units",
                            example=f"{name}=UNIT")
        if unit is not None and UNITS[unit.lower()][0] != KINDS[name]:
            raise DataError(f"{src}: column '{name}' ({header[j]!r}): unit {unit!r} is a "
                            f"{UNITS[unit.lower()][0]} unit, '{name}' is a {KINDS[name]}")
        used_units[name] = unit
        if unit is not None:
            kind, factor, offset = UNITS[unit.lower()]
            if factor != 1.0 or offset != 0.0:
                scale[name] = (factor, offset)
                conversions.append(f"{name}: {unit} -> {SI[kind]} (x {factor:g}"
                                   + (f", {offset:+g} {SI[kind]} absolute -> gauge" if offset else "") + ")")
    return used_units, conversions, scale


def estimate_rows(path) -> int | None:
    """About how many rows a file holds, from its size, before it is read: Parquet exactly (its
    metadata); plain and zip CSV from the (uncompressed) size over the mean length of its first
    lines; gzip from the uncompressed size its trailer records (one member under 4 GiB).  None where
    the size is not known in advance (bzip2, xz, MATLAB, an unreadable file).

    Parameters
    ----------
    path : str or Path
        The file.
    """
    import zipfile

    path = Path(path)
    try:
        size = path.stat().st_size
        with path.open("rb") as fh:
            magic = fh.read(4)
            if magic == b"PAR1":
                import pyarrow.parquet as pq

                return int(pq.ParquetFile(path).metadata.num_rows)
            if magic[:2] == b"\x1f\x8b":
                fh.seek(-4, 2)
                full = int.from_bytes(fh.read(4), "little")
                if full < size:  # over 4 GiB (the field wraps) or several members: unknown
                    return None
                import gzip

                with gzip.open(path, "rb") as g:
                    head = g.read(65536)
            elif magic == b"PK\x03\x04":
                with zipfile.ZipFile(path) as zf:
                    names = [n for n in zf.namelist() if not n.endswith("/")]
                    if len(names) != 1:
                        return None
                    full = zf.getinfo(names[0]).file_size
                    with zf.open(names[0]) as m:
                        head = m.read(65536)
            elif magic[:3] == b"BZh" or magic[:4] in (b"\xfd7zX", b"MATL", b"\x89HDF"):
                return None
            else:
                fh.seek(0)
                head, full = fh.read(65536), size
    except Exception:  # noqa: BLE001 - an estimate: the reader names what is wrong with the file
        return None
    lines = head.count(b"\n")
    if lines < 2:
        return None
    return int(full / (len(head) / lines))


def _hdr(header) -> str:
    s = ", ".join(str(h) for h in header)
    return s if len(s) < 200 else s[:200] + "..."


#: largest plausible sampling interval of undeclared time [s] (waves of 5-20 s need > 1 Hz)
MAX_DT_S = 1.0
#: longest plausible log of undeclared time [s]
MAX_SPAN_S = 2 * 86400.0


def _check_time_unit(t, declared: bool, src: str, header) -> None:
    """Undeclared time that looks like milliseconds (interval > 1 s or span > 2 days) is an error."""
    if declared:
        return
    d = np.diff(t[np.isfinite(t)])
    d = d[d > 0]
    if d.size == 0:
        return
    dt = float(np.median(d))
    span = float(np.nanmax(t) - np.nanmin(t))
    if dt > MAX_DT_S or span > MAX_SPAN_S:
        raise DataError(f"{src}: column 't' ({header!r}): median interval {dt:.4g} and span {span:.4g} in "
                        f"seconds is implausible for a heave log — time in milliseconds? declare its unit, t=ms "
                        "([measurement] units, or name the column 'Time [ms]')", option="units", example="t=ms")


def gaps(t, max_gap: float, factor: float = 3.0):
    """Indices i where ``t[i+1] - t[i]`` exceeds both ``factor`` median intervals and ``max_gap`` [s].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times, increasing.
    max_gap : float [s]
        Smallest interval that counts as a gap.
    factor : float [-]
        Smallest interval that counts as a gap, in median intervals.
    """
    d = np.diff(t)
    if d.size == 0:
        return np.array([], dtype=int)
    lim = max(max_gap, factor * float(np.median(d)))
    return np.flatnonzero(d > lim)


__all__ = ["Series", "read_series", "iter_chunks", "estimate_rows", "read_text", "parse_mapping", "check_spec", "split_header", "UNITS", "KINDS", "short",
           "gaps"]
