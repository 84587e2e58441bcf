"""Issue 31, the defects of the rig engineer's loop (reproducers 2026-12: D1, D2, D6, D7, D8, U7-U13), each
checked on what the code decides; the files are generated here or kept in tests/data."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import run
from heavecomp.effects import spec
from heavecomp.errors import ParameterError
from heavecomp.params import dumps, loads, paper_a


def _file(tmp_path, extra: str, name="p.toml", params=None) -> str:
    f = tmp_path / name
    f.write_text(dumps(params or paper_a()) + "\n" + extra)
    return str(f)


# ---------------------------------------------------------------- D6: duplicate [[effects]]

GAIN = '[[effects]]\nname = "sensor_gain"\nchannel = "wob"\nfactor = 1.08\n'
DAMP = '[[effects]]\nname = "string_damping"\ndamping = 4.7e4\n'


@pytest.mark.parametrize("entries, words", [
    (GAIN + "\n" + GAIN, ["effects[1]", "effects[0]", "sensor_gain", "wob"]),
    (DAMP + "\n" + GAIN + "\n" + DAMP, ["effects[2]", "effects[0]", "string_damping"]),
])
def test_a_duplicate_effect_is_refused_by_index(tmp_path, entries, words):
    """A WOB gain of 1.08 written twice corrected the reading by 1.1664 without a word (D6)."""
    with pytest.raises(ParameterError) as exc:
        spec.check(loads(dumps(paper_a()) + "\n" + entries))
    assert "\n" not in str(exc.value) and all(w in str(exc.value) for w in words)
    r = run("params", _file(tmp_path, entries))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "effects[" in r.stderr


def test_the_same_effect_on_two_channels_is_no_duplicate():
    other = GAIN.replace('"wob"', '"stroke"')
    assert len(spec.check(loads(dumps(paper_a()) + "\n" + GAIN + "\n" + other))) == 2


# ---------------------------------------------------------------- U12: params -q, the file's effects named

def test_params_quiet_is_quiet_and_the_check_names_the_effects(tmp_path):
    f = _file(tmp_path, DAMP + "\n" + GAIN)
    quiet = run("params", f, "-q")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    loud = run("params", f)
    assert loud.returncode == 0 and "[[effects]]" in loud.stdout
    assert "2 [[effects]]: string_damping (plant), sensor_gain on wob (reading)" in loud.stderr


# ---------------------------------------------------------------- U11: an epoch-ms time column

@pytest.mark.parametrize("clock, units", [(1733500000000, {"t": "ms"}), (1733500000.0, None)])
def test_a_clock_in_the_time_column_is_no_non_uniform_sampling(tmp_path, clock, units):
    """Epoch ms scaled to s before the origin came off kept ~2e-7 s of rounding in every 40 ms interval:
    "non-uniform sampling (intervals 0.04..0.04 s)" on a uniform 25 Hz log (U11)."""
    from heavecomp.diagnosis.data import load_run
    from heavecomp.simulate import simulate

    res = simulate(paper_a(), 120.0, rate=25.0)
    step = 40 if units else 0.04
    f = tmp_path / "log.csv"
    rows = [f"{clock + i * step:.13g};{z:.6g};{s:.6g};{p:.6g};{w:.6g}" for i, (z, s, p, w) in
            enumerate(zip(res["heave"], res["stroke"], res["pressure"], res["wob"]))]
    f.write_text("TIME;heave;stroke;pressure;wob\n" + "\n".join(rows) + "\n")
    r = load_run(f, paper_a(), columns={"t": "TIME"}, units=units)
    assert not [w for w in r.warnings if "non-uniform" in w], r.warnings
    np.testing.assert_allclose(np.diff(r.t), 0.04, rtol=0, atol=1e-9 if units else 1e-6)
    assert r.t[0] == 0.0 and abs(r.t[-1] - 120.0) < 1e-6


# ---------------------------------------------------------------- U8: a controller designed on another file

def _rig(tmp_path, name, extra=""):
    p = paper_a("stribeck").replace(active={"u_max": 60e3, "rate_max": 300e3, "control_rate": 20.0})
    return _file(tmp_path, extra, name=name, params=p)


def test_a_controller_designed_on_the_nominal_leaves_more_wob_variation_on_a_plant_with_more_friction(tmp_path):
    """The first question after a calibration: what does my current controller do on the rig as it is (U8)?
    On a plant with 10 kN more seal friction in a 0.6 m band of the stroke, the linear MPC designed on the
    nominal file (which does not know it) holds the WOB worse than the one designed on the plant's own file."""
    plant = _rig(tmp_path, "plant.toml", '[[effects]]\nname = "position_friction"\nextra_force = 1e4\n'
                                          'centre = 0.0\nwidth = 0.6\n')
    nominal = _rig(tmp_path, "nominal.toml")
    std = {}
    for design in ("plant", "nominal"):
        out = tmp_path / design
        r = run("simulate", plant, "--duration", 60, "--controller", "linear-mpc", "--controller-params",
                tmp_path / f"{design}.toml", "--out", out)
        assert r.returncode == 0, r.stderr
        std[design] = json.loads((out / "metrics.json").read_text())["wob_std"]
    assert std["nominal"] > 1.3 * std["plant"], std


