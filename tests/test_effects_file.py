"""``[[effects]]`` in the parameter file (issue 22 item 1): strict checks, round trip, plant vs reading."""

from __future__ import annotations

import numpy as np
import pytest

from heavecomp.cli import main
from heavecomp.effects import spec
from heavecomp.effects.discovered_term import DiscoveredTerm
from heavecomp.errors import ParameterError
from heavecomp.params import dumps, loads, paper_a

FX = [("string_damping", {"damping": 4.7e4}), ("sensor_gain", {"channel": "wob", "factor": 1.08})]


def _file(extra: str) -> str:
    return dumps(paper_a()) + "\n" + extra


def test_effects_round_trip_through_the_file():
    p = paper_a().replace(effects=FX)
    text = dumps(p)
    assert text.count("[[effects]]") == 2
    q = loads(text)
    assert q == p and q.effects == p.effects
    assert [type(e).__name__ for e in spec.check(q)] == ["StringDamping", "SensorGain"]


@pytest.mark.parametrize("entry, words", [
    ('name = "string_dampin"\ndamping = 1e4', ["effects[0].name", "did you mean 'string_damping'"]),
    ('name = "string_damping"\ndampng = 1e4', ["effects[0].dampng", "did you mean 'damping'"]),
    ('name = "string_damping"\ndamping = 1e9', ["effects[0].damping", "N s/m", "outside the possible range"]),
    ('name = "string_damping"', ["effects[0].damping", "missing required key", "N s/m"]),
    ('name = "sensor_gain"\nfactor = 1.1', ["effects[0].channel", "missing required key"]),
    ('name = "sensor_gain"\nchannel = "wbo"\nfactor = 1.1', ["effects[0].channel", "did you mean 'wob'"]),
    ('name = "string_damping"\nchannel = "wob"\ndamping = 1e4', ["effects[0].channel", "acts on no channel"]),
    ('damping = 1e4', ["effects[0].name", "missing required key"]),
    ('name = "string_damping"\ndamping = "lots"', ["effects[0].damping", "expected a number"]),
])
def test_a_bad_entry_is_one_line_naming_the_key(entry, words):
    with pytest.raises(ParameterError) as exc:  # the shape by the params layer, the rest by the effects layer
        spec.check(loads(_file("[[effects]]\n" + entry + "\n")))
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_a_single_table_instead_of_an_array_is_named():
    with pytest.raises(ParameterError, match=r"\[\[effects\]\]"):
        loads(_file('[effects]\nname = "string_damping"\ndamping = 1e4\n'))


def test_params_command_checks_and_writes_the_effects_back(tmp_path, capsys):
    good = tmp_path / "fx.toml"
    good.write_text(dumps(paper_a().replace(effects=FX)))
    assert main(["params", str(good)]) == 0
    out = capsys.readouterr().out
    assert out.count("[[effects]]") == 2 and 'channel = "wob"' in out
    bad = tmp_path / "bad.toml"
    bad.write_text(good.read_text().replace("damping = 47000.0", "dampin = 47000.0"))
    assert main(["params", str(bad)]) == 2
    assert "did you mean 'damping'" in capsys.readouterr().err


def test_optional_parameters_take_their_null_value():
    p = loads(_file('[[effects]]\nname = "sensor_offset"\nchannel = "pressure"\noffset = 101325.0\n'
                    '[[effects]]\nname = "discovered_term"\nsign_v_pos = 1500.0\n'))
    off, term = spec.check(p)
    assert off.values == {"offset": 101325.0, "drift": 0.0}
    assert term.values["sign_v_neg"] == 0.0 and term.values["sign_v_pos"] == 1500.0


