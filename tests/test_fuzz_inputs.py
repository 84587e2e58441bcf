"""Fuzzing measured runs and heave files (issue 14): the promise, on inputs a careless user or a rig
logger produces.

Every generated file is either

- accepted (exit 0) with the *right* numbers: the series the command works on equals the one the file
  was made from (in SI, after the declared conversions; missing where cells were emptied) — so a unit,
  a shifted row or a spline through a hole cannot pass as a confident answer; or
- refused with exit 2 and one line on stderr naming the column, the row or the file-level problem,

within a time and memory budget, never a traceback. Which of the two is decided by how the file was
made (the oracle below), not by what the code answers.

Measured runs go through ``heavecomp diagnose`` in-process (``heavecomp.cli.main``) up to the start of
the fitting: ``GapDiagnoser`` is replaced by a probe that receives the checked run and stops there —
the diagnosis itself is covered by its own tests and takes ~1 min per run. Heave files go through
``heavecomp simulate`` for real (20 s of simulated time) and the heave in ``timeseries.csv`` is
compared with the file's. A few cases run as subprocesses (``python -m heavecomp.cli``).

The default run draws a few examples of each (seconds); ``-m slow`` variants draw >= 60 each.
"""

from __future__ import annotations

import bz2
import gzip
import io
import lzma
import resource
import subprocess
import sys
import time
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from unittest import mock

import numpy as np
import pytest

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from heavecomp.cli import main
from heavecomp.params import dumps, paper_a
from heavecomp.signals import HEAVE_CUTOFF, flat_zero_phase

P = paper_a()
W0 = P.operating_point.wob_setpoint
ROOT = Path(__file__).resolve().parents[1]
TIME_BUDGET_S = 60.0       #: per file, in-process (generous: the shared CI machine is slow)
RSS_BUDGET_MB = 3000.0     #: peak resident memory of the test process
FILE_PROBLEMS = ("binary file", "empty file", "corrupt compressed", "cannot read", "not found", "not well-formed XML")
COUNTS = {"runs_accepted": 0, "runs_refused": 0, "heave_accepted": 0, "heave_refused": 0}

TEXT_FORMATS = ("csv", "semicolon_comma", "tab", "spaces", "gz", "bz2", "xz", "zip")
FORMATS = TEXT_FORMATS + ("parquet", "mat")
RUN_DEFECTS = ("none",) * 8 + ("nan_cells", "nan_cells", "inf_cell", "abs_pressure", "ragged_row", "dup_timestamp",
               "dup_column", "too_few", "too_short", "gap", "backwards", "text_cell", "empty", "binary")
RIG = {"t": ("Time", "ms", 1e3), "heave": ("MRU_heave", "m", 1.0), "stroke": ("CMC_pos", "mm", 1e3),
       "pressure": ("P_main", "bar", 1e-5), "wob": ("WOB", "kN", 1e-3)}


class _Reached(Exception):
    """Raised by the probe: the command accepted the run and was about to fit."""

    def __init__(self, run):
        super().__init__("reached the fit")
        self.run = run


class _Probe:
    def __init__(self, *a, **k):
        pass

    def fit(self, run):
        raise _Reached(run)


@dataclass
class Table:
    """A file to write: header, columns (floats or strings), how, and what should happen."""

    header: list
    cols: list
    fmt: str = "csv"
    encoding: str = "utf-8"
    argv: list = field(default_factory=list)
    toml_extra: str = ""
    refuse: str | None = None      #: fragment the one-line error must contain (None: must be accepted)
    text_edit: object = None       #: callable(lines) -> lines, applied to text formats
    raw: bytes | None = None       #: write these bytes instead


def _fmt_cell(v, decimal, blank=""):
    if isinstance(v, str):
        return v
    s = blank if np.isnan(v) else ("inf" if np.isinf(v) and v > 0 else ("-inf" if np.isinf(v) else repr(float(v))))
    return s.replace(".", ",") if decimal == "," else s