def test_controller_params_needs_a_controller_and_a_valid_file(tmp_path):
    nominal = _rig(tmp_path, "nominal.toml")
    r = run("simulate", nominal, "--duration", 10, "--controller-params", nominal, "--out", tmp_path / "o")
    assert r.returncode == 2 and "--controller-params needs --controller" in r.stderr
    bad = _rig(tmp_path, "bad.toml", '[[effects]]\nname = "string_dampin"\ndamping = 1e4\n')
    r = run("simulate", nominal, "--duration", 10, "--controller", "pid", "--controller-params", bad,
            "--out", tmp_path / "o")
    assert r.returncode == 2 and "effects[0].name" in r.stderr


# ---------------------------------------------------------------- D7: the file's reading effects in the closed loop

def test_simulate_with_a_controller_refuses_a_bare_sensor_delay_and_warns_of_a_sensor_lag(tmp_path):
    """docs/control.md: a reading's delay has no finite-state model (refused by name), a ``sensor_lag`` is read
    through its factor with a warning naming what is left out; the closed loop ignored both (D7)."""
    delay = _rig(tmp_path, "k4.toml", '[[effects]]\nname = "sensor_delay"\nchannel = "wob"\ndelay = 0.5\n')
    r = run("simulate", delay, "--duration", 10, "--controller", "linear-mpc", "--out", tmp_path / "k4")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "k4.toml [[effects]]" in r.stderr and "sensor_delay" in r.stderr and not (tmp_path / "k4").exists()
    lag = _rig(tmp_path, "k1.toml", '[[effects]]\nname = "sensor_lag"\nchannel = "stroke"\nfactor = 0.983\n'
                                    'time_constant = 0.839\ndelay = -0.048\n')
    r = run("simulate", lag, "--duration", 10, "--controller", "linear-mpc", "--out", tmp_path / "k1")
    assert r.returncode == 0 and "sensor_lag" in r.stderr and "time_constant=0.839" in r.stderr


def test_the_rigs_sensor_misreading_reaches_the_controller(tmp_path):
    """The plant's reading effect acts on what the controller measures: a PID (no model) on a WOB read 10 %
    high holds the reading at the set-point, so the true WOB settles 10 % low; without the effect it holds W_0."""
    means = {}
    for name, extra in (("plain", ""), ("gain", '[[effects]]\nname = "sensor_gain"\nchannel = "wob"\nfactor = 1.1\n')):
        f = _rig(tmp_path, f"{name}.toml", extra)
        r = run("simulate", f, "--duration", 120, "--controller", "pid", "--no-noise", "--out", tmp_path / name)
        assert r.returncode == 0, r.stderr
        means[name] = json.loads((tmp_path / name / "metrics.json").read_text())["wob_mean"]
    w0 = paper_a().operating_point.wob_setpoint
    assert abs(means["plain"] / w0 - 1) < 0.02 and abs(means["gain"] * 1.1 / w0 - 1) < 0.02, means