def test_plant_and_reading_effects_are_kept_apart():
    p = paper_a().replace(effects=FX + [("heave_reference", {"scale": 0.9, "delay": 0.1, "lever_arm": 0.0})])
    assert [e.name for e in spec.plant_effects(p)] == ["string_damping"]
    assert [e.name for e in spec.reading_effects(p)] == ["sensor_gain", "heave_reference"]
    assert [e.name for e in spec.effects_for(p)] == ["string_damping"]
    assert spec.effects_for(p, ()) == []  # an explicit effects= replaces the file's


def test_correct_undoes_what_each_sensor_effect_does():
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 100.0, 2001)
    true = {"wob": 9e4 + 3e3 * np.sin(0.5 * t), "pressure": 2.4e6 + 1e4 * rng.normal(size=t.size),
            "stroke": 0.1 * np.sin(0.3 * t), "heave": np.sin(0.6 * t)}
    fx = spec.check(paper_a().replace(effects=[
        ("sensor_gain", {"channel": "wob", "factor": 1.08}),
        ("sensor_offset", {"channel": "pressure", "offset": 101325.0, "drift": 2.0}),
        ("sensor_delay", {"channel": "stroke", "delay": 0.5})]))
    read = {c: y.copy() for c, y in true.items()}
    for e in fx:
        read[e.channel] = e.measure(t, t, true[e.channel])
    got, notes = spec.correct(fx, t, read)
    assert len(notes) == 3
    np.testing.assert_allclose(got["wob"], true["wob"], rtol=1e-12)
    np.testing.assert_allclose(got["pressure"], true["pressure"], rtol=1e-12)
    ok = np.isfinite(got["stroke"])
    assert np.isnan(got["stroke"][-1]) and ok.sum() > 0.99 * t.size  # the last t_d seconds are unknown
    np.testing.assert_allclose(got["stroke"][ok], true["stroke"][ok], atol=1e-12)


def test_correct_reads_a_files_heave_reference_by_name_high_pass_included():
    """A calibrated file's MRU high-pass is undone when the log is read, whatever the order of its keys:
    the heave the compensator saw, not the measured one (positionally a file's ``highpass`` was taken
    for the lever arm, which the angle term applies, and the high-pass was dropped: the replay and the
    re-diagnosis of a calibrated MRU file read the log as the nominal does)."""
    from scipy.signal import butter, lfilter

    t = np.arange(0.0, 600.0, 0.1)
    true = 0.8 * np.sin(2 * np.pi * t / 11.0) + 0.3 * np.sin(2 * np.pi * t / 8.0 + 1.0)
    b, a = butter(2, 0.01, btype="highpass", fs=10.0)  # the MRU's 2nd-order high-pass, 100 s
    meas = lfilter(b, a, true)
    for order in (("scale", "delay", "highpass", "lever_arm"), ("highpass", "lever_arm", "delay", "scale")):
        values = {"scale": 1.0, "delay": 0.0, "highpass": 0.01, "lever_arm": 0.0}
        fx = spec.check(paper_a().replace(effects=[("heave_reference", {k: values[k] for k in order})]))
        got, notes = spec.correct(fx, t, {"heave": meas})
        late = t > 100.0  # after the filter's start-up
        err, before = (np.sqrt(np.mean((y - true)[late] ** 2)) for y in (got["heave"], meas))
        assert len(notes) == 1 and err < 0.2 * before, (order, err, before)


def test_discovered_term_adds_friction_by_direction_and_never_pushes():
    J = 5e3
    args = dict(sign_v_pos=1.9e3, sign_v_neg=-200.0, v=0.0, v_abs_v=0.0, p_sign_v=0.0)
    jump = DiscoveredTerm.jump
    assert jump(0, 0.1, 2e6, J, 0.0, 1.0, (), None, *args.values()) == pytest.approx(J + 1.9e3)
    assert jump(0, 0.1, 2e6, J, 0.0, -1.0, (), None, *args.values()) == pytest.approx(J - 200.0)
    assert jump(0, 0.1, 2e6, 100.0, 0.0, -1.0, (), None, *args.values()) == 0.0  # clipped: friction >= 0
    assert jump(0, 0.1, 2e6, J, 0.0, 1.0, (), None, *DiscoveredTerm.null(None).values()) == J


