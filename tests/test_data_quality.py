"""Corrupted logs (issue 21 item 4): refused naming the column, or read with a warning that names the
problem and a confidence cap of ``low`` -- never a confident verdict; and clean logs pass without a
false alarm.  The reproducers of November 2026 are in ``tests/data/corrupt_2026_11`` (README there);
fresh variants of each class are made from the clean one with :mod:`heavecomp.benchmark.corruption`."""

import gzip
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from heavecomp.benchmark import corruption as K
from heavecomp.diagnosis import quality as Q
from heavecomp.diagnosis.data import check_run, load_run
from heavecomp.errors import DataError
from heavecomp.params import load

DATA = Path(__file__).parent / "data" / "corrupt_2026_11"
EXAMPLES = Path(__file__).resolve().parents[1] / "heavecomp" / "data" / "examples"
P = load(DATA / "pj.toml")


def _arrays(name="C0_clean_300s_20Hz"):
    with gzip.open(DATA / f"{name}.csv.gz", "rt") as f:
        d = np.genfromtxt(f, delimiter=",", names=True)
    return d["t"], {c: d[c] for c in ("heave", "stroke", "pressure", "wob")}


T0, C0 = _arrays()


def _checked(t, cols):
    """The run load_run would return (check_run, then the quality checks)."""
    return Q.checked(check_run(t, cols, params=P, source="x"), P)


def _issue(run, kind):
    return [i for i in run.quality.issues if i["kind"] == kind]


# ---- the reproducers -------------------------------------------------------------------------------------


def test_clean_log_has_no_quality_warning():
    run = load_run(DATA / "C0_clean_300s_20Hz.csv.gz", P)
    assert run.quality.issues == [] and run.quality.confidence_cap is None
    assert run.warnings == []


def test_shipped_example_with_its_readme_mapping_is_clean():
    run = load_run(EXAMPLES / "rig_log_example.csv.gz", load(EXAMPLES / "rig_log_example.toml"),
                   columns=dict(t="Time", heave="MRU_heave", stroke="CMC_pos", pressure="P_main", wob="WOB"),
                   units=dict(t="ms", pressure="bar", wob="kN", stroke="mm"))
    assert run.quality.issues == []


def test_torn_last_row_is_dropped_and_named():
    run = load_run(DATA / "C9_torn_last_value.csv.gz", P)
    (torn,) = _issue(run, "torn")
    assert torn["column"] == "wob" and "row 6002 (the last)" in torn["message"]
    assert run.t.size == 6000 and run.quality.confidence_cap is None  # the rest is the clean log
    np.testing.assert_array_equal(run["wob"], C0["wob"][:-1])


def test_time_base_at_half_scale_caps_the_confidence():
    run = load_run(DATA / "C10_time_base_x0.5.csv.gz", P)
    (tb,) = _issue(run, "time_base")
    assert tb["column"] == "t" and run.quality.confidence_cap == "low"


def test_frozen_wob_is_refused_by_name():
    with pytest.raises(DataError, match=r"column 'wob': frozen: .* from row 1502"):
        load_run(DATA / "C11_wob_frozen_after_75s.csv.gz", P)


def test_heave_clock_skew_names_the_heave():
    run = load_run(DATA / "C12_heave_clock_skew_5s.csv.gz", P)
    (sk,) = _issue(run, "clock_skew")
    assert sk["column"] == "heave" and run.quality.confidence_cap == "low"
    assert "-4.9" in sk["message"] or "-5.0" in sk["message"]


def test_wob_spike_is_excluded_and_caps_the_confidence():
    run = load_run(DATA / "C13_wob_spike_1e9.csv.gz", P)
    (sp,) = _issue(run, "spike")
    assert sp["column"] == "wob" and "row 3002" in sp["message"] and run.quality.confidence_cap == "low"
    assert np.isnan(run["wob"][3000]) and np.nanmax(run["wob"]) < 1e6  # the rest as logged


def test_inf_cell_is_an_error_naming_column_and_row(tmp_path):
    """The contract: non-finite values are an error (1e400 parses as inf; it was '1 missing sample')."""
    text = gzip.decompress((DATA / "C0_clean_300s_20Hz.csv.gz").read_bytes()).decode().splitlines()
    parts = text[101].split(",")
    parts[3] = "1e400"
    text[101] = ",".join(parts)
    f = tmp_path / "r.csv"
    f.write_text("\n".join(text) + "\n")
    with pytest.raises(DataError, match=r"column 'pressure', row 102: non-finite value"):
        load_run(f, P)


# ---- fresh variants of each class --------------------------------------------------------------------------


@pytest.mark.parametrize("channel", ["stroke", "pressure", "wob"])
def test_short_frozen_stretch_is_excluded_with_low_confidence(channel):
    t, cols, d = K.frozen(T0, C0, channel, 250.0)  # the last 50 s of 300 s: 17 % of the channel
    run = _checked(t, cols)
    (fr,) = _issue(run, "frozen")
    assert fr["column"] == channel and run.quality.confidence_cap == "low"
    assert np.isnan(run[channel][t >= 251.0]).all()


