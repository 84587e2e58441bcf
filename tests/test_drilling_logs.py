"""Drilling-system logs (WITSML 1.4.1.1, LAS 2.0) read by the one reader (issue 33): mnemonics mapped by
the default table or ``--columns``, rig units converted and recorded, the refusals, and the same
verdict as the CSV of the same run."""

from __future__ import annotations

import json

import numpy as np
import pytest

from heavecomp.data import EXAMPLE_PARAMS, EXAMPLE_RUN
from heavecomp.errors import DataError
from heavecomp.io import logs
from heavecomp.io.series import read_series

from _cli import run

MAP = dict(t="Time", heave="MRU_heave", stroke="CMC_pos", pressure="P_main", wob="WOB")
UNITS = dict(t="ms", pressure="bar", wob="kN", stroke="mm")
OPTIONAL = ("stroke", "pressure", "wob", "hook_load")
#: rig units each channel is written in (factor: SI per unit)
RIG = {"HEAVE": ("ft", 0.3048), "CMC_POS": ("in", 0.0254), "CMC_PRES": ("psi", 6894.757), "WOB": ("klbf", 4448.22)}


def _example():
    """The shipped example run (heavecomp's simulator, nominal parameters) in SI."""
    return read_series(EXAMPLE_RUN, ("t", "heave"), optional=OPTIONAL, columns=MAP, units=UNITS).columns


def rig_channels(c, wob_unit=("klbf", 4448.22)):
    """A simulated run's SI columns as a drilling system logs them: mnemonics, rig units, plus a standpipe
    pressure (not a compensator channel: carried, never mapped)."""
    rig = dict(RIG, WOB=wob_unit)
    ch = {"TIME": c["t"], "HEAVE": c["heave"] / rig["HEAVE"][1], "CMC_POS": c["stroke"] / rig["CMC_POS"][1],
          "CMC_PRES": c["pressure"] / rig["CMC_PRES"][1], "WOB": c["wob"] / rig["WOB"][1],
          "SPPA": np.full(c["t"].size, 3000.0)}
    units = {"TIME": "s", "SPPA": "psi", **{m: u for m, (u, _f) in rig.items()}}
    return ch, units


def write_witsml_run(path, c, **kw):
    """A WITSML 1.4.1.1 log of a simulated run in rig units (date time index)."""
    ch, units = rig_channels(c)
    logs.write_witsml(path, ch, units, start="2026-11-02T06:00:00Z", **kw)
    return path


def write_las_run(path, c):
    """A LAS 2.0 file of a simulated run in rig units (WOB in kkgf, elapsed time index in s)."""
    ch, units = rig_channels(c, ("kkgf", 9806.65))
    logs.write_las(path, ch, units)
    return path


@pytest.fixture(scope="module")
def example():
    return _example()


def _close(read, c):
    for k in ("heave", "stroke", "pressure", "wob"):
        scale = np.std(c[k])
        assert np.max(np.abs(read[k] - c[k])) < 1e-6 * scale, k
    assert np.max(np.abs(read["t"] - (c["t"] - c["t"][0]))) < 1e-5


def test_witsml_log_reads_to_the_si_run_with_every_mapping_and_conversion_recorded(tmp_path, example):
    f = write_witsml_run(tmp_path / "run.xml", example)
    s = read_series(f, ("t", "heave"), optional=OPTIONAL)
    _close(s.columns, example)
    m = s.measurement
    assert m["format"] == "witsml 1.4.1.1" and m["index_type"] == "date time"
    assert m["units"] == {"t": "timestamp", "heave": "ft", "stroke": "in", "pressure": "psi", "wob": "klbf"}
    for line in ("mnemonic TIME -> t (index curve)", "mnemonic HEAVE -> heave (default mnemonic table)",
                 "mnemonic WOB -> wob (default mnemonic table)", "wob: klbf -> N (x 4448.22)",
                 "heave: ft -> m (x 0.3048)", "pressure: psi -> Pa (x 6894.76)"):
        assert line in m["conversions"], (line, m["conversions"])
    assert "SPPA [psi]" in s.columns  # the standpipe pressure is carried, not taken for the compensator's
    assert "pressure" in s.columns and np.allclose(s["pressure"], example["pressure"], atol=1e-3)


def test_las_log_reads_to_the_si_run(tmp_path, example):
    pytest.importorskip("lasio")
    f = write_las_run(tmp_path / "run.las", example)
    s = read_series(f, ("t", "heave"), optional=OPTIONAL)
    _close(s.columns, example)
    assert s.measurement["format"] == "las 2.0"
    assert "wob: kkgf -> N (x 9806.65)" in s.measurement["conversions"]


def test_columns_override_the_default_table_and_elapsed_ms_index(tmp_path, example):
    ch, units = rig_channels(example)
    ch = {"TIME": ch["TIME"] * 1e3, **{k: v for k, v in ch.items() if k != "TIME"}, "SWOB": ch["WOB"] * 2.0}
    units = {**units, "TIME": "ms", "SWOB": "klbf"}
    f = tmp_path / "run.xml"
    logs.write_witsml(f, ch, units)  # elapsed time in ms
    s = read_series(f, ("t", "heave"), optional=OPTIONAL, columns={"wob": "SWOB"})
    assert np.allclose(s["wob"], 2.0 * example["wob"], rtol=1e-8)
    assert "mnemonic SWOB -> wob (mapped)" in s.measurement["conversions"]
    assert "t: ms -> s (x 0.001)" in s.measurement["conversions"]
    assert np.allclose(s["t"], example["t"] - example["t"][0], atol=1e-6)
    # the default table alone takes WOB, the first of its wob mnemonics present
    assert np.allclose(read_series(f, ("t", "heave"), optional=OPTIONAL)["wob"], example["wob"], rtol=1e-8)


