"""Reading corrections of the calibrated model (issue 22): a channel's discovered misreading carried as
``sensor_term``, and a reading candidate's fit that does not stop short.

The truths are the generator's (a run of the benchmark's) with a misreading the test makes itself
(a load cell that clips), never the equation of the effect that carries it.
"""

from __future__ import annotations

import numpy as np
import pytest

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis.calibrate import FILE, calibrate, replay_shrink, to_toml, write
from heavecomp.diagnosis.data import load_run
from heavecomp.effects import spec
from tests._cli import run as cli


@pytest.fixture(scope="module")
def clipped(tmp_path_factory):
    """A generated run with no effect whose WOB the test clips at its mean + 0.8 std (a load cell that
    saturates); the clean WOB kept."""
    from heavecomp.benchmark import Case, generate

    tr = generate(Case("none", 11, "none", duration=200.0))
    clean = np.asarray(tr.columns["wob"], float).copy()
    w_max = float(np.mean(clean) + 0.8 * np.std(clean))
    tr.columns["wob"] = np.minimum(clean, w_max)
    d = tmp_path_factory.mktemp("clip")
    return tr, clean, w_max, tr.to_csv(d / "run.csv"), d


def _discovered(tr, path):
    """The channel search's term on the log, as the verdict's ``discovered`` block carries it."""
    run = load_run(path, tr.nominal)
    cr = CR.residuals(run, tr.nominal)
    t = run.t
    fit = t < 0.67 * t[-1]
    return CR.channel_search(cr, fit & cr.mask, ~fit & cr.mask)


@pytest.mark.slow
def test_a_discovered_sensors_term_round_trips_and_rereads_the_log_right(clipped):
    tr, clean, w_max, path, d = clipped
    found = _discovered(tr, path)
    assert found is not None and found["channel"] == "wob" and found["levels"]
    diag = {"verdict": {"effect": "discovered", "confidence": "low", "shrink": 0.2, "shrink_channel": "wob",
                        "component": "sensors", "discovered": dict(found, component="sensors")},
            "split": {"fit": [0.0, 134.0], "validate": [134.0, 200.0]}}
    cal = calibrate(tr.nominal, diag)
    assert [(c["name"], c["role"]) for c in cal.changes] == [("sensor_term", "reading")]
    # the file passes `heavecomp params` and reads back to the same correction
    (d / FILE).write_text(to_toml(cal), encoding="utf-8")
    res = cli("params", d / FILE, "-o", d / "checked.toml")
    assert res.returncode == 0, res.stderr
    (e,) = spec.reading_effects(spec.load(d / FILE))
    assert e.name == "sensor_term" and e.channel == "wob"
    # the log read through the file: the clipped samples move back towards the clean load
    raw, fixed = load_run(path, tr.nominal), load_run(path, spec.load(d / FILE))
    at = clean > w_max
    before = np.sqrt(np.mean((raw["wob"][at] - clean[at]) ** 2))
    after = np.sqrt(np.mean((fixed["wob"][at] - clean[at]) ** 2))
    assert after < 0.6 * before
    # written with the log, the file reports the term's held-out replay shrink, and replaying reproduces it
    cal = write(tr.nominal, diag, d, source="run.csv", run=raw)
    assert cal.expected_shrink > 0.2 and cal.verdict_shrink == 0.2
    rep = replay_shrink(path, spec.load(d / FILE), tr.nominal, dict(diag, calibrated=cal.block()))
    assert rep["agreement"] <= 0.1
    # where the cell did not clip, the reading is left (nearly) as it was: within the WOB's own noise
    below = clean < w_max - 3 * tr.truth["noise_floor"]["wob"]
    assert np.sqrt(np.mean((fixed["wob"][below] - raw["wob"][below]) ** 2)) < 2 * tr.truth["noise_floor"]["wob"]


@pytest.mark.slow
def test_a_planted_lever_arm_is_fitted_within_one_percent():
    """The generator's lever arm (heave measured L m from the compensator, a logged pitch; never the
    candidate's equation): the reading fit, its lever arm rescanned for a second start, finds L."""
    from heavecomp.benchmark import Case, generate
    from heavecomp.diagnosis import fitting as F
    from heavecomp.diagnosis.replay import prepare

    tr = generate(Case("heave_reference", 560018, "named", variant="lever_arm", sea="buoy", duration=300.0))
    ctx = prepare(tr.to_run(), tr.nominal, decimate=2)
    got = F.fit(ctx, "heave_reference")
    truth = tr.truth["parameters"]["heave_reference"]["lever_arm"]
    # found within 1 % (measured: 10.958 m of 10.974 m; the stalled local fit stopped at 8.8-9.2 m of 13.65 m on
    # 560018's 600 s log).  Just outside the reported 1-sigma (11 mm against a 15 mm error): the Jacobian's
    # sigma, even inflated for correlated residuals, under-states a stick-slip fit's spread
    assert got.values["lever_arm"] == pytest.approx(truth, rel=0.01)