def test_frozen_heave_is_refused():
    t, cols, _ = K.frozen(T0, C0, "heave", 280.0)
    with pytest.raises(DataError, match="column 'heave': frozen"):
        _checked(t, cols)


@pytest.mark.parametrize("channel,value", [("heave", 1e3), ("stroke", -50.0), ("pressure", 1e12), ("wob", -1e9)])
def test_spike_in_any_channel(channel, value):
    t, cols, _ = K.spike(T0, C0, channel, 4321, value)
    run = _checked(t, cols)
    (sp,) = _issue(run, "spike")
    assert sp["column"] == channel and "row 4323" in sp["message"] and run.quality.confidence_cap == "low"


@pytest.mark.parametrize("factor", [0.5, 2.0])
def test_time_scale_either_way(factor):
    t, cols, _ = K.time_scale(T0, C0, factor)
    run = _checked(t, cols)
    assert [i["column"] for i in _issue(run, "time_base")] == ["t"]


@pytest.mark.parametrize("channel,lag", [("stroke", 5.0), ("pressure", -6.0), ("heave", 4.0)])
def test_clock_skew_names_the_skewed_channel(channel, lag):
    t, cols, _ = K.clock_skew(T0, C0, channel, lag)
    run = _checked(t, cols)
    (sk,) = _issue(run, "clock_skew")
    assert sk["column"] == channel


def test_sensor_lag_inside_the_modelled_range_is_no_skew():
    """A 1 s sensor lag is an effect the diagnosis fits (sensor_delay), not corruption."""
    t, cols, _ = K.clock_skew(T0, C0, "stroke", 1.0)
    assert _issue(_checked(t, cols), "clock_skew") == []


@pytest.mark.parametrize("keep", [1, 2, 3, 4])
def test_torn_wob_of_any_length(keep):
    t, cols, d = K.torn(T0, C0, "wob", keep)
    run = _checked(t, cols)
    assert d["expect"] == "dropped"
    assert [i["column"] for i in _issue(run, "torn")] == ["wob"] and run.t.size == T0.size - 1


def test_wob_in_kn_declared_as_tonnes_is_refused():
    """983 kN against a 98.1 kN set-point: more than the lower mass weighs (the string would push)."""
    t, cols, _ = K.scaled(T0, C0, "wob", 9.81)
    with pytest.raises(DataError, match=r"column 'wob': mean .* above the lower mass's weight"):
        _checked(t, cols)


def test_wob_mean_at_a_third_of_the_setpoint_caps_the_confidence():
    t, cols, _ = K.scaled(T0, C0, "wob", 1 / 3)
    run = _checked(t, cols)
    assert [i["column"] for i in _issue(run, "wob_setpoint")] == ["wob"] and run.quality.confidence_cap == "low"


@pytest.mark.parametrize("make,column", [
    (lambda: K.scaled(T0, C0, "stroke", 100.0, "magnitude"), "stroke"),
    (lambda: K.offset(T0, C0, "pressure", -(P.p0 + 3e5)), "pressure"),
    (lambda: K.scaled(T0, C0, "heave", 50.0, "magnitude"), "heave"),
])
def test_impossible_magnitudes_are_refused_by_name(make, column):
    t, cols, _ = make()
    with pytest.raises(DataError, match=f"column '{column}'"):
        _checked(t, cols)


# ---- the physics of the thresholds ---------------------------------------------------------------------------


def test_a_step_and_a_fast_mode_are_no_spikes():
    """A breakaway step keeps the median of three; a mode sampled 6 times a period with an amplitude of
    half the range moves a lone sample by at most a quarter of the range (the spike margin)."""
    t = np.arange(6000) * 0.1
    rng = np.random.default_rng(1)
    step = np.where(t > 300, 2.3e4, 0.0) + 50.0 * rng.normal(size=t.size)
    assert Q.spikes(step)[0].size == 0
    mode = 0.5 * np.sin(2 * np.pi * t / 0.6 + 0.3) + np.sin(2 * np.pi * t / 10)
    assert Q.spikes(mode)[0].size == 0


def test_noisy_stuck_stroke_is_not_frozen_but_a_held_value_is():
    rng = np.random.default_rng(2)
    y = 1e-3 * rng.normal(size=3000)  # a stroke stuck for 300 s still reads its sensor noise
    assert Q.frozen_runs(y, 200) == []
    y[1000:1300] = y[1000]
    assert Q.frozen_runs(y, 200) == [(1000, 1300)]


def test_apply_quality_caps_and_says_so():
    v = {"effect": "none", "confidence": "high"}
    t, cols, _ = K.spike(T0, C0, "wob", 100, 1e9)
    q = _checked(t, cols).quality
    out = Q.apply_quality(v, q)
    assert out["confidence"] == "low" and out["confidence_capped_from"] == "high"
    assert out["data_quality"] == [{"kind": "spike", "column": "wob"}]
    assert v["confidence"] == "high"  # a new dict
    assert Q.apply_quality(v, None) is v and Q.apply_quality(v, Q.Quality()) is v