def write_table(tab: Table, path: Path) -> Path:
    """Write ``tab`` in its format; returns the path (with a fitting suffix)."""
    if tab.raw is not None:
        path.write_bytes(tab.raw)
        return path
    if tab.fmt == "parquet":
        import pandas as pd

        df = pd.DataFrame({h: c for h, c in zip(tab.header, tab.cols)})
        path = path.with_suffix(".parquet")
        df.to_parquet(path, index=False)
        return path
    if tab.fmt == "mat":
        import scipy.io

        path = path.with_suffix(".mat")
        scipy.io.savemat(path, {h: np.asarray(c, dtype=float) for h, c in zip(tab.header, tab.cols)})
        return path
    sep, decimal = {"semicolon_comma": (";", ","), "tab": ("\t", "."), "spaces": ("   ", ".")}.get(tab.fmt, (",", "."))
    lines = [sep.join(tab.header)]
    n = len(tab.cols[0])
    for i in range(n):
        lines.append(sep.join(_fmt_cell(c[i], decimal, "NaN" if sep.isspace() else "") for c in tab.cols))
    if tab.text_edit is not None:
        lines = tab.text_edit(lines, sep)
    text = "\n".join(lines) + "\n"
    if tab.encoding == "latin-1":
        data = ("# exported by Ølogger, station Ålesund\n" + text).encode("latin-1")
    elif tab.encoding == "utf-8-sig":
        data = text.encode("utf-8-sig")
    else:
        data = text.encode("utf-8")
    if tab.fmt == "gz":
        data, path = gzip.compress(data), path.with_suffix(".csv.gz")
    elif tab.fmt == "bz2":
        data, path = bz2.compress(data), path.with_suffix(".csv.bz2")
    elif tab.fmt == "xz":
        data, path = lzma.compress(data), path.with_suffix(".csv.xz")
    elif tab.fmt == "zip":
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as zf:
            zf.writestr("log.csv", data)
        data, path = buf.getvalue(), path.with_suffix(".zip")
    path.write_bytes(data)
    return path