# ---------------------------------------------------------------- U9: the controller's sample time

class _Slow:
    """A controller that computes for ``wait`` s each step."""

    def __init__(self, wait):
        self.wait = wait

    def step(self, t, measurement, preview=None):
        import time

        time.sleep(self.wait)
        return 0.0


@pytest.mark.parametrize("wait, missed", [(0.07, True), (0.0, False)])
def test_a_controller_that_misses_its_sample_time_is_said_so(tmp_path, caplog, wait, missed):
    """The NMPC's p99 solve time of 62 ms against its 50 ms interval gave no word (U9)."""
    from heavecomp.closed_loop import simulate_closed_loop
    from heavecomp.report.simulation import write_closed_loop_outputs

    p = paper_a().replace(active={"control_rate": 20.0})
    with caplog.at_level("WARNING", logger="heavecomp"):
        res = simulate_closed_loop(p, _Slow(wait), 1.0)
    said = [r.getMessage() for r in caplog.records if "sample time" in r.getMessage()]
    assert len(said) == int(missed) and (not missed or "50 ms sample time" in said[0])
    write_closed_loop_outputs(res, tmp_path)
    assert json.loads((tmp_path / "metrics.json").read_text())["sample_time_missed"] is missed


# ---------------------------------------------------------------- D2: effect sizes where the physics runs away

@pytest.mark.parametrize("entry, key", [
    ('name = "line_term"\nconst = 1e12', "effects[0].const"),
    ('name = "string_term"\nrel_cubed = 1e12\nsign_v_pos = 1e12', "effects[0].sign_v_pos"),
    ('name = "gas_term"\nconst = -1e12', "effects[0].const"),
])
def test_a_hook_term_that_would_run_the_stroke_away_is_refused_by_name_before_work(tmp_path, entry, key):
    """``line_term`` ``const = 1e12`` Pa, inside the open search's +-1e12 bounds, simulated to a 1.2e10 m stroke
    with exit 0 (D2): the force it adds over the rig's envelope would move the stroke past any stroke built."""
    f = _file(tmp_path, "[[effects]]\n" + entry + "\n")
    r = run("simulate", f, "--duration", 300, "--out", tmp_path / "s")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "s").exists()
    assert key in r.stderr and "longest stroke built" in r.stderr


def test_a_hook_term_of_a_calibrated_size_is_kept():
    """Terms of the size a diagnosis finds (kPa, kN) stay valid: the bound is the rig's, not a tight one."""
    p = loads(dumps(paper_a()) + '\n[[effects]]\nname = "line_term"\nconst = 2e4\nv_abs_v = -3.1e6\n\n'
              '[[effects]]\nname = "string_term"\nrel = 2e5\nrel_cubed = 8.3e9\nrel_median = 0.01\n')
    assert [e.name for e in spec.check(p)] == ["line_term", "string_term"]


def test_a_stepper_divergence_names_the_files_effects():
    """A run that diverges with effects at the plant's hooks named only the step (D2)."""
    from heavecomp.simulate import simulate
    from heavecomp.simulate.core import SimulationError

    p = paper_a().replace(effects=[("string_damping", {"damping": 2e6})])
    with pytest.raises(SimulationError, match=r"with effects\[0\] \(string_damping\)"):
        simulate(p, 10.0, dt=0.05)


