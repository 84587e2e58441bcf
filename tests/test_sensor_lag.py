"""A reading with its own dynamics (``sensor_lag``, issue 22): the calibrated model reads a sensor-fault
verdict's channel through a factor, a first-order lag and a delay fitted together.

The truths are the generator's (a run of the benchmark's with no effect) read through a sensor the test
makes itself: a first-order lag integrated by ``scipy.signal.lsim`` on the continuous transfer function
1 / (tau s + 1), never the effect's own recursion.
"""

from __future__ import annotations

import numpy as np
import pytest

from heavecomp.diagnosis.calibrate import FILE, fit_reading, replay_shrink, write
from heavecomp.diagnosis.data import load_run
from heavecomp.effects import spec
from heavecomp.effects.sensor_lag import SensorLag
from heavecomp.errors import ParameterError
from heavecomp.params import dumps, loads, paper_a
from tests._cli import run as cli

#: the planted sensor: a sign flip read through a 0.6 s lag
TAU, FACTOR = 0.6, -1.0


def _lagged(t, y, tau):
    """The test's own sensor: 1 / (tau s + 1) by scipy's lsim (linear interpolation of the input)."""
    from scipy import signal

    _, out, _ = signal.lsim(signal.lti([1.0], [tau, 1.0]), y - y[0], t)
    return out + y[0]


def test_the_lag_is_the_continuous_first_order_lag():
    """On a 10 Hz grid the effect's lag of a mixed sea is the continuous lag (lsim) and its phase at
    0.1 Hz is atan(w tau): no half-step delay of its own."""
    t = np.arange(0.0, 200.0, 0.1)
    y = np.sin(2 * np.pi * 0.1 * t) + 0.5 * np.sin(2 * np.pi * 0.23 * t + 1.0)
    got = SensorLag(channel="stroke", time_constant=TAU).measure(t, t, y)
    np.testing.assert_allclose(got, _lagged(t, y, TAU), atol=1e-6)


def test_a_reading_fit_recovers_a_known_lag_factor_and_delay():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 300.0, 0.1)
    y = sum(a * np.sin(2 * np.pi * f * t + p) for a, f, p in ((0.2, 0.08, 0.0), (0.1, 0.13, 1.0), (0.05, 0.3, 2.0)))
    meas = 0.97 * np.interp(t - 0.2, t, _lagged(t, y, 0.85)) + rng.normal(0.0, 0.005, t.size)
    got = fit_reading(t, y, meas, t < 200.0)
    assert got["time_constant"] == pytest.approx(0.85, rel=0.05)
    assert got["delay"] == pytest.approx(0.2, abs=0.03)
    assert got["factor"] == pytest.approx(0.97, rel=0.01)


@pytest.fixture(scope="module")
def lagged_run(tmp_path_factory):
    """A generated run with no effect whose stroke the test reads through its own sign-flipped lagged sensor."""
    from heavecomp.benchmark import Case, generate

    tr = generate(Case("none", 12, "none", duration=230.0))
    t = np.asarray(tr.t, float)
    tr.columns["true_stroke"] = np.asarray(tr.columns["stroke"], float).copy()
    tr.columns["stroke"] = FACTOR * _lagged(t, tr.columns["true_stroke"], TAU)
    tr = tr.cropped(30.0)  # a log that starts mid-operation: the sensor's lag has a history
    true = tr.columns.pop("true_stroke")
    d = tmp_path_factory.mktemp("lag")
    return tr, tr.to_csv(d / "run.csv"), d, true


@pytest.mark.slow
def test_a_reading_verdict_is_written_with_the_sensors_lag_and_round_trips(lagged_run):
    """A verdict that read the lagged, sign-flipped stroke as a sign flip alone (sensor_gain, what the
    diagnosis names): the calibrated file reads it with the sensor's lag found within 10 %, passes
    ``heavecomp params``, and replaying it reproduces the shrink it reports."""
    tr, path, d, _ = lagged_run
    run = load_run(path, tr.nominal)
    T = float(run.t[-1])
    diag = {"verdict": {"effect": "sensor_gain", "confidence": "high", "shrink": 0.9, "shrink_channel": "stroke",
                        "parameters": {"channel": "stroke", "factor": -1.02}},
            "split": {"fit": [0.0, 0.67 * T], "validate": [0.67 * T, T], "settle": 20.0}}
    cal = write(tr.nominal, diag, d, run=run)
    (lag,) = [c for c in cal.changes if c["name"] == "sensor_lag"]
    assert [c["name"] for c in cal.changes] == ["sensor_lag"] and lag["replaces"] == ["sensor_gain"]
    assert lag["parameters"]["time_constant"] == pytest.approx(TAU, rel=0.1)
    assert lag["parameters"]["factor"] == pytest.approx(FACTOR, rel=0.02)
    assert cal.verdict_shrink == 0.9
    res = cli("params", str(d / FILE))
    assert res.returncode == 0 and 'name = "sensor_lag"' in res.stdout
    back = spec.load(d / FILE)
    assert back.effects[-1] == ("sensor_lag", lag["parameters"])
    got = replay_shrink(path, back, tr.nominal, {**diag, "calibrated": cal.block()})
    assert got["shrink"] == pytest.approx(cal.expected_shrink, rel=0.1)
    assert got["shrink"] > 0.9  # the sign flip and its lag: what the nominal misses on the stroke
    # a diagnosis whose policy switches the reading's dynamics off writes the verdict's reading as it is
    from heavecomp.diagnosis.policy import VerdictPolicy

    off = write(tr.nominal, diag, d, run=run, policy=VerdictPolicy(reading_dynamics_gain=0.0))
    assert [c["name"] for c in off.changes] == ["sensor_gain"]