def test_simulate_runs_the_files_plant_effects_and_not_its_reading_effects():
    from heavecomp.simulate import simulate

    base = paper_a()
    p = base.replace(effects=FX)
    got = simulate(p, 30.0).data
    want = simulate(base, 30.0, effects=[FX[0]]).data  # the plant effect only: the WOB gain reads logs
    np.testing.assert_array_equal(got, want)
    assert not np.array_equal(got, simulate(base, 30.0).data)  # the damping acts
    np.testing.assert_array_equal(simulate(p, 30.0, effects=()).data, simulate(base, 30.0).data)


def test_a_run_folders_params_toml_records_the_effects(tmp_path):
    from heavecomp.report.provenance import write_params

    p = paper_a().replace(effects=FX)
    assert spec.load(write_params(tmp_path, p)) == p


def test_linearise_and_the_mpc_model_take_the_files_plant_effects():
    from heavecomp.analysis.linear import linearise_details
    from heavecomp.controllers.linear_mpc import LinearMPC

    base, p = paper_a(), paper_a().replace(effects=FX)
    damped, nominal = linearise_details(p), linearise_details(base)
    assert not np.allclose(damped.sys.A, nominal.sys.A)  # the string damping enters the dynamics
    np.testing.assert_allclose(damped.sys.A, linearise_details(base, effects=[FX[0]]).sys.A)
    assert [e.name for e in LinearMPC(p).effects] == ["string_damping"]


def test_a_campaign_refuses_plant_effects_it_would_not_simulate(tmp_path):
    from heavecomp.campaign import spec as campaign

    (tmp_path / "rig.toml").write_text(dumps(paper_a().replace(effects=FX)))
    text = (campaign.DEFAULT_FILE.read_text().replace('base = "paper_a"', 'base = "rig.toml"'))
    with pytest.raises(ParameterError, match="plant effects in \\[\\[effects\\]\\] \\(string_damping, sensor_gain\\)"):
        campaign.loads(text, base_dir=tmp_path).base_params()


@pytest.mark.slow  # compiles the stepper of a discovered_term composition (about 40 s of CPU once, 78 s at load 8)
def test_discovered_term_is_the_open_search_term_it_carries():
    """Round trip: a plant with discovered_term, its friction residual (simulated friction minus the
    nominal law at the same v and p, the friction component's residual) is exactly the term, and the
    open search reads back the features and coefficients the effect was given."""
    from heavecomp.diagnosis.equation_error import open_search
    from heavecomp.friction.laws import friction_cont, friction_jump
    from heavecomp.plants.cmc import plant_vectors
    from heavecomp.simulate import simulate

    c, k = 2.5e3, 1.0e-3
    base = paper_a()
    r = simulate(base.replace(effects=[("discovered_term", {"sign_v_pos": c, "p_sign_v": k})]), 200.0,
                 rate=50.0).to_dict()
    pv = plant_vectors(base)
    t, v, p = r["t"], r["stroke_velocity"], r["pressure"]
    nominal = np.array([friction_jump(pv.code, abs(a), b, pv.FP) * np.sign(a) + friction_cont(pv.code, a, b, pv.FP)
                        for a, b in zip(v, p)])
    sliding = np.abs(v) > 1e-3
    res = np.where(sliding, r["friction"] - nominal, np.nan)
    np.testing.assert_allclose(res[sliding], (c * (v > 0) + k * p * np.sign(v))[sliding], atol=1e-6 * c)
    got = open_search(res, {"t": t, "v": v, "p": p}, sliding & (t < 130.0), sliding & (t >= 130.0),
                      component="friction")
    assert got["features"] == ["sign_v_pos", "p_sign_v"]
    assert got["coefficients"]["sign_v_pos"] == pytest.approx(c) and got["coefficients"]["p_sign_v"] == pytest.approx(k)