@pytest.mark.slow  # compiles a stepper with a string_term (about 60 s of CPU once)
def test_a_divergence_at_the_default_step_names_the_entry_and_not_the_step():
    """A huge ``string_term`` diverges at the plant's own stable step: the message named the type only and
    advised ``--dt`` (F5); it names ``effects[1] (string_term)`` and gives no step advice."""
    from heavecomp.simulate import simulate
    from heavecomp.simulate.core import SimulationError

    p = paper_a().replace(effects=[("sensor_gain", {"channel": "wob", "factor": 1.1}),
                                   ("string_term", {"rel_cubed": 1e12, "v_abs_v": 1e12})])
    with pytest.raises(SimulationError, match=r"effects\[1\] \(string_term\)") as e:
        simulate(p, 60.0)
    assert "dt" not in str(e.value) and e.value.option != "dt", str(e.value)


# ---------------------------------------------------------------- D1: the sample-rate floor from the rig's modes

def _log(tmp_path, rate, duration=300.0, name=None, drop=(), params=None):
    from heavecomp.simulate import simulate

    res = simulate(params or paper_a(), duration, rate=rate)
    cols = [c for c in ("t", "heave", "stroke", "pressure", "wob") if c not in drop]
    f = tmp_path / (name or f"log_{rate:g}Hz.csv")
    arr = np.column_stack([np.asarray(res[c], float) for c in cols])
    np.savetxt(f, arr, delimiter=",", header=",".join(cols), comments="", fmt="%.9g")
    return f


def test_a_log_slower_than_the_rigs_fastest_mode_is_refused_naming_its_rate(tmp_path):
    """A 1 Hz log of a plant with string damping read ``none``, high (D1): paper A's bit-bounce mode (1.76 Hz)
    aliases at 1 Hz.  Diagnose and monitor refuse it before work; a 5 Hz log is read."""
    from heavecomp.diagnosis.data import load_run
    from heavecomp.diagnosis.policy import DEFAULT
    from heavecomp.params.plausibility import natural_frequencies

    floor = DEFAULT.min_samples_per_mode * max(natural_frequencies(paper_a())[0])
    assert 1.0 < floor < 5.0  # 4.4 Hz: the reproducer's 5 and 10 Hz logs read string damping right
    slow = _log(tmp_path, 1.0)
    params = _file(tmp_path, "")
    for cmd in ("diagnose", "monitor"):
        r = run(cmd, slow, "--params", params, "--out", tmp_path / cmd)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert "sampled at 1 Hz" in r.stderr and f"{floor:.3g} Hz" in r.stderr and not (tmp_path / cmd).exists()
    assert load_run(_log(tmp_path, 5.0), paper_a()).duration == pytest.approx(300.0)


# ---------------------------------------------------------------- U13: a channel the log lacks is said assumed

@pytest.mark.parametrize("assumed, said, unsaid", [
    (("stroke",), ["assumed: no stroke channel"], ["stroke +0.0000 m", "(stuck)"]),
    (("wob",), ["WOB W_0 (assumed: no WOB channel)", "stroke +0.0100 m"], ["WOB 98.1 kN"]),
    ((), ["stroke +0.0100 m", "(sliding)", "WOB 98.1 kN"], ["assumed"]),
])
def test_the_reports_start_state_says_a_missing_channel_is_assumed(assumed, said, unsaid):
    """A log without a stroke column reported "stroke +0.0000 m ... (stuck)" as if measured (U13)."""
    from types import SimpleNamespace

    from heavecomp.diagnosis.start import InitialState
    from heavecomp.report.diagnosis import _initial_state_lines

    st = InitialState(stroke=0.0 if "stroke" in assumed else 0.01, stroke_velocity=0.0 if "stroke" in assumed
                      else 0.02, lower_displacement=0.0, lower_velocity=0.0, stuck="stroke" in assumed,
                      heave_reference=0.0, wob=98.1e3, at_rest=False, window=10.0, sigma={}, assumed=assumed)
    text = _initial_state_lines(SimpleNamespace(initial_=st))[0]
    assert all(w in text for w in said) and not any(w in text for w in unsaid), text


# ---------------------------------------------------------------- D8: the line names the file's key, not the log