def test_a_re_diagnosis_reading_is_not_stacked_on_the_files_lag(lagged_run):
    """A file that reads the stroke already (``sensor_lag``): a re-diagnosis' reading of the stroke is written as
    the verdict says, not refitted into a second lag on the same channel."""
    from heavecomp.diagnosis.calibrate import calibrate, reading_dynamics

    tr, path, _, _ = lagged_run
    nominal = tr.nominal.replace(effects=[("sensor_lag", {"channel": "stroke", "factor": FACTOR, "time_constant": TAU,
                                                        "delay": 0.0})])
    run = load_run(path, nominal)
    T = float(run.t[-1])
    diag = {"verdict": {"effect": "sensor_gain", "confidence": "low", "shrink": 0.3, "shrink_channel": "stroke",
                        "parameters": {"channel": "stroke", "factor": 1.05}},
            "split": {"fit": [0.0, 0.67 * T], "validate": [0.67 * T, T], "settle": 20.0}}
    cal = calibrate(nominal, diag)
    assert reading_dynamics(cal, run, nominal, diag) is cal
    assert [n for n, _ in cal.params.effects] == ["sensor_lag", "sensor_gain"]


def test_a_bad_time_constant_is_one_line_naming_the_key(tmp_path):
    entry = {"channel": "stroke", "factor": 1.0, "time_constant": -0.5}
    with pytest.raises(ParameterError) as exc:
        spec.check(paper_a().replace(effects=[("sensor_lag", entry)]))
    msg = str(exc.value)
    assert "\n" not in msg and "effects[0].time_constant" in msg and "s" in msg
    bad = tmp_path / "bad.toml"
    bad.write_text(dumps(paper_a().replace(effects=[("sensor_lag", {**entry, "time_constant": 0.5})]))
                   .replace("time_constant = 0.5", "time_constant = -0.5"))
    res = cli("params", str(bad))
    assert res.returncode == 2 and "effects[0].time_constant" in res.stderr and len(res.stderr.strip().splitlines()) == 1


def test_its_factor_and_delay_are_undone_on_the_log_and_its_lag_is_not():
    """A log correction inverts the factor and the delay exactly; the lag is left for the model side
    (inverting it would differentiate the noise)."""
    t = np.arange(0.0, 100.0, 0.05)
    y = 0.1 * np.sin(0.5 * t)
    e = SensorLag(channel="stroke", factor=-0.9, time_constant=0.4, delay=0.3)
    got, notes = spec.correct([e], t, {"stroke": e.measure(t, t, y)})
    ok = np.isfinite(got["stroke"])
    assert len(notes) == 1 and ok.sum() > 0.99 * t.size
    np.testing.assert_allclose(got["stroke"][ok], e.lag(t, t, y)[ok], atol=1e-9)
    assert not np.allclose(got["stroke"][ok], y[ok], atol=1e-3)


def test_the_diagnosis_replay_reads_the_files_lag_on_the_model_side(lagged_run):
    """The replay of a file with ``sensor_lag`` on the stroke predicts its plant's stroke read through the lag
    (the log, corrected for the factor only, holds the lagged stroke), and it starts from the stroke lifted
    back: its start is nearer the true (unlagged) stroke's than the lagged log's."""
    from heavecomp.diagnosis.replay import build
    from heavecomp.diagnosis.stepper import CHANNELS

    tr, path, _, true = lagged_run
    fx = {"channel": "stroke", "factor": FACTOR, "time_constant": TAU, "delay": 0.0}
    with_lag = tr.nominal.replace(effects=[("sensor_lag", fx)])
    run = load_run(path, with_lag)
    rp = build(run, with_lag)
    got = rp.simulate([])
    grid = got["_grid"]
    want = SensorLag(channel="stroke", time_constant=TAU).lag(run.t, grid[:, 0], grid[:, CHANNELS.index("stroke")])
    np.testing.assert_allclose(got["stroke"], want, atol=1e-12)
    assert not np.allclose(got["stroke"], grid[:, CHANNELS.index("stroke")][: run.t.size], atol=1e-4)
    no_lift = build(run, tr.nominal.replace(effects=[("sensor_gain", {"channel": "stroke", "factor": FACTOR})]))
    # measured: lifted -0.126 m, the lagged log's -0.254 m, the true stroke -0.154 m
    assert abs(rp.initial.stroke - true[0]) < 0.5 * abs(no_lift.initial.stroke - true[0])
    # a candidate that reads the stroke by a factor of 1 (fitted in every re-diagnosis) starts where the
    # file's replay starts, from the stroke lifted back, with no shift of the heave reference
    shift, starts = rp.start_for([("sensor_gain", {"channel": "stroke", "factor": 1.0})])
    assert shift == pytest.approx(0.0, abs=1e-9) and starts[0][0] == pytest.approx(rp.starts[0][0], abs=1e-9)


def test_a_file_round_trips_its_sensor_lag():
    fx = [("sensor_lag", {"channel": "pressure", "factor": 0.98, "time_constant": 0.25, "delay": 0.05})]
    back = loads(dumps(paper_a().replace(effects=fx)))
    assert list(back.effects) == fx and [e.name for e in spec.reading_effects(back)] == ["sensor_lag"]


def test_a_lag_on_the_heave_is_refused_in_one_line():
    """The heave is the replay's input: nothing predicts it, so no lag can be read on the model side; the file
    is refused (exit 2 from the command) instead of its lag being dropped with a 'corrected' note."""
    fx = [("sensor_lag", {"channel": "heave", "factor": 1.0, "time_constant": 2.0})]
    with pytest.raises(ParameterError) as exc:
        spec.reading_effects(loads(dumps(paper_a().replace(effects=fx))))
    msg = str(exc.value)
    assert "\n" not in msg and "sensor_lag" in msg and "heave" in msg, msg
