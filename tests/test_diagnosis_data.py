"""Measured-run contract: every bad-input case is one line naming the column (exit 2 from the CLI);
documented treatments (dropouts, non-uniform sampling) are accepted and reported."""


import numpy as np
import pytest

from heavecomp.diagnosis.data import load_run, noise_floor
from heavecomp.signals import flat_zero_phase
from heavecomp.errors import DataError
from heavecomp.params import dumps, paper_a

P = paper_a()


def _write(path, t, cols, header=("t", "heave", "stroke", "pressure", "wob")):
    rows = [",".join(header)]
    for i in range(len(t)):
        rows.append(",".join("" if (isinstance(v, float) and np.isnan(v)) else repr(float(v))
                             for v in [t[i]] + [cols[c][i] for c in header[1:]]))
    path.write_text("\n".join(rows) + "\n")
    return path


def _good(n=600, dt=0.05):
    t = np.arange(n) * dt
    z = 0.5 * np.sin(2 * np.pi * t / 10)
    return t, {"heave": z, "stroke": -0.9 * z, "pressure": P.p0 + 1e5 * z,
               "wob": P.operating_point.wob_setpoint + 2e4 * z}


def _err(tmp_path, t, cols, **kw):
    f = _write(tmp_path / "r.csv", t, cols, **kw)
    with pytest.raises(DataError) as e:
        load_run(f, P)
    msg = str(e.value)
    assert "\n" not in msg
    return msg


def test_good_run_loads(tmp_path):
    t, c = _good()
    r = load_run(_write(tmp_path / "r.csv", t, c), P)
    assert r.uniform and r.warnings == [] and r.duration == pytest.approx(t[-1])


def test_missing_column(tmp_path):
    t, c = _good()
    msg = _err(tmp_path, t, c, header=("t", "stroke", "pressure", "wob"))
    assert "missing column 'heave'" in msg
    msg = _err(tmp_path, t, c, header=("t", "heave"))  # the heave alone: nothing to compare the model with
    assert "'stroke', 'pressure', 'wob'" in msg


@pytest.mark.parametrize("header", [("t", "heave", "stroke", "wob"), ("t", "heave", "pressure", "wob"),
                                    ("t", "heave", "wob"), ("t", "heave", "stroke")])
def test_stroke_pressure_and_wob_are_each_optional(tmp_path, header):
    """Contract schema 3: heave is required, any of stroke, pressure and WOB may be missing; the run
    says which it has, and the magnitudes of those present are still checked."""
    t, c = _good()
    r = load_run(_write(tmp_path / "r.csv", t, c, header=header), P)
    assert r.sensors == ("heave",) + tuple(k for k in ("stroke", "pressure", "wob") if k in header)
    assert set(r.columns) == set(header[1:])
    assert sorted(w.split("'")[1] for w in r.warnings) == sorted(set(("stroke", "pressure", "wob")) - set(header))
    if "wob" in header:  # a WOB in kN is still caught without the pressure
        c2 = dict(c, wob=c["wob"] / 1e3)
        assert "wob=kN" in _err(tmp_path, t, c2, header=header)


def test_wob_from_hook_load_is_explicit_and_recorded(tmp_path):
    """A log with a hook load and no WOB: W = string weight - hook load, the string weight from the
    parameter file's [measurement] table (or the keyword), the conversion in the provenance; without a
    string weight it is one line naming the column and the key."""
    from heavecomp.params import load

    t, c = _good()
    W_s = 1.5e6
    hl = dict(c, hook_load=(W_s - c["wob"]) / 1e3)  # logged in kN
    f = _write(tmp_path / "r.csv", t, hl, header=("t", "heave", "stroke", "pressure", "hook_load"))
    toml = tmp_path / "p.toml"
    toml.write_text(dumps(P) + f"\n[measurement]\nunits = {{ hook_load = \"kN\" }}\nstring_weight = {W_s}\n")
    r = load_run(f, load(toml))
    np.testing.assert_allclose(r["wob"], c["wob"], rtol=1e-9)
    assert r.measurement["wob_from"] == {"column": "hook_load", "string_weight_N": W_s,
                                         "formula": "wob = string_weight - hook_load"}
    assert any("hook_load" in x for x in r.measurement["conversions"])
    r2 = load_run(f, P, units={"hook_load": "kN"}, string_weight=W_s)
    np.testing.assert_allclose(r2["wob"], c["wob"], rtol=1e-9)
    with pytest.raises(DataError) as e:
        load_run(f, P, units={"hook_load": "kN"})
    assert "'hook_load'" in str(e.value) and "string_weight" in str(e.value) and "\n" not in str(e.value)