@pytest.mark.parametrize("entry, words", [
    ('name = "heave_reference"\nscale = 0.0\ndelay = 0.0\nlever_arm = 0.0', ["effects[0].scale = 0", "no heave motion"]),
    ('name = "sensor_gain"\nchannel = "wob"\nfactor = 0.0', ["effects[0].factor = 0", "wob channel would read 0"]),
])
def test_a_reading_of_zero_is_refused_by_name(tmp_path, entry, words):
    """``heave_reference`` ``scale = 0`` was blamed on the log ("no heave motion" in it) (D8)."""
    r = run("params", _file(tmp_path, "[[effects]]\n" + entry + "\n"))
    assert r.returncode == 2 and all(w in r.stderr for w in words), r.stderr


def test_an_effect_on_a_channel_the_log_lacks_is_named_by_index(tmp_path):
    f = _file(tmp_path, DAMP + "\n" + GAIN.replace('"wob"', '"stroke"'))
    r = run("diagnose", _log(tmp_path, 10.0, 120.0, drop=("stroke",)), "--params", f, "--out", tmp_path / "d")
    assert r.returncode == 2 and "effects[1] (sensor_gain): channel 'stroke' is not in the log" in r.stderr


def test_a_negative_span_reaches_the_commands_own_check(tmp_path):
    """``--span -5:10`` gave argparse's "expected one argument" (D8)."""
    r = run("diagnose", _log(tmp_path, 10.0, 120.0), "--params", _file(tmp_path, ""), "--span", "-5:10",
            "--out", tmp_path / "d")
    assert r.returncode == 2 and "expected one argument" not in r.stderr and "'-5' must be" in r.stderr, r.stderr


def test_a_hook_load_in_tonnes_is_named_as_the_hook_load(tmp_path):
    """A hook load logged in tonnes read as N was blamed on a ``wob`` column the log lacks (D8)."""
    from heavecomp.simulate import simulate

    res = simulate(paper_a(), 120.0, rate=10.0)
    sw = 1.5e6
    f = tmp_path / "hook.csv"
    rows = [f"{t:.2f},{z:.6g},{s:.6g},{p:.6g},{(sw - w) / 9810:.6g}" for t, z, s, p, w in
            zip(res["t"], res["heave"], res["stroke"], res["pressure"], res["wob"])]
    f.write_text("t,heave,stroke,pressure,hook_load\n" + "\n".join(rows) + "\n")
    params = _file(tmp_path, "[measurement]\nstring_weight = 1.5e6\n")
    r = run("diagnose", f, "--params", params, "--out", tmp_path / "d")
    assert r.returncode == 2 and "column 'hook_load'" in r.stderr and "measurement.string_weight" in r.stderr
    assert "hook_load=t" in r.stderr and "column 'wob'" not in r.stderr


def test_a_hook_load_in_n_declared_in_tonnes_is_named_as_the_hook_load(tmp_path):
    """``--units hook_load=t`` on a hook load in N: the WOB it gives (-1.4e10 N) was blamed on a ``wob`` column the
    log lacks by the generic unit check (F4); the line names the hook load and the string weight."""
    from heavecomp.simulate import simulate

    res = simulate(paper_a(), 120.0, rate=10.0)
    f = tmp_path / "hook.csv"
    rows = [f"{t:.2f},{z:.6g},{s:.6g},{p:.6g},{1.5e6 - w:.6g}" for t, z, s, p, w in
            zip(res["t"], res["heave"], res["stroke"], res["pressure"], res["wob"])]
    f.write_text("t,heave,stroke,pressure,hook_load\n" + "\n".join(rows) + "\n")
    params = _file(tmp_path, "[measurement]\nstring_weight = 1.5e6\n")
    r = run("diagnose", f, "--params", params, "--out", tmp_path / "d", "--units", "hook_load=t")
    assert r.returncode == 2 and "column 'hook_load'" in r.stderr and "string_weight" in r.stderr, r.stderr
    assert "column 'wob'" not in r.stderr and "hook_load=N" in r.stderr, r.stderr