# ---------------------------------------------------------------- measured runs
@st.composite
def measured_runs(draw):
    """(Table, expected SI columns or None)."""
    dt = draw(st.sampled_from([0.05, 0.1, 0.2]))
    span = draw(st.floats(65.0, 150.0))
    n = int(span / dt)
    seed = draw(st.integers(0, 2 ** 16))
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt + draw(st.sampled_from([0.0, 1.7e9, 12.5]))
    tp = draw(st.floats(6.0, 16.0))
    z = draw(st.floats(0.1, 2.0)) * np.sin(2 * np.pi * (t - t[0]) / tp + rng.uniform(0, 6))
    si = {"t": t, "heave": z, "stroke": -0.9 * z + 2e-3 * rng.normal(size=n),
          "pressure": P.p0 + 3e5 * z, "wob": W0 + 3e4 * z + 400 * rng.normal(size=n)}
    units = draw(st.sampled_from(["si", "si", "si", "rig_declared", "rig_declared", "rig_in_header",
                                  "rig_undeclared", "ms_undeclared"]))
    naming = draw(st.sampled_from(["exact", "upper", "spaced"])) if units in ("si", "ms_undeclared") else "rig"
    fmt = draw(st.sampled_from(FORMATS))
    enc = draw(st.sampled_from(["utf-8", "utf-8-sig", "latin-1"]))
    defect = draw(st.sampled_from(RUN_DEFECTS))
    if fmt in ("parquet", "mat") and defect in ("ragged_row", "dup_column", "text_cell", "empty"):
        defect = "none"
    if units in ("rig_declared", "rig_in_header") and defect == "abs_pressure":
        defect = "none"
    if fmt == "mat":  # MATLAB variable names: no spaces or brackets
        units = "rig_declared" if units == "rig_in_header" else units
        naming = "exact" if naming == "spaced" else naming
    names = list(si)
    expected = {k: v.copy() for k, v in si.items()}
    # defects on the values
    if defect == "nan_cells":
        for c in draw(st.lists(st.sampled_from(names[1:]), min_size=1, max_size=3)):
            idx = rng.choice(np.arange(5, n - 5), size=max(1, n // 200), replace=False)
            si[c] = si[c].copy()
            si[c][idx] = np.nan
            expected[c][idx] = np.nan
    elif defect == "inf_cell":
        c = draw(st.sampled_from(names[1:]))
        i = int(rng.integers(5, n - 5))
        si[c] = si[c].copy()
        si[c][i] = np.inf
        expected[c][i] = np.nan
    elif defect == "abs_pressure":
        si["pressure"] = si["pressure"] + 101325.0
        expected["pressure"] = si["pressure"].copy()
    elif defect == "too_few":
        k = draw(st.integers(0, 49))
        si = {c: v[:k] for c, v in si.items()}
    elif defect == "too_short":
        k = int(draw(st.floats(5.0, 55.0)) / dt)
        si = {c: v[:k] for c, v in si.items()}
    elif defect == "gap":
        a = int(rng.integers(n // 4, n // 2))
        length = min(int(draw(st.floats(3.0, 60.0)) / dt), n - a - 10)  # a hole, not a cut end
        keep = np.ones(n, bool)
        keep[a:a + length] = False
        si = {c: v[keep] for c, v in si.items()}
    elif defect == "dup_timestamp":
        i = int(rng.integers(1, n - 1))
        si = {c: np.insert(v, i, v[i]) for c, v in si.items()}
    elif defect == "backwards":
        i = int(rng.integers(1, n - 2))
        si["t"] = si["t"].copy()
        si["t"][[i, i + 1]] = si["t"][[i + 1, i]]
    # columns in the file's units and names
    cols, header, argv = [], [], []
    for c in names:
        name, unit, scale = RIG[c]
        if units == "si" or (units == "ms_undeclared" and c != "t"):
            h = {"exact": c, "upper": c.upper(), "spaced": f"  {c.capitalize()} "}[naming]
            cols.append(si[c])
        elif units == "ms_undeclared":
            h = {"exact": c, "upper": c.upper(), "spaced": f"  {c.capitalize()} "}[naming]
            cols.append(si[c] * 1e3)
        else:
            h = (f"{name}[{unit}]" if fmt == "spaces" else f"{name} [{unit}]") if units == "rig_in_header" else name
            cols.append(si[c] * scale)
        header.append(h)
    if units in ("rig_declared", "rig_undeclared", "rig_in_header"):
        argv += ["--columns", ",".join(f"{c}={RIG[c][0]}" for c in names)]
    if units == "rig_declared":
        argv += ["--units", "t=ms,stroke=mm,pressure=bar,wob=kN"]
    tab = Table(header=header, cols=cols, fmt=fmt, encoding=enc, argv=argv)
    if defect == "ragged_row":
        k = draw(st.integers(2, 40))

        def ragged(lines, sep, k=k):
            lines[k] = lines[k] + sep + "0.5"
            return lines
        tab.text_edit, tab.refuse = ragged, f"row {k + 1 + (enc == 'latin-1')} has 6 fields"
    elif defect == "dup_column":
        tab.header = header + [header[-1]]
        tab.cols = cols + [cols[-1]]
        tab.refuse = "appears twice"
    elif defect == "text_cell":
        k = draw(st.integers(3, 30))
        c = draw(st.integers(1, 4))
        col = [_fmt_cell(v, ".") for v in cols[c]]
        col[k] = draw(st.sampled_from(["n.a.", "ERR", "#VALUE!", "12..5", "1e"]))
        tab.cols = [*cols[:c], col, *cols[c + 1:]]
        tab.refuse = "not a number"
    elif defect == "empty":
        tab.raw = b"" if draw(st.booleans()) else b"\n\n"
        tab.refuse = "empty file"
    elif defect == "binary":
        tab.raw = bytes(rng.integers(0, 256, size=int(rng.integers(64, 4000)), dtype=np.uint8))
        tab.refuse = ""
    elif defect == "too_few":
        tab.refuse = "need at least 50 samples" if units not in ("rig_undeclared", "ms_undeclared") else ""
    elif defect == "too_short":
        tab.refuse = "column 't'"  # too few samples or too short a span, whichever is met first
    elif defect == "gap":
        tab.refuse = "without samples"
    elif defect == "inf_cell":  # the contract: non-finite values are an error (issue 21: was a dropout)
        tab.refuse = "non-finite value"
    elif defect in ("dup_timestamp", "backwards"):
        tab.refuse = "not strictly increasing"
    if units in ("rig_undeclared", "ms_undeclared") and tab.refuse is None:
        tab.refuse = "column 't'"      # ms time is named first
    elif units in ("rig_undeclared", "ms_undeclared") and tab.refuse not in ("", "empty file", "appears twice"):
        tab.refuse = ""                # two problems: any one-line naming answer will do
    expected["t"] = expected["t"] - expected["t"][0]
    return tab, (None if tab.refuse is not None else expected)


def _one_line(err: str, cmd: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"heavecomp {cmd}: error: "), err
    assert "Traceback" not in err
    return lines[0]


def _names_something(msg: str) -> bool:
    return "column '" in msg or "row " in msg or any(p in msg for p in FILE_PROBLEMS)


def _budget(t0):
    assert time.perf_counter() - t0 < TIME_BUDGET_S
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 < RSS_BUDGET_MB


def check_run_promise(tab: Table, expected, tmp: Path, capsys):
    nominal = tmp / "nominal.toml"
    nominal.write_text(dumps(P))
    path = write_table(tab, tmp / "run.csv")
    argv = ["diagnose", str(path), "--params", str(nominal), "--out", str(tmp / "out"), "--quiet", *tab.argv]
    t0 = time.perf_counter()
    # the command builds its diagnoser through calibrate.diagnoser (the file's effects in every replay)
    with mock.patch("heavecomp.diagnosis.estimator.GapDiagnoser", _Probe):  # diagnose builds it at call time
        try:
            rc = main(argv)
            run = None
        except _Reached as r:
            rc, run = 0, r.run
    _budget(t0)
    err = capsys.readouterr().err
    if expected is None:
        assert rc == 2 and run is None, (tab.refuse, err)
        msg = _one_line(err, "diagnose")
        assert _names_something(msg), msg
        assert tab.refuse in msg, (tab.refuse, msg)
        COUNTS["runs_refused"] += 1
        return
    assert rc == 0 and run is not None, err
    assert np.all(np.isfinite(run.t)) and np.all(np.diff(run.t) > 0)
    np.testing.assert_allclose(run.t, expected["t"], atol=1e-6 * max(1.0, abs(expected["t"][-1])) + 1e-6)
    for c in ("heave", "stroke", "pressure", "wob"):
        got, want = run[c], expected[c]
        miss = ~np.isfinite(want)
        assert np.all(~np.isfinite(got[miss])), c
        np.testing.assert_allclose(got[~miss], want[~miss], rtol=1e-7, atol=1e-9, err_msg=c)
    COUNTS["runs_accepted"] += 1


@pytest.fixture(scope="module", autouse=True)
def _report_counts():
    """After the module: how many generated files were accepted / refused (for the issue's note)."""
    yield
    import logging

    logging.getLogger(__name__).warning("fuzz counts: %s", COUNTS)
    sys.stderr.write(f"\nfuzz counts: {COUNTS}\n")


def fuzz(n):
    """Hypothesis settings: n examples, derandomized (the same files every run), no example database."""
    return settings(max_examples=n, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True,
                    database=None)


@fuzz(12)
@given(case=measured_runs())
def test_fuzz_measured_runs(case, tmp_path_factory, capsys):
    tab, expected = case
    check_run_promise(tab, expected, tmp_path_factory.mktemp("run"), capsys)


@pytest.mark.slow
@fuzz(80)
@given(case=measured_runs())
def test_fuzz_measured_runs_long(case, tmp_path_factory, capsys):
    tab, expected = case
    check_run_promise(tab, expected, tmp_path_factory.mktemp("run"), capsys)


# ---------------------------------------------------------------- heave files
DURATION = 20.0  #: simulated time [s]


@st.composite
def heave_files(draw):
    """(Table, (t, z) the simulation must see, or None when the file must be refused)."""
    dt = draw(st.sampled_from([0.1, 0.25, 0.5, 0.78125]))
    n = int(draw(st.floats(40.0, 90.0)) / dt)
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 16)))
    t = np.arange(n) * dt
    tp = draw(st.floats(6.0, 16.0))
    z = draw(st.floats(0.2, 3.0)) * np.sin(2 * np.pi * t / tp + rng.uniform(0, 6)) + 0.05 * rng.normal(size=n)
    fmt = draw(st.sampled_from(FORMATS))
    enc = draw(st.sampled_from(["utf-8", "utf-8-sig", "latin-1"]))
    naming = draw(st.sampled_from(["exact", "exact", "units_header", "rig_mapped", "ms_declared", "ms_declared",
                                   "ms_undeclared", "mm_undeclared"]))
    defect = draw(st.sampled_from(["none"] * 6 + ["short_gap"] * 2 + ["nan_cell", "long_gap", "dup_timestamp",
                                   "backwards", "ragged_row", "dup_column", "too_few", "too_short_record",
                                   "binary"]))
    if fmt in ("parquet", "mat") and defect in ("ragged_row", "dup_column"):
        defect = "none"
    refuse = None
    if defect == "nan_cell":
        z = z.copy()
        z[int(rng.integers(3, n - 3))] = np.nan
        refuse = "missing or non-finite"
    elif defect in ("short_gap", "long_gap"):
        a = int(rng.integers(n // 4, n // 2))
        length = 1 if defect == "short_gap" else min(1 + int(draw(st.floats(4.0, 60.0)) / dt), n - a - 10)
        keep = np.ones(n, bool)
        keep[a:a + length] = False
        t, z = t[keep], z[keep]
        if defect == "long_gap":
            refuse = "without heave samples"
    elif defect == "dup_timestamp":
        i = int(rng.integers(1, n - 1))
        t, z = np.insert(t, i, t[i]), np.insert(z, i, z[i])
        refuse = "not strictly increasing"
    elif defect == "backwards":
        i = int(rng.integers(1, n - 2))
        t = t.copy()
        t[[i, i + 1]] = t[[i + 1, i]]
        refuse = "not strictly increasing"
    elif defect == "too_few":
        t, z = t[:3], z[:3]
        refuse = "need at least 4 samples"
    elif defect == "too_short_record":
        keep = t < draw(st.floats(3.0, DURATION - 2.0))
        t, z = t[keep], z[keep]
        refuse = "exceeds the heave record's span"
    header, cols, toml = ["t", "heave"], [t, z], ""
    if naming == "units_header":
        header = ["Time[s]", "Heave(m)"] if fmt in ("spaces", "mat") else ["Time [s]", "Heave (m)"]
    elif naming == "rig_mapped":
        header = ["Zeit", "MRU_Heave"]
        toml = '\n[measurement]\ncolumns = { t = "Zeit", heave = "MRU_Heave" }\n'
    elif naming == "ms_declared":
        cols = [t * 1e3, z]
        toml = '\n[measurement]\nunits = { t = "ms" }\n'
    elif naming == "ms_undeclared":
        cols = [t * 1e3, z]
        refuse = "column 't'"  # ms detection, or too few samples: both name 't'
        if defect == "dup_column":
            refuse = "appears twice"
    elif naming == "mm_undeclared":
        cols = [t, z * 1e3]
        if refuse is None or refuse in ("without heave samples", "exceeds the heave record's span"):
            refuse = ""
    tab = Table(header=header, cols=cols, fmt=fmt, encoding=enc, toml_extra=toml, refuse=refuse)
    if defect == "ragged_row":
        k = draw(st.integers(2, 20))

        def ragged(lines, sep, k=k):
            lines[k] = lines[k] + sep + "1.5"
            return lines
        tab.text_edit = ragged
        tab.refuse = "has 3 fields" if naming not in ("ms_undeclared",) else ""
    elif defect == "dup_column":
        tab.header, tab.cols = header + [header[1]], cols + [cols[1]]
        tab.refuse = "appears twice"
    elif defect == "binary":
        tab.raw = bytes(rng.integers(0, 256, size=int(rng.integers(64, 4000)), dtype=np.uint8))
        tab.refuse = ""
    return tab, (None if tab.refuse is not None else (t, z))


@pytest.fixture(scope="module")
def warm():
    """Compile the stepper once (numba, when the ahead-of-time build is absent) outside the time budget."""
    from heavecomp.simulate import simulate

    simulate(P, 1.0)


def check_heave_promise(tab: Table, expected, tmp: Path, capsys):
    path = write_table(tab, tmp / "heave.csv")
    p = P.replace(heave={"kind": "file", "path": path.name, "amplitude": None, "period": None, "ramp": None})
    ptoml = tmp / "p.toml"
    ptoml.write_text(dumps(p) + tab.toml_extra)
    t0 = time.perf_counter()
    rc = main(["simulate", str(ptoml), "--duration", str(DURATION), "--out", str(tmp / "out"), "--rate", "10"])
    _budget(t0)
    err = capsys.readouterr().err
    if expected is None:
        assert rc == 2, (tab.refuse, err)
        msg = _one_line(err, "simulate")
        assert _names_something(msg) or "heave record" in msg, msg
        assert tab.refuse in msg, (tab.refuse, msg)
        COUNTS["heave_refused"] += 1
        return
    assert rc == 0, err
    ts = np.genfromtxt(tmp / "out" / "timeseries.csv", delimiter=",", names=True)
    for c in ts.dtype.names:
        assert np.all(np.isfinite(ts[c])), c
    t, z = expected
    # linear through the samples (holes bridged linearly) on the file's own step, then the documented heave
    # pre-processing (excitation.PREPROCESSING: zero-phase low-pass at HEAVE_CUTOFF, the first filtered sample
    # as reference): what reaches the plant is the file's heave, not its content above the wave band
    dt = float(np.median(np.diff(t)))
    tu = np.arange(t[0], t[-1] + 1e-9 * dt, dt)
    zf = flat_zero_phase(np.interp(tu, t, z), 1.0 / dt, HEAVE_CUTOFF)
    want = np.interp(ts["t"], tu - t[0], zf - zf[0])
    amp = float(np.ptp(z))
    assert np.max(np.abs(ts["heave"] - want)) < 0.05 + 0.03 * amp, "the simulated heave is not the file's"
    COUNTS["heave_accepted"] += 1


@fuzz(6)
@given(case=heave_files())
def test_fuzz_heave_files(case, tmp_path_factory, capsys, warm):
    tab, expected = case
    check_heave_promise(tab, expected, tmp_path_factory.mktemp("heave"), capsys)


@pytest.mark.slow
@fuzz(60)
@given(case=heave_files())
def test_fuzz_heave_files_long(case, tmp_path_factory, capsys, warm):
    tab, expected = case
    check_heave_promise(tab, expected, tmp_path_factory.mktemp("heave"), capsys)


# ---------------------------------------------------------------- as a user runs it: subprocesses
@pytest.mark.parametrize("content", [
    b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 8,
    gzip.compress(b"t;heave;stroke;pressure;wob\n0;0,1;0;2,4;98\n", mtime=0),
    "t,heave,stroke,pressure,wob\n".encode("utf-16"),
], ids=["binary", "gzip_semicolons", "utf16"])  # ids, not the bytes (gzip's header held the time of collection)
def test_subprocess_odd_logs_one_line(tmp_path, content):
    f = tmp_path / "log.csv"
    f.write_bytes(content)
    nominal = tmp_path / "n.toml"
    nominal.write_text(dumps(P))
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "diagnose", str(f), "--params", str(nominal),
                        "--out", str(tmp_path / "o"), "--quiet"], capture_output=True, text=True, timeout=120,
                       cwd=ROOT)
    assert r.returncode == 2, r.stderr
    msg = _one_line(r.stderr, "diagnose")
    assert _names_something(msg), msg


# ---------------------------------------------------------------- drilling logs (WITSML 1.4.1.1, LAS 2.0)
#: rig units of a drilling log: contract column -> [(unit, SI per unit)]
LOG_UNITS = {"heave": [("m", 1.0), ("ft", 0.3048), ("in", 0.0254)], "stroke": [("m", 1.0), ("in", 0.0254), ("mm", 1e-3)],
             "pressure": [("psi", 6894.757), ("kPa", 1e3), ("bar", 1e5)],
             "wob": [("klbf", 4448.22), ("kkgf", 9806.65), ("kN", 1e3), ("daN", 10.0)]}
LOG_MNEMONICS = {"heave": ("HEAVE", "MRU_HEAVE", "RIG_HEAVE"), "stroke": ("CMC_POS", "CMC_STROKE"),
                 "pressure": ("CMC_PRES", "COMP_PRES"), "wob": ("WOB", "SWOB")}
LOG_DEFECTS = ("none",) * 6 + ("nulls", "unknown_unit", "missing_heave", "depth_index", "truncated")


@st.composite
def drilling_logs(draw):
    """(Table of raw bytes, expected SI columns or None): a WITSML or LAS log in rig units."""
    from heavecomp.io import logs

    kind = draw(st.sampled_from(["witsml", "witsml_datetime", "las"]))
    dt = draw(st.sampled_from([0.1, 0.2]))
    n = int(draw(st.floats(65.0, 120.0)) / dt)
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 16)))
    t = np.arange(n) * dt
    z = draw(st.floats(0.1, 2.0)) * np.sin(2 * np.pi * t / draw(st.floats(6.0, 16.0)) + rng.uniform(0, 6))
    si = {"t": t, "heave": z, "stroke": -0.9 * z + 2e-3 * rng.normal(size=n), "pressure": P.p0 + 3e5 * z,
          "wob": W0 + 3e4 * z + 400 * rng.normal(size=n)}
    defect = draw(st.sampled_from(LOG_DEFECTS))
    channels, units, expected = {"TIME": t}, {"TIME": "s"}, {k: v.copy() for k, v in si.items()}
    refuse = None
    for c in ("heave", "stroke", "pressure", "wob"):
        m = draw(st.sampled_from(LOG_MNEMONICS[c]))
        u, f = draw(st.sampled_from(LOG_UNITS[c]))
        channels[m], units[m] = si[c] / f, u
        expected[c] = channels[m] * f
    mn = {c: next(m for m in channels if m in LOG_MNEMONICS.get(c, ())) for c in LOG_MNEMONICS}
    if defect == "nulls":
        idx = rng.choice(np.arange(5, n - 5), size=max(1, n // 200), replace=False)
        channels[mn["wob"]] = channels[mn["wob"]].copy()
        channels[mn["wob"]][idx] = np.nan
        expected["wob"][idx] = np.nan
    elif defect == "unknown_unit":
        units[mn["wob"]], refuse = "klbs", "unknown unit 'klbs'"
    elif defect == "missing_heave":
        del channels[mn["heave"]]
        refuse = "missing column 'heave'"
    elif defect == "depth_index":
        channels = {"DEPT": 1000.0 + t, **{k: v for k, v in channels.items() if k != "TIME"}}
        units["DEPT"] = "m"
        refuse = "a time index is needed"
    expected["t"] = t
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "log"
        index = "DEPT" if defect == "depth_index" else "TIME"
        if kind == "las":
            logs.write_las(f, channels, units, index=index)
        else:
            logs.write_witsml(f, channels, units, index=index, null="-999.25" if defect == "nulls" else None,
                              start="2026-11-02T06:00:00Z" if kind == "witsml_datetime" and index == "TIME" else None)
            if defect == "depth_index":
                f.write_text(f.read_text().replace("elapsed time", "measured depth"))
        raw = f.read_bytes()
    if defect == "truncated":
        raw = raw[: int(len(raw) * 0.6)]
        refuse = "not well-formed XML" if kind != "las" else "row "
        if kind == "las":  # a LAS file cut mid-row: lasio reads the rows before it; the torn row is short
            refuse, expected = None, None
    tab = Table(header=[], cols=[], raw=raw, refuse=refuse)
    return tab, (None if refuse is not None else expected), kind == "las" and defect == "truncated"


@fuzz(10)
@given(case=drilling_logs())
def test_fuzz_drilling_logs(case, tmp_path_factory, capsys):
    """WITSML and LAS logs in rig units: read to the SI run they were made from, or one line naming the
    column (unknown unit, missing mnemonic), the index (depth) or the file (not well-formed)."""
    pytest.importorskip("lasio")
    tab, expected, torn_las = case
    if torn_las:  # either accepted or one line: the torn LAS row is a reader's judgement, not an oracle's
        tmp = tmp_path_factory.mktemp("run")
        nominal = tmp / "nominal.toml"
        nominal.write_text(dumps(P))
        path = write_table(tab, tmp / "run.csv")
        with mock.patch("heavecomp.diagnosis.estimator.GapDiagnoser", _Probe):
            try:
                rc = main(["diagnose", str(path), "--params", str(nominal), "--out", str(tmp / "o"), "--quiet"])
            except _Reached:
                rc = 0
        err = capsys.readouterr().err
        assert rc == 0 or (rc == 2 and len(err.strip().splitlines()) == 1), err
        return
    check_run_promise(tab, expected, tmp_path_factory.mktemp("run"), capsys)