def test_non_numeric_cell_names_column_and_row(tmp_path):
    t, c = _good()
    f = _write(tmp_path / "r.csv", t, c)
    lines = f.read_text().splitlines()
    parts = lines[5].split(",")
    parts[4] = "12kN"
    lines[5] = ",".join(parts)
    f.write_text("\n".join(lines))
    with pytest.raises(DataError, match=r"column 'wob', row 6: not a number: '12kN'"):
        load_run(f, P)


@pytest.mark.parametrize("kind", ["duplicate", "backwards"])
def test_time_not_increasing_names_t_and_row(tmp_path, kind):
    t, c = _good()
    t = t.copy()
    t[100] = t[99] if kind == "duplicate" else t[99] - 0.2
    msg = _err(tmp_path, t, c)
    assert "column 't', row 102: time not strictly increasing" in msg  # file line (header = 1)


def test_mostly_missing_column(tmp_path):
    t, c = _good()
    c["stroke"] = c["stroke"].copy()
    c["stroke"][::2] = np.nan
    assert "column 'stroke': 50 % of samples missing" in _err(tmp_path, t, c)


def test_long_heave_dropout(tmp_path):
    t, c = _good()
    c["heave"] = c["heave"].copy()
    c["heave"][100:160] = np.nan  # 3 s
    assert "column 'heave', row 102: dropout of" in _err(tmp_path, t, c)


@pytest.mark.parametrize("col,factor,unit", [("pressure", 1e-5, "bar"), ("pressure", 1e-6, "MPa"),
                                             ("wob", 1e-3, "kN"), ("wob", 1 / 9810.0, "tonnes"),
                                             ("stroke", 1e3, "mm")])
def test_wrong_unit_is_named(tmp_path, col, factor, unit):
    t, c = _good()
    c[col] = c[col] * factor
    msg = _err(tmp_path, t, c)
    assert f"column '{col}'" in msg and unit in msg


def test_dropouts_and_jitter_are_treated_and_reported(tmp_path):
    t, c = _good()
    rng = np.random.default_rng(0)
    t = t + rng.uniform(-0.01, 0.01, t.size)
    t[0] = 0.0
    c["wob"] = c["wob"].copy()
    c["wob"][50:55] = np.nan
    c["heave"] = c["heave"].copy()
    c["heave"][200:204] = np.nan
    r = load_run(_write(tmp_path / "r.csv", t, c), P)
    text = " ".join(r.warnings)
    assert "non-uniform sampling" in text and "column 'wob': 5 missing" in text and "interpolated" in text


def test_noise_floor_estimator_recovers_white_noise():
    t = np.arange(20000) * 0.02
    y = 3e4 * np.sin(2 * np.pi * t / 11) + np.random.default_rng(1).normal(0, 400, t.size)
    assert noise_floor(y) == pytest.approx(400, rel=0.05)


def test_zero_phase_filter_has_no_lag():
    """filtfilt FIR (paper B): a 0.1 Hz sine passes with no phase shift and unit gain."""
    dt = 0.02
    t = np.arange(30000) * dt
    y = np.sin(2 * np.pi * 0.1 * t)
    f = flat_zero_phase(y + np.random.default_rng(2).normal(0, 0.05, t.size), 1.0 / dt, 0.8)
    mid = slice(2000, -2000)
    lags = np.arange(-10, 11)
    corr = [np.dot(f[2000 + k:-2000 + k], y[mid]) for k in lags]
    assert lags[int(np.argmax(corr))] == 0 and np.std(f[mid] - y[mid]) < 0.02


def test_cli_bad_input_exit_2_one_line(tmp_path, diagnose_cli):
    t, c = _good()
    c["pressure"] = c["pressure"] * 1e-5
    f = _write(tmp_path / "r.csv", t, c)
    toml = tmp_path / "nom.toml"
    toml.write_text(dumps(P))
    r = diagnose_cli(f, toml)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("heavecomp diagnose: error:") and "'pressure'" in lines[0]
    assert "bar" in lines[0]
    r = diagnose_cli(f, toml, "--candidates", "flow_los")
    assert r.returncode == 2 and "did you mean 'flow_loss'" in r.stderr and len(r.stderr.strip().splitlines()) == 1