# ---- end to end: the verdict of the diagnosis itself -----------------------------------------------------------


@pytest.mark.slow
def test_diagnose_cli_on_the_spike_reproducer_is_low_with_a_warning(tmp_path):
    from heavecomp.cli import main

    rc = main(["diagnose", str(DATA / "C13_wob_spike_1e9.csv.gz"), "--params", str(DATA / "pj.toml"),
               "--out", str(tmp_path / "d"), "--candidates", "sensor_gain", "--quiet"])
    assert rc == 0
    d = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert d["verdict"]["confidence"] == "low"
    assert any("column 'wob'" in w and "spike" in w for w in d["warnings"])


# ---- a reading on a coarse grid (issue 30: a pressure on a 0.25 bar grid with hum read as a gas effect) --
def test_coarse_grid_is_part_of_the_noise_floor_and_reported():
    """A pressure read on a 0.25 bar grid with hum aliased to 0.02 Hz: most differences of the reading are
    exactly 0, so the difference estimate alone read the noise as ~50 Pa; the floor must hold the reading's
    own error, step / sqrt(12) = 7.2 kPa, the warning names the column, and nothing is capped or frozen."""
    from heavecomp.diagnosis.data import noise_floor

    step = 25e3
    t, cols, _ = K.quantised(T0, C0, "pressure", step, hum=10e3, hum_frequency=0.02)
    run = _checked(t, cols)
    assert noise_floor(run["pressure"]) >= 0.95 * step / math.sqrt(12.0)
    (iq,) = _issue(run, "quantised")
    assert iq["column"] == "pressure" and iq["step"] == pytest.approx(step) and "pressure" in iq["message"]
    assert not _issue(run, "frozen") and run.quality.confidence_cap is None
    assert noise_floor(run["wob"]) == noise_floor(C0["wob"])  # the other channels as they were


def test_a_fine_grid_is_no_artefact():
    """A 16-bit reading of the pressure (its range over 65536 steps) is dithered by its own noise: no
    warning, and the noise floor is the difference estimate's."""
    from heavecomp.diagnosis.data import noise_floor

    p = C0["pressure"]
    step = float(np.ptp(p)) / 65536
    t, cols, _ = K.quantised(T0, C0, "pressure", step)
    run = _checked(t, cols)
    assert Q.quantum(cols["pressure"]) == 0.0 and not _issue(run, "quantised")
    assert noise_floor(cols["pressure"]) == pytest.approx(noise_floor(p), rel=0.05)


def test_a_hum_in_one_channel_joins_its_noise_floor():
    """Mains hum aliased to 0.02 Hz on the pressure alone (3 kPa, under the wave band): a line no other channel
    has is a reading artefact; its rms is part of the pressure's floor (the replay's output noise), no cap;
    the clean log has no such line."""
    from heavecomp.diagnosis.replay import output_noise

    assert not _issue(_checked(T0, C0), "hum")
    t, cols, _ = K.quantised(T0, C0, "pressure", 1.0, hum=3e3, hum_frequency=0.02)
    run = _checked(t, cols)
    (h,) = _issue(run, "hum")
    assert h["column"] == "pressure" and h["frequency"] == pytest.approx(0.02, abs=2 / 300.0)
    assert h["amplitude"] == pytest.approx(3e3, rel=0.1) and run.quality.confidence_cap is None
    clean = output_noise(_checked(T0, C0))["pressure"]
    assert output_noise(run)["pressure"] == pytest.approx(math.hypot(clean, 3e3 / math.sqrt(2)), rel=0.1)


@pytest.mark.parametrize("effect", ["none", "flow_loss"])
def test_a_none_verdict_places_the_reading_artefacts_in_the_sensors(effect):
    """The same grid and hum: once their reading error is in the floor, a `none` verdict says where the log still
    departs from an ideal reading (component sensors, the artefacts listed); a named verdict keeps its own
    component; a clean log's `none` has none."""
    t, cols, _ = K.quantised(T0, C0, "pressure", 25e3, hum=10e3, hum_frequency=0.02)
    run = _checked(t, cols)
    v = Q.place_reading_artefacts({"effect": effect, "confidence": "high", "component": None}, run.quality)
    if effect == "none":
        assert v["component"] == "sensors"
        assert {(a["kind"], a["column"]) for a in v["reading_artefacts"]} == {("quantised", "pressure"),
                                                                               ("hum", "pressure")}
        assert "pressure" in v["note"] and v["confidence"] == "high"
    else:
        assert v["component"] is None and "reading_artefacts" not in v
    clean = Q.place_reading_artefacts({"effect": "none", "confidence": "high"}, _checked(T0, C0).quality)
    assert "component" not in clean and "reading_artefacts" not in clean