def test_null_values_read_as_dropouts(tmp_path, example):
    c = dict(example)
    c["wob"] = c["wob"].copy()
    c["wob"][100:105] = np.nan
    f = write_witsml_run(tmp_path / "run.xml", c, null="-999.25")
    assert "<nullValue>-999.25</nullValue>" in f.read_text()
    s = read_series(f, ("t", "heave"), optional=OPTIONAL)
    assert np.isnan(s["wob"][100:105]).all() and np.isfinite(s["wob"][:100]).all()


def _refused(f, match):
    with pytest.raises(DataError, match=match) as exc:
        read_series(f, ("t", "heave"), optional=OPTIONAL)
    assert "\n" not in str(exc.value)


def test_missing_mnemonic_unknown_unit_and_depth_index_are_one_line_errors(tmp_path, example):
    ch, units = rig_channels(example)
    f = tmp_path / "noheave.xml"
    logs.write_witsml(f, {k: v for k, v in ch.items() if k != "HEAVE"}, units)
    _refused(f, r"missing column 'heave'.*heave=NAME")
    f = tmp_path / "unit.xml"
    logs.write_witsml(f, ch, {**units, "WOB": "klbs"})
    _refused(f, r"column 'wob' \('WOB \[klbs\]'\): unknown unit 'klbs'")
    f = tmp_path / "depth.xml"
    logs.write_witsml(f, {"DEPT": np.arange(60.0), **{k: v[:60] for k, v in ch.items() if k != "TIME"}},
                      {**units, "DEPT": "m"}, index="DEPT")
    f.write_text(f.read_text().replace("elapsed time", "measured depth"))
    _refused(f, r"column 'DEPT' \(the WITSML index curve\) is 'measured depth': a time index is needed")
    f = tmp_path / "v2.xml"
    f.write_text('<?xml version="1.0"?><ChannelSet xmlns="http://www.energistics.org/energyml/data/witsmlv2" '
                 'schemaVersion="2.0"/>')
    _refused(f, "WITSML 2.0 ChannelSet: not read")


def test_las_depth_index_is_refused(tmp_path, example):
    pytest.importorskip("lasio")
    ch, units = rig_channels(example)
    f = tmp_path / "depth.las"
    logs.write_las(f, {"DEPT": 1000.0 + np.arange(60.0), **{k: v[:60] for k, v in ch.items() if k != "TIME"}},
                   {**units, "DEPT": "M"}, index="DEPT")
    _refused(f, r"column 'DEPT' \(the LAS index curve, M\) is a depth: a time index is needed")


def test_a_bad_log_stops_diagnose_with_one_line_exit_2(tmp_path, example):
    ch, units = rig_channels(example)
    f = tmp_path / "unit.xml"
    logs.write_witsml(f, ch, {**units, "HEAVE": "furlong"})
    r = run("diagnose", f, "--params", EXAMPLE_PARAMS, "--out", tmp_path / "o")
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "unknown unit 'furlong'" in r.stderr, r.stderr


#: a short stretch and two candidates: the same verdict is the point, not the diagnosis' reach
QUICK = ("--span", "60:420", "--candidates", "pressure_friction,gas_leak", "--jobs", "1", "--quiet")


def _verdict(tmp_path, log, *extra):
    out = tmp_path / log.name.replace(".", "_")
    r = run("diagnose", log, "--params", EXAMPLE_PARAMS, "--out", out, *QUICK, *extra)
    assert r.returncode == 0, r.stderr
    return json.loads((out / "diagnosis.json").read_text())


@pytest.mark.slow
def test_witsml_and_las_logs_diagnose_to_the_csv_verdict(tmp_path, example):
    pytest.importorskip("lasio")
    csv = _verdict(tmp_path, EXAMPLE_RUN, "--columns", ",".join(f"{k}={v}" for k, v in MAP.items()),
                   "--units", ",".join(f"{k}={v}" for k, v in UNITS.items()))
    for log in (write_witsml_run(tmp_path / "run.xml", example), write_las_run(tmp_path / "run.las", example)):
        d = _verdict(tmp_path, log)
        assert d["verdict"]["effect"] == csv["verdict"]["effect"], (log.name, d["verdict"], csv["verdict"])
        assert d["verdict"]["confidence"] == csv["verdict"]["confidence"], log.name
        assert d["measurement"]["format"] in ("witsml 1.4.1.1", "las 2.0")


def test_fleet_finds_witsml_and_las_logs_in_a_folder(tmp_path, example):
    from heavecomp.campaign.fleet import find_logs

    write_witsml_run(tmp_path / "day1.xml", example)
    write_las_run(tmp_path / "day2.las", example)
    (tmp_path / "notes.md").write_text("not a log")
    _root, found = find_logs(tmp_path)
    assert sorted(p.name for p in found) == ["day1.xml", "day2.las"]