def test_a_discovered_flow_line_term_is_carried_at_the_line_hook_and_round_trips(tmp_path):
    from heavecomp.params import paper_a

    nom = paper_a()
    d = {"component": "flow_line", "features": ["v_abs_v"], "coefficients": {"v_abs_v": -3.1e6}, "shrink": 0.7,
         "term": "-3.1e6*v*|v|", "levels": {"x_mean": 0.1}}
    diag = {"verdict": {"effect": "discovered", "confidence": "low", "shrink": 0.3, "shrink_channel": "pressure",
                        "component": "flow_line", "discovered": d}, "split": {"fit": [0, 100], "validate": [100, 150]}}
    cal = calibrate(nom, diag)
    assert [(c["name"], c["role"]) for c in cal.changes] == [("line_term", "plant")]
    (tmp_path / FILE).write_text(to_toml(cal), encoding="utf-8")
    assert cli("params", tmp_path / FILE, "-o", tmp_path / "checked.toml").returncode == 0
    (e,) = spec.plant_effects(spec.load(tmp_path / FILE))
    # the hook adds the term to the cylinder pressure: a turbulent drop against the flow
    assert e.line(0.2, 2e6, (), None, *e.prm) == pytest.approx(2e6 - 3.1e6 * 0.04)
    # a feature the hook cannot compute (time): not carried, the nominal kept and the file says why
    cal = calibrate(nom, dict(diag, verdict=dict(diag["verdict"], discovered=dict(d, features=["t"],
                                                                                 coefficients={"t": 5.0}))))
    assert cal.changes == [] and "has no model form" in to_toml(cal)


def test_a_discovered_string_term_in_the_stretch_is_carried_with_its_centre_and_round_trips(tmp_path):
    """590030's kind of term (stretch cubed about its median, a sign term) is carried as ``string_term``: the
    hook recovers the stretch z_h + s - y_b from the tension it is handed, so the term added is the search's
    feature of the plant's own stretch; without the recorded median it is not carried."""
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import plant_vectors, tension

    nom = paper_a()
    d = {"component": "string_formation", "features": ["sign_v_neg", "rel_cubed"], "shrink": 0.52,
         "coefficients": {"sign_v_neg": 4.1e3, "rel_cubed": 8.3e9}, "term": "...",
         "levels": {"x_mean": 0.002, "rel_median": 0.004}}
    diag = {"verdict": {"effect": "discovered", "confidence": "low", "shrink": 0.1, "shrink_channel": "wob",
                        "component": "string_formation", "discovered": d},
            "split": {"fit": [0, 100], "validate": [100, 150]}}
    cal = calibrate(nom, diag)
    assert [(c["name"], c["role"]) for c in cal.changes] == [("string_term", "plant")]
    assert cal.changes[0]["parameters"]["rel_median"] == 0.004
    (tmp_path / FILE).write_text(to_toml(cal), encoding="utf-8")
    assert cli("params", tmp_path / FILE, "-o", tmp_path / "checked.toml").returncode == 0
    (e,) = spec.plant_effects(spec.load(tmp_path / FILE))
    PP = plant_vectors(nom).PP
    s, v, yb, vb, zh, dzh = 0.3, -0.2, 0.05, 0.1, 0.4, 0.3
    T = tension(s, v, yb, vb, zh, dzh, PP)
    dv = dzh + v - vb                                    # shortening: the sign term takes 4.1 kN off
    stretch = zh + s - yb
    assert e.string(dv, T, (), PP, *e.prm) == pytest.approx(T - 4.1e3 + 8.3e9 * (stretch - 0.004) ** 3, rel=1e-12)
    # no recorded centre (a diagnosis before levels.rel_median): the term cannot be placed, the nominal kept
    bare = dict(d, levels={"x_mean": 0.002})
    cal = calibrate(nom, dict(diag, verdict=dict(diag["verdict"], discovered=bare)))
    assert cal.changes == [] and "has no model form" in to_toml(cal)
