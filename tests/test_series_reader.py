"""Measured series in any reasonable shape, through one reader (issue 13 item 2), and the
silent-wrong-answer / traceback cases of issue 14 (items 4, 5, 8, 11) as CLI regressions:
exit 2, one line, naming the column / row / key."""

from __future__ import annotations

import bz2
import gzip
import io
import lzma
import zipfile

import numpy as np
import pytest

from heavecomp.cli import main
from heavecomp.diagnosis.data import load_run
from heavecomp.errors import DataError, InputError
from heavecomp.io.series import read_series, split_header
from heavecomp.params import dumps, paper_a

P = paper_a()
SI_COLS = ("t", "heave", "stroke", "pressure", "wob")


def _si(n=1200, dt=0.1, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    z = 0.5 * np.sin(2 * np.pi * t / 10)
    return {"t": t, "heave": z, "stroke": -0.9 * z + 1e-3 * rng.normal(size=n),
            "pressure": P.p0 + 1e5 * z, "wob": P.operating_point.wob_setpoint + 2e4 * z}


def _csv(cols, header=SI_COLS, scale=None, sep=",", decimal=".", fmt="{:.6f}"):
    scale = scale or {}
    lines = [sep.join(header)]
    names = list(cols)
    for i in range(len(next(iter(cols.values())))):
        cells = [fmt.format(cols[c][i] * scale.get(c, 1.0)) for c in names]
        if decimal == ",":
            cells = [c.replace(".", ",") for c in cells]
        lines.append(sep.join(cells))
    return "\n".join(lines) + "\n"


def _cli_err(argv, capsys):
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    return err


@pytest.fixture
def nominal(tmp_path):
    f = tmp_path / "nominal.toml"
    f.write_text(dumps(P))
    return f


def _diag(tmp_path, run, nominal, *extra):
    return ["diagnose", str(run), "--params", str(nominal), "--out", str(tmp_path / "out"), "--quiet", *extra]


# ---------------------------------------------------------------- shapes that must read the same
RIG = {"t": 1e3, "stroke": 1e3, "pressure": 1e-5, "wob": 1e-3}  # s->ms, m->mm, Pa->bar, N->kN


def _rig_frame(cols):
    return {"Time": cols["t"] * 1e3, "MRU_heave": cols["heave"], "CMC_pos": cols["stroke"] * 1e3,
            "P_main": cols["pressure"] * 1e-5, "WOB": cols["wob"] * 1e-3}


MAP = {"t": "Time", "heave": "MRU_heave", "stroke": "CMC_pos", "pressure": "P_main", "wob": "WOB"}
UNITS = {"t": "ms", "pressure": "bar", "wob": "kN", "stroke": "mm"}


def _writers():
    def csv_semicolon_comma(path, cols):
        path.write_text(_csv(_rig_frame(cols), header=list(MAP.values()), sep=";", decimal=","), encoding="utf-8")

    def csv_tab_bom(path, cols):
        path.write_text("\ufeff" + _csv(_rig_frame(cols), header=list(MAP.values()), sep="\t"), encoding="utf-8")

    def csv_gz(path, cols):
        path.write_bytes(gzip.compress(_csv(_rig_frame(cols), header=list(MAP.values())).encode()))

    def csv_bz2(path, cols):
        path.write_bytes(bz2.compress(_csv(_rig_frame(cols), header=list(MAP.values())).encode()))

    def csv_xz(path, cols):
        path.write_bytes(lzma.compress(_csv(_rig_frame(cols), header=list(MAP.values())).encode()))

    def csv_zip(path, cols):
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as zf:
            zf.writestr("log.csv", _csv(_rig_frame(cols), header=list(MAP.values())))
        path.write_bytes(buf.getvalue())

    def parquet(path, cols):
        import pandas as pd

        pd.DataFrame(_rig_frame(cols)).to_parquet(path)

    def mat(path, cols):
        import scipy.io

        scipy.io.savemat(path, {k: v for k, v in _rig_frame(cols).items()})

    def whitespace_latin1(path, cols):
        text = _csv(_rig_frame(cols), header=list(MAP.values()), sep="  ")
        path.write_bytes(("# logged at Møre rig\n" + text).encode("latin-1"))

    return {"semicolon_decimal_comma.csv": csv_semicolon_comma, "tab_bom.tsv": csv_tab_bom, "log.csv.gz": csv_gz,
            "log.csv.bz2": csv_bz2, "log.csv.xz": csv_xz, "log.zip": csv_zip, "log.parquet": parquet,
            "log.mat": mat, "whitespace_latin1.txt": whitespace_latin1}


@pytest.mark.parametrize("name", list(_writers()))
def test_every_format_reads_to_the_same_si_run(tmp_path, name):
    cols = _si()
    f = tmp_path / name
    _writers()[name](f, cols)
    run = load_run(f, P, columns=MAP, units=UNITS)
    for c in SI_COLS[1:]:
        np.testing.assert_allclose(run[c], cols[c], rtol=1e-5, atol=1e-6 * np.abs(cols[c]).max(), err_msg=c)
    np.testing.assert_allclose(run.t, cols["t"], atol=1e-6)
    m = run.measurement
    assert m["columns"] == MAP
    assert "pressure: bar -> Pa (x 100000)" in m["conversions"] and "t: ms -> s (x 0.001)" in m["conversions"]


def test_header_units_case_and_iso_time(tmp_path):
    cols = _si()
    stamps = np.datetime64("2026-11-22T06:00:00") + (cols["t"] * 1e3).astype("timedelta64[ms]")
    lines = ["TIME ,  Heave [m] , Stroke [mm], Pressure (bar), WOB_kN"]
    for i in range(cols["t"].size):
        lines.append(f"{stamps[i]}Z,{cols['heave'][i]:.6f},{cols['stroke'][i] * 1e3:.4f},"
                     f"{cols['pressure'][i] * 1e-5:.6f},{cols['wob'][i] * 1e-3:.5f}")
    f = tmp_path / "iso.csv"
    f.write_text("\n".join(lines) + "\n")
    run = load_run(f, P)
    np.testing.assert_allclose(run.t, cols["t"], atol=1e-9)
    np.testing.assert_allclose(run["wob"], cols["wob"], rtol=1e-6)
    assert run.measurement["units"]["t"] == "timestamp" and run.measurement["units"]["stroke"] == "mm"


def test_split_header():
    assert split_header("Time [ms]") == ("time", "ms")
    assert split_header("  WOB  (kN) ") == ("wob", "kN")
    assert split_header("pressure_bar") == ("pressure", "bar")
    assert split_header("heave_velocity") == ("heave_velocity", None)


def test_measurement_table_in_the_parameter_file(tmp_path):
    cols = _si()
    f = tmp_path / "log.csv"
    f.write_text(_csv(_rig_frame(cols), header=list(MAP.values())))
    p = P.replace(measurement={"columns": MAP, "units": UNITS})
    run = load_run(f, p)
    np.testing.assert_allclose(run["pressure"], cols["pressure"], rtol=1e-6)
    # the table round-trips through TOML, and the command line overrides it key by key
    from heavecomp.params import loads

    assert loads(dumps(p)).extra["measurement"].units == UNITS
    with pytest.raises(DataError, match="column 'wob'.*looks like kN"):
        load_run(f, p, units={"wob": "N"})


@pytest.mark.parametrize("table,fragment", [
    ({"units": {"pressure": "kN"}}, "measurement.units.pressure: 'kN' is a force unit"),
    ({"units": {"wob": "kilonewton"}}, "measurement.units.wob: unknown unit 'kilonewton'"),
    ({"columns": {"whob": "WOB"}}, "measurement.columns.whob: not a contract column (did you mean 'wob'?)"),
    ({"colums": {}}, "measurement.colums: unknown key (did you mean 'columns'?)"),
    ({"columns": "Time"}, "measurement.columns: expected an inline table"),
])
def test_bad_measurement_table_names_the_key(tmp_path, capsys, table, fragment):
    with pytest.raises(InputError) as e:
        P.replace(measurement=table)
    assert fragment in str(e.value)
    f = tmp_path / "p.toml"
    f.write_text(dumps(P) + "\n[measurement]\n" + "\n".join(
        f"{k} = " + ("{ " + ", ".join(f'{a} = "{b}"' for a, b in v.items()) + " }" if isinstance(v, dict) else f'"{v}"')
        for k, v in table.items()) + "\n")
    assert fragment in _cli_err(["params", str(f)], capsys)


# ---------------------------------------------------------------- CLI: rig log end to end (reading)
def test_cli_columns_units_bad_values(tmp_path, nominal, capsys):
    f = tmp_path / "log.csv"
    f.write_text(_csv(_rig_frame(_si()), header=list(MAP.values())))
    err = _cli_err(_diag(tmp_path, f, nominal, "--columns", "t=Time,heave=Heave"), capsys)
    assert "column 'heave' mapped to 'Heave': no such column" in err
    err = _cli_err(_diag(tmp_path, f, nominal, "--units", "t=fortnight"), capsys)
    assert "--units t: unknown unit 'fortnight'" in err
    err = _cli_err(_diag(tmp_path, f, nominal, "--units", "t"), capsys)
    assert "--units: expected NAME=VALUE" in err


def test_cli_undeclared_rig_units_name_the_column(tmp_path, nominal, capsys):
    """Without --units the rig log is refused, column by column, with the likely unit — never diagnosed."""
    f = tmp_path / "log.csv"
    f.write_text(_csv(_rig_frame(_si()), header=list(MAP.values())))
    cols = ",".join(f"{k}={v}" for k, v in MAP.items())
    err = _cli_err(_diag(tmp_path, f, nominal, "--columns", cols), capsys)
    assert "column 't'" in err and "milliseconds" in err and "--units t=ms" in err       # issue 14 item 5
    err = _cli_err(_diag(tmp_path, f, nominal, "--columns", cols, "--units", "t=ms"), capsys)
    assert "column 'pressure'" in err and "bar" in err


def test_absolute_pressure_gets_a_warning(tmp_path):
    cols = _si()
    cols["pressure"] = cols["pressure"] + 101325.0
    f = tmp_path / "abs.csv"
    f.write_text(_csv(cols))
    run = load_run(f, P)
    assert any("absolute" in w and "bara" in w for w in run.warnings)
    run_g = load_run(f, P, units={"pressure": "Pa_abs"})
    np.testing.assert_allclose(run_g["pressure"], _si()["pressure"], rtol=1e-9)
    assert not any("absolute" in w for w in run_g.warnings)


# ---------------------------------------------------------------- issue 14: silent wrong answers, tracebacks
def test_stray_delimiter_names_the_row(tmp_path, nominal, capsys):
    text = _csv(_si()).splitlines()
    text[7] = text[7].replace(",", ",,", 1)          # one row gets an extra field
    f = tmp_path / "ragged.csv"
    f.write_text("\n".join(text) + "\n")
    err = _cli_err(_diag(tmp_path, f, nominal), capsys)
    assert "row 8 has 6 fields, the header has 5" in err


@pytest.mark.parametrize("header,fragment", [
    ("t,heave,stroke,pressure,wob,wob", "column 'wob' appears twice in the header (columns 5 and 6)"),
    ("t,heave,stroke,pressure,wob,WOB", "'wob', 'WOB' all look like 'wob'"),
])
def test_duplicate_column_names_are_refused(tmp_path, nominal, capsys, header, fragment):
    """Two columns of one name: the last one used to win silently."""
    text = _csv(_si()).splitlines()
    text = [header] + [ln + "," + ln.split(",")[-1] for ln in text[1:]]
    f = tmp_path / "dup.csv"
    f.write_text("\n".join(text) + "\n")
    assert fragment in _cli_err(_diag(tmp_path, f, nominal), capsys)


@pytest.mark.parametrize("n,dt,fragment", [(10, 0.1, "need at least 50 samples"), (49, 0.1, "need at least 50"),
                                           (120, 0.1, "the run spans 11.9 s; diagnose needs at least 60 s"),
                                           (200, 0.25, "the run spans 49.8 s")])
def test_too_short_run_is_one_line(tmp_path, nominal, capsys, n, dt, fragment):
    """50-200 samples used to end in an IndexError or a 'medium confidence' verdict from 5 s of data."""
    cols = _si(n=n, dt=dt)
    f = tmp_path / "short.csv"
    f.write_text(_csv(cols))
    assert fragment in _cli_err(_diag(tmp_path, f, nominal), capsys)


def test_binary_and_unreadable_files(tmp_path, nominal, capsys):
    f = tmp_path / "blob.csv"
    f.write_bytes(bytes(range(256)) * 40)
    assert "binary file" in _cli_err(_diag(tmp_path, f, nominal), capsys)
    g = tmp_path / "broken.csv.gz"
    g.write_bytes(gzip.compress(b"t,heave\n" * 100)[:-12])  # cut before the trailer
    assert "corrupt compressed file" in _cli_err(_diag(tmp_path, g, nominal), capsys)
    long = tmp_path / ("x" * 5000 + ".csv")
    err = _cli_err(_diag(tmp_path, long, nominal), capsys)
    assert len(err) < 400 and "cannot read" in err or "file not found" in err


def test_bom_and_decimal_comma_get_the_right_explanation(tmp_path):
    """A BOM used to give "missing column 't'"; a decimal comma in a comma-separated file now
    says so (issue 14 item 11)."""
    cols = _si()
    f = tmp_path / "bom.csv"
    f.write_bytes(b"\xef\xbb\xbf" + _csv(cols).encode())
    assert load_run(f, P).t.size == cols["t"].size
    g = tmp_path / "comma.csv"
    g.write_text(_csv(cols, decimal=","))
    with pytest.raises(DataError, match="a stray delimiter or a decimal comma"):
        load_run(g, P)
    h = tmp_path / "comma1.csv"
    h.write_text("t,heave,stroke,pressure,wob\n" + "\n".join(
        f'{t:.1f},"{z:.3f}",0,{P.p0:.1f},{P.operating_point.wob_setpoint:.1f}'.replace('"0.', '"0,').replace('"-0.', '"-0,')
        for t, z in zip(cols["t"], cols["heave"])) + "\n")
    with pytest.raises(DataError, match="column 'heave', row 2: not a number.*decimal comma"):
        load_run(h, P)


def test_hole_in_the_time_column_is_refused(tmp_path, nominal, capsys):
    cols = _si(n=3000)
    keep = (cols["t"] < 100) | (cols["t"] >= 160)
    f = tmp_path / "hole.csv"
    f.write_text(_csv({k: v[keep] for k, v in cols.items()}))
    err = _cli_err(_diag(tmp_path, f, nominal), capsys)
    assert "column 't', row 1002" in err and "without samples" in err


# ---------------------------------------------------------------- heave files
def _heave_params(tmp_path, heave_file, measurement=None):
    p = P.replace(heave={"kind": "file", "path": heave_file.name, "amplitude": None, "period": None, "ramp": None})
    if measurement:
        p = p.replace(measurement=measurement)
    f = tmp_path / "p.toml"
    f.write_text(dumps(p))
    return f


def test_heave_file_60s_hole_refused_short_hole_bridged_linearly(tmp_path, capsys, caplog):
    """A 60 s hole used to be bridged by a spline inventing +-2.9 m; now it is refused by row, and a
    short hole is bridged by a straight line (the heave stays between its neighbours)."""
    from heavecomp.simulate.excitation import from_series

    t = np.arange(0, 400, 0.5)
    z = 0.8 * np.sin(2 * np.pi * t / 11.0)
    keep = (t < 100) | (t >= 160)
    f = tmp_path / "heave.csv"
    f.write_text("t,heave\n" + "\n".join(f"{a:.2f},{b:.5f}" for a, b in zip(t[keep], z[keep])) + "\n")
    err = _cli_err(["simulate", str(_heave_params(tmp_path, f)), "--duration", "300", "--out", str(tmp_path / "o")],
                   capsys)
    assert "column 't', row 202" in err and "60.5 s without heave samples" in err
    # a 1.5 s hole at 0.5 s sampling: bridged linearly (the spline alone would swing past the neighbours)
    keep2 = (t < 100) | (t >= 101.5)
    hs = from_series(t[keep2], z[keep2], 300.0, 0.05)
    inside = (hs.t > 99.5) & (hs.t < 101.5)
    lo, hi = sorted((z[t == 99.5][0], z[t == 101.5][0]))
    assert np.all(hs.z[inside] >= lo - z[0] - 1e-9) and np.all(hs.z[inside] <= hi - z[0] + 1e-9)
    assert "bridged linearly" in caplog.text


def test_heave_file_in_a_rig_shape(tmp_path):
    from heavecomp.params import load
    from heavecomp.simulate.excitation import make_heave

    t = np.arange(0, 200, 0.1)
    z = 0.8 * np.sin(2 * np.pi * t / 11.0)
    f = tmp_path / "mru.csv.gz"
    f.write_bytes(gzip.compress(("Zeit;MRU Heave\n" + "\n".join(
        f"{a * 1e3:.0f};{b * 1e3:.3f}".replace(".", ",") for a, b in zip(t, z)) + "\n").encode("latin-1")))
    p = load(_heave_params(tmp_path, f, {"columns": {"t": "Zeit", "heave": "MRU Heave"},
                                         "units": {"t": "ms", "heave": "mm"}}))
    hs = make_heave(p.heave, 100.0, 0.05, p.base_dir, measurement=p.extra["measurement"])
    # the heave is read in mm and ms and low-passed as the diagnosis' replay does (flat pass band: a 11 s wave
    # passes to within its 0.04 % ripple, 0.3 mm of 0.8 m)
    np.testing.assert_allclose(hs.z[::2][:1000], (z - z[0])[:1000], atol=5e-4)


@pytest.mark.parametrize("content,fragment", [
    (b"\xff\xfe\x00\x01garbage" * 50, "binary file"),
    (gzip.compress(b"t,heave\n0,0\n1,0.1\n2,0.2\n", mtime=0), "need at least 4 samples, got 3"),
    ("t,heave\n0,0\n1,0.1\n2,0.2\n3,0.1\n4,0\n5,0.5\n".encode("cp1252") + b"6,\x80\n", "column 'heave', row 8: not a number"),
])
def test_odd_heave_files_one_line(tmp_path, capsys, content, fragment):
    f = tmp_path / "h.csv"
    f.write_bytes(content)
    err = _cli_err(["simulate", str(_heave_params(tmp_path, f)), "--duration", "2", "--out", str(tmp_path / "o")],
                   capsys)
    assert fragment in err


# ---------------------------------------------------------------- identification loaders
def test_identify_odd_files_one_line(tmp_path, capsys, data_dir):
    """Seal files gzip-compressed read like the plain ones; binary, Latin-1 garbage and a 5000-character
    path are one line, exit 2 (issue 14 item 8)."""
    from heavecomp.identification.seal import load_seal_csv

    plain = data_dir / "seal-friction" / "O-ring_1bar.csv"
    gz = tmp_path / "O-ring_1bar.csv.gz"
    gz.write_bytes(gzip.compress(plain.read_bytes()))
    a, b = load_seal_csv(plain), load_seal_csv(gz)
    np.testing.assert_array_equal(a.force, b.force)
    blob = tmp_path / "blob.csv"
    blob.write_bytes(bytes(range(256)) * 20)
    err = _cli_err(["identify", "seal", str(plain), str(blob), "--out", str(tmp_path / "o")], capsys)
    assert "blob.csv: binary file" in err
    latin = tmp_path / "latin.csv"
    latin.write_bytes(plain.read_bytes()[:2000] + "é\n".encode("latin-1"))
    err = _cli_err(["identify", "seal", str(plain), str(latin), "--out", str(tmp_path / "o")], capsys)
    assert "latin.csv: row" in err
    long = "/" + "y" * 5000 + ".mat"
    err = _cli_err(["identify", "emps", long, "--out", str(tmp_path / "o")], capsys)
    assert len(err) < 300


def test_heave_spike_is_named_not_blamed_on_dt(tmp_path, capsys):
    """Issue 14 item 11: a one-sample spike in a heave file is named by row. Before, a 40 m spike ended
    in "stepper diverged ... reduce --dt" and an 8 m one was simulated silently (WOB peak-to-peak
    557 kN). The same record without the spike, and the shipped buoy record, pass."""
    from heavecomp.data import WAVERIDER
    from heavecomp.simulate.excitation import _check_series, load_waverider

    t = np.arange(0, 120, 0.1)
    rng = np.random.default_rng(3)
    z = 1.2 * np.sin(2 * np.pi * t / 9.0) + 0.02 * rng.normal(size=t.size)
    _check_series(t, z, "clean")
    z[400] += 8.0
    f = tmp_path / "spiky.csv"
    f.write_text("t,heave\n" + "\n".join(f"{a:.2f},{b:.5f}" for a, b in zip(t, z)) + "\n")
    err = _cli_err(["simulate", str(_heave_params(tmp_path, f)), "--duration", "60", "--out", str(tmp_path / "o")],
                   capsys)
    assert "column 'heave', row 402: a spike of +" in err and "--dt" not in err
    tb, zb = load_waverider(WAVERIDER)
    _check_series(tb, zb, "waverider")  # real buoy heave at 1.28 Hz: no false alarm