def test_a_log_without_heave_motion_says_so_not_a_wrong_time_base(tmp_path):
    """A calm-sea log's heave noise has a "period" of 2 s: it was read as a time base at the wrong scale (D8)."""
    from heavecomp.diagnosis.data import load_run

    calm = paper_a().replace(heave={"amplitude": 0.0})
    f = _log(tmp_path, 10.0, 300.0, params=calm)
    arr = np.loadtxt(f, delimiter=",", skiprows=1)
    arr[:, 1:] += np.random.default_rng(1).normal(0.0, [2e-3, 2e-3, 2e3, 400.0], (arr.shape[0], 4))  # sensors' noise
    np.savetxt(f, arr, delimiter=",", header="t,heave,stroke,pressure,wob", comments="", fmt="%.9g")
    q = load_run(f, paper_a()).quality
    assert [i["kind"] for i in q.issues] == ["no_heave"] and "no heave motion" in q.issues[0]["message"]
    assert q.confidence_cap == "low"


# ---------------------------------------------------------------- U7: what analyse kept, linearised or left out

def test_analyse_says_what_it_kept_linearised_or_left_out(tmp_path):
    """``analyse calibrated.toml`` gave the nominal's numbers without a word about the file's friction (U7)."""
    f = _file(tmp_path, '[[effects]]\nname = "pressure_friction"\nextra_pressure_coefficient = 5e-3\n\n' + DAMP
              + "\n" + GAIN)
    r = run("analyse", f, "--out", tmp_path / "a", "--points", 50)
    assert r.returncode == 0
    line = r.stdout.splitlines()[0]
    assert "friction law (stribeck" in line and "effects[0] pressure_friction: left out" in line
    assert "effects[1] string_damping: kept" in line and "effects[2] sensor_gain on wob: left out" in line
    assert "--sliding-velocity" in line
    s = json.loads((tmp_path / "a" / "analysis.json").read_text())
    roles = {e["item"]: e["role"] for e in s["effects"]}
    assert roles["effects[0] pressure_friction"] == "left out" and "describing" in s["effects"][1]["why"]
    assert "- effects[1] string_damping: **kept**" in (tmp_path / "a" / "report.md").read_text()
    r = run("analyse", f, "--out", tmp_path / "b", "--points", 50, "--sliding-velocity", 0.1)
    s = json.loads((tmp_path / "b" / "analysis.json").read_text())
    assert {e["item"]: e["role"] for e in s["effects"]}["effects[0] pressure_friction"] == "linearised"


def test_a_reading_that_depends_on_the_string_tops_motion_runs_in_the_closed_loop(tmp_path):
    """A calibrated ``sensor_term`` with a ``*_motion`` term reads z_h + s: the loop hands it the true motion
    (it raised "they need the heave and stroke with the reading" once the loop took the file's readings)."""
    f = _rig(tmp_path, "k2.toml", '[[effects]]\nname = "sensor_term"\nchannel = "wob"\nc_top = -1.72e4\n'
                                  'c_top_motion = 6.88e5\ntop_level = 1.246e5\nmotion_top = -0.064\n')
    r = run("simulate", f, "--duration", 10, "--controller", "pid", "--out", tmp_path / "o")
    assert r.returncode == 0, r.stderr
    assert np.isfinite(json.loads((tmp_path / "o" / "metrics.json").read_text())["wob_std"])


def test_the_equation_error_of_a_component_that_never_moves_is_no_runtime_warning():
    """A calm log never slides: the friction component's fit rows are empty, and numpy warned "Degrees of
    freedom <= 0" three times on the terminal (D8's calm log)."""
    import warnings

    from heavecomp.diagnosis.equation_error import _lstsq

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _lstsq(np.zeros((0, 2)), np.zeros(0)).shape == (2,)
