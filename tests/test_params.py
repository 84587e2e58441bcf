"""Parameter files: the TOML contract, round trip, and every class of bad input (one line, exit 2)."""

import math

import pytest

from heavecomp.errors import ParameterError
from heavecomp.params import dumps, load, loads, paper_a

from _cli import run as run_cli

CONTRACT_EXAMPLE = """
[heave]
kind = "sine"
amplitude = 1.0
period = 12.0
ramp = 24.0

[compensator]
plunger_diameter = 0.72
moving_mass = 80000.0
gas_stiffness = 46e3
polytropic_index = 1.3

[friction]
model = "stribeck"
static_force = 23e3
coulomb_force = 12e3
stribeck_velocity = 0.01
viscous_coefficient = 10e3
pressure_coefficient = 2e-3

[drill_string]
stiffness = 2.08e6
damping = 0.0
lower_mass = 30000.0

[formation]
stiffness = 1e6
damping = 20e3

[operating_point]
wob_setpoint = 98.1e3
"""


def test_contract_example_equals_builtin_paper_a():
    p = loads(CONTRACT_EXAMPLE)
    assert p == paper_a("stribeck")
    # cmc-reference.md: k_eff ~ 43.07 kN/m
    assert p.k_eff == pytest.approx(43.07e3, rel=2e-4)
    # operating point balance p0 A = (Mc + mb) g - W0 and the gas-volume definition of k_gas
    assert p.p0 * p.area == pytest.approx((80000 + 30000) * 9.81 - 98.1e3)
    assert 1.3 * (p.p0 + 101325) * p.area ** 2 / p.gas_volume == pytest.approx(46e3)


@pytest.mark.parametrize("model", ["none", "stribeck", "rotating_eq6", "rotating_eq7"])
def test_round_trip(model, tmp_path):
    p = paper_a(model)
    f = tmp_path / "p.toml"
    f.write_text(dumps(p))
    assert load(f) == p


def _mutate(text, old, new):
    assert old in text
    return text.replace(old, new, 1)


BAD = [
    # (description, old, new, expected fragment of the message)
    ("misspelt key", "plunger_diameter", "plunger_diamter", "compensator.plunger_diamter: unknown key (did you mean 'plunger_diameter'?)"),
    ("unknown table", "[formation]", "[formations]", "[formations]: unknown table (did you mean 'formation'?)"),
    ("missing key", "moving_mass = 80000.0\n", "", "compensator.moving_mass: missing required key"),
    ("missing table", "[operating_point]\nwob_setpoint = 98.1e3", "", "[operating_point]: missing required table"),
    ("wrong type", "moving_mass = 80000.0", 'moving_mass = "80 t"', "compensator.moving_mass: expected a number in kg"),
    ("bool as number", "damping = 0.0", "damping = true", "drill_string.damping: expected a number"),
    ("nan", "gas_stiffness = 46e3", "gas_stiffness = nan", "compensator.gas_stiffness: must be finite"),
    ("inf", "stiffness = 1e6", "stiffness = inf", "formation.stiffness: must be finite"),
    ("negative mass", "lower_mass = 30000.0", "lower_mass = -30000.0", "drill_string.lower_mass = -30000 kg is outside"),
    ("zero mass", "moving_mass = 80000.0", "moving_mass = 0", "compensator.moving_mass = 0 kg is outside"),
    ("static < coulomb", "static_force = 23e3", "static_force = 10e3", "friction.static_force = 10000 N is below friction.coulomb_force"),
    ("stribeck velocity 0", "stribeck_velocity = 0.01", "stribeck_velocity = 0.0", "friction.stribeck_velocity = 0 m/s is outside"),
    ("polytropic < 1", "polytropic_index = 1.3", "polytropic_index = 0.8", "compensator.polytropic_index = 0.8 - is outside"),
    ("mm instead of m", "plunger_diameter = 0.72", "plunger_diameter = 720", "; is it in mm? (SI: m)"),
    ("N/bar instead of N/Pa", "pressure_coefficient = 2e-3", "pressure_coefficient = 200", "friction.pressure_coefficient = 200 N/Pa is outside"),
    ("unknown friction model", 'model = "stribeck"', 'model = "stribek"', "friction.model = 'stribek' is not one of none, stribeck, rotating_eq6, rotating_eq7 (did you mean 'stribeck'?)"),
    ("rotating without v_t", 'model = "stribeck"', 'model = "rotating_eq7"', "friction.tangential_velocity: missing required key for model = \"rotating_eq7\""),
    ("heave kind needs keys", 'kind = "sine"', 'kind = "jonswap"', 'heave.hs: missing required key for kind = "jonswap"'),
    ("WOB above weight", "wob_setpoint = 98.1e3", "wob_setpoint = 2e6", "operating_point.wob_setpoint = 2e+06 N must be below the suspended weight"),
    ("not TOML", "[heave]", "[heave", "not valid TOML"),
]


@pytest.mark.parametrize("desc,old,new,fragment", BAD, ids=[b[0] for b in BAD])
def test_bad_parameter_files_raise_one_line(desc, old, new, fragment):
    with pytest.raises(ParameterError) as ei:
        loads(_mutate(CONTRACT_EXAMPLE, old, new))
    msg = str(ei.value)
    assert fragment in msg
    assert "\n" not in msg


def test_table_given_as_value():
    text = "operating_point = 3\n" + CONTRACT_EXAMPLE.replace("[operating_point]\nwob_setpoint = 98.1e3", "")
    with pytest.raises(ParameterError, match="operating_point: expected a table"):
        loads(text)


def test_documented_defaults_only():
    text = CONTRACT_EXAMPLE.replace("damping = 0.0\n", "").replace("ramp = 24.0\n", "")
    p = loads(text)
    assert p.drill_string.damping == 0.0            # documented default
    assert p.heave.ramp == pytest.approx(24.0)       # documented: two periods
    # model "none" needs no friction coefficients
    p = loads(CONTRACT_EXAMPLE.split("[friction]")[0] + '[friction]\nmodel = "none"\n'
              + "[drill_string]" + CONTRACT_EXAMPLE.split("[drill_string]")[1])
    assert p.friction.model == "none"
    # heave table may be omitted (diagnosis takes heave from data)
    p = loads("[compensator]" + CONTRACT_EXAMPLE.split("[compensator]", 1)[1])
    assert p.heave is None


def test_replace_is_validated():
    p = paper_a()
    assert p.replace(drill_string={"stiffness": 208e3}).drill_string.stiffness == 208e3
    with pytest.raises(ParameterError, match="drill_string.stifness: unknown key"):
        p.replace(drill_string={"stifness": 1.0})
    with pytest.raises(ParameterError, match="friction.coulomb_force"):
        p.replace(friction={"coulomb_force": 30e3})


_cli = run_cli  # in this process (tests/_cli.py): what the command writes or refuses


@pytest.mark.parametrize("desc,old,new,fragment", [BAD[0], BAD[6], BAD[10], BAD[13]], ids=["misspelt", "nan", "static<coulomb", "unit"])
def test_cli_bad_params_exit_2_one_line(tmp_path, desc, old, new, fragment):
    f = tmp_path / "bad.toml"
    f.write_text(_mutate(CONTRACT_EXAMPLE, old, new))
    r = _cli("simulate", str(f), "--duration", "10", "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert fragment in lines[0]
    assert not (tmp_path / "o").exists()


def test_cli_missing_file_and_bad_duration(tmp_path, paper_a_toml):
    r = _cli("simulate", str(tmp_path / "nope.toml"), "--duration", "10", "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "parameter file not found" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    r = _cli("simulate", str(paper_a_toml), "--duration", "-5", "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "--duration" in r.stderr
    r = _cli("simulate", str(paper_a_toml), "--duration", "10", "--out", str(tmp_path / "o"), "--friction", "stribek")
    assert r.returncode == 2 and "did you mean 'stribeck'" in r.stderr


def test_params_command_writes_valid_builtin(tmp_path):
    out = tmp_path / "pa.toml"
    r = _cli("params", "paper_a", "--friction", "rotating_eq7", "-o", str(out))
    assert r.returncode == 0, r.stderr
    p = load(out)
    assert p.friction.model == "rotating_eq7" and p.friction.tangential_velocity == 0.05
    r = _cli("params", "paper_b_nonsense")
    assert r.returncode == 2 and "built-in sets: paper_a" in r.stderr


# ---- issue 14 / 13.3: implausible magnitudes, unit slips, run budget (in-process CLI: exit 2, one line) ----------

def _main(argv, capsys):
    from heavecomp.cli import main

    code = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    return code, err


def _bad_file(tmp_path, old, new, text=CONTRACT_EXAMPLE):
    f = tmp_path / "bad.toml"
    f.write_text(_mutate(text, old, new))
    return f


def _assert_one_line(code, err, key):
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert key in err, err


JONSWAP = CONTRACT_EXAMPLE.replace('kind = "sine"\namplitude = 1.0\nperiod = 12.0\n',
                                   'kind = "jonswap"\nhs = 2.0\ntp = 12.0\nseed = 3\n')


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "-1", "1e300", "4294967296", "1.5"])
def test_heave_seed_must_be_an_integer_in_range(tmp_path, capsys, value):
    """Issue 14.6: NaN/inf gave a traceback, -1 passed `params` and crashed simulate, 1e300 was accepted."""
    f = _bad_file(tmp_path, "seed = 3", f"seed = {value}", JONSWAP)
    _assert_one_line(*_main(["params", f], capsys), "heave.seed")


def test_heave_seed_edges_are_accepted():
    assert loads(JONSWAP.replace("seed = 3", "seed = 4294967295")).heave.seed == 2 ** 32 - 1
    assert loads(JONSWAP.replace("seed = 3", "seed = 0")).heave.seed == 0


@pytest.mark.parametrize("value", ["1e-300", "0.01", "24000.0"])
def test_heave_ramp_between_zero_and_half_a_period_is_refused(tmp_path, capsys, value):
    """Issue 14.8: heave.ramp = 1e-300 raised ZeroDivisionError in simulate; now `params` names it."""
    f = _bad_file(tmp_path, "ramp = 24.0", f"ramp = {value}")
    _assert_one_line(*_main(["params", f], capsys), "heave.ramp")


def test_heave_ramp_zero_means_no_fade_in(tmp_path):
    from heavecomp.simulate import simulate

    res = simulate(loads(CONTRACT_EXAMPLE.replace("ramp = 24.0", "ramp = 0.0")), 3.0)
    # no fade-in: the heave is the full sine from t = 0 (z = a sin(2 pi t / T))
    assert res["heave"][-1] == pytest.approx(math.sin(2 * math.pi * 3.0 / 12.0), rel=1e-6)


TINY = [  # issue 14.1: tiny positive values that collapsed the default step; `params` called them valid
    ("moving_mass = 80000.0", "moving_mass = 1e-4", "compensator.moving_mass", CONTRACT_EXAMPLE),
    ("moving_mass = 80000.0", "moving_mass = 1e-2", "compensator.moving_mass", CONTRACT_EXAMPLE),
    ("stribeck_velocity = 0.01", "stribeck_velocity = 1e-9", "friction.stribeck_velocity", CONTRACT_EXAMPLE),
    ("lower_mass = 30000.0", "lower_mass = 1e-300", "drill_string.lower_mass", CONTRACT_EXAMPLE),
    ('model = "stribeck"', 'model = "rotating_eq7"\ntangential_velocity = 1e-300', "friction.tangential_velocity",
     CONTRACT_EXAMPLE),
]


@pytest.mark.parametrize("old,new,key,text", TINY, ids=[t[1].split("\n")[-1] for t in TINY])
@pytest.mark.parametrize("command", ["params", "simulate"])
def test_tiny_values_that_collapse_the_step_are_refused_by_name(tmp_path, capsys, old, new, key, text, command):
    f = _bad_file(tmp_path, old, new, text)
    argv = ["params", f] if command == "params" else ["simulate", f, "--duration", "10", "--out", tmp_path / "o"]
    _assert_one_line(*_main(argv, capsys), key)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("old,new,key,unit", [
    ("wob_setpoint = 98.1e3", "wob_setpoint = 10", "operating_point.wob_setpoint = 10 N", "is it in kN? (SI: N)"),
    ("gas_stiffness = 46e3", "gas_stiffness = 46", "compensator.gas_stiffness = 46 N/m", "is it in kN/m? (SI: N/m)"),
    ("moving_mass = 80000.0", "moving_mass = 80", "compensator.moving_mass = 80 kg", "is it in t? (SI: kg)"),
    ("stribeck_velocity = 0.01", "stribeck_velocity = 10", "friction.stribeck_velocity", "is it in mm/s?"),
    ("pressure_coefficient = 2e-3", "pressure_coefficient = 200", "friction.pressure_coefficient", "is it in N/bar?"),
])
def test_wrong_magnitude_names_key_and_likely_unit(tmp_path, capsys, old, new, key, unit):
    """Issue 13.3: a WOB of 10 N or a gas spring of 46 N/m were accepted with exit 0."""
    code, err = _main(["params", _bad_file(tmp_path, old, new)], capsys)
    _assert_one_line(code, err, key)
    assert unit in err


@pytest.mark.parametrize("old,new,key,why", [
    # inside every key's own bounds, but not with the other keys (issue 14.10)
    ("gas_stiffness = 46e3", "gas_stiffness = 46e6", "compensator.gas_stiffness", "gas column"),
    ("coulomb_force = 12e3", "coulomb_force = 12", "friction.coulomb_force", "1/100 of friction.static_force"),
    ("viscous_coefficient = 10e3", "viscous_coefficient = 10e6", "friction.viscous_coefficient", "cylinder load"),
    ("static_force = 23e3", "static_force = 500e3", "friction.static_force", "cylinder load"),
    ("damping = 20e3", "damping = 9e6", "formation.damping", "damping ratio"),
    ("wob_setpoint = 98.1e3", "wob_setpoint = 400e3", "operating_point.wob_setpoint", "lower mass's weight"),
    ("stiffness = 2.08e6", "stiffness = 1e8", "drill_string.stiffness = 1e+08", "natural frequency"),
])
def test_cross_key_checks_name_the_key(old, new, key, why):
    text = _mutate(CONTRACT_EXAMPLE, old, new)
    if "natural frequency" in why:  # a stiff string alone is plausible; with a 1 t top mass the mode is 51 Hz
        text = _mutate(text, "moving_mass = 80000.0", "moving_mass = 1000.0")
    with pytest.raises(ParameterError) as ei:
        loads(text)
    msg = str(ei.value)
    assert key in msg and why in msg and "\n" not in msg
    assert msg.startswith(key.split(" = ")[0] if "natural" not in why else "compensator.moving_mass")


def test_active_table_cross_checks():
    with pytest.raises(ParameterError, match=r"^active.rate_max = 3e\+08 N/s takes"):
        paper_a().replace(active={"rate_max": 3e8})
    with pytest.raises(ParameterError, match=r"^active.u_max = 5e\+06 N is above the suspended weight"):
        paper_a().replace(active={"u_max": 5e6, "rate_max": 5e8})


def _unit_slips():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / "unit_slips.py"
    spec = importlib.util.spec_from_file_location("unit_slips", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_unit_slips_are_caught_by_name_except_the_plausible_ones():
    """Issue 14.10: every x1000 and /1000 slip of every numeric key of the shipped sets is refused naming the
    slipped key, except the ones scripts/unit_slips.py lists as physically plausible (small but valid values)."""
    us = _unit_slips()
    rows = list(us.slips())
    assert len(rows) > 150
    passed = {(key, f) for _, key, f, _, msg in rows if msg is None}
    assert passed == set(us.PLAUSIBLE)
    for label, key, factor, value, msg in rows:
        if msg is not None:
            assert key in msg and "\n" not in msg, (label, key, factor, msg)


# ---- run-size budget (issue 14.1): refused up front, by name -------------------------------------------------

def _extreme_but_plausible():
    """Every key and cross-key check passes, but a 1 t top mass with a 0.1 mm/s Stribeck velocity and
    5 MN of static friction makes the friction slope F_S / v_S / M_c ~ 5e7 1/s."""
    return paper_a().replace(
        compensator={"moving_mass": 1e3, "gas_stiffness": 1e5, "plunger_diameter": 3.0},
        drill_string={"lower_mass": 2e6, "stiffness": 1e4}, formation={"stiffness": 5e3},
        friction={"static_force": 5e6, "coulomb_force": 5e4, "stribeck_velocity": 1e-4})


def test_params_refuses_a_set_whose_default_step_collapses(tmp_path, capsys):
    p = _extreme_but_plausible()
    f = tmp_path / "x.toml"
    f.write_text(dumps(p))
    code, err = _main(["params", f], capsys)
    _assert_one_line(code, err, "default time step")
    assert "friction.stribeck_velocity" in err and "compensator.moving_mass" in err


def test_simulate_refuses_a_run_that_cannot_fit_before_allocating(tmp_path, capsys, paper_a_toml):
    f = tmp_path / "x.toml"
    f.write_text(dumps(_extreme_but_plausible()))
    code, err = _main(["simulate", f, "--duration", "10", "--out", tmp_path / "o"], capsys)
    _assert_one_line(code, err, "friction.stribeck_velocity")
    assert "RK4 steps" in err
    code, err = _main(["simulate", paper_a_toml, "--duration", "3600", "--dt", "1e-6", "--out", tmp_path / "o"], capsys)
    _assert_one_line(code, err, "--dt = 1e-06 s")
    code, err = _main(["simulate", paper_a_toml, "--duration", "100", "--rate", "1e9", "--out", tmp_path / "o"], capsys)
    _assert_one_line(code, err, "--rate = 1e+09 Hz")
    assert not (tmp_path / "o").exists()


def test_output_budget_names_rate_and_duration():
    from heavecomp.params.budget import MAX_BYTES
    from heavecomp.simulate import simulate
    from heavecomp.simulate.layout import NCH

    rows = MAX_BYTES // (8 * NCH) + 1  # one row more than fits, at the default 25 ms step and 40 Hz output
    with pytest.raises(ParameterError, match=r"rate = 40 Hz writes .* rows x \d+ columns"):
        simulate(paper_a(), rows / 40.0, rate=40.0)


def test_closed_loop_checks_the_budget_too():
    from heavecomp.closed_loop.loop import simulate_closed_loop

    with pytest.raises(ParameterError, match="dt = 1e-07 s"):
        simulate_closed_loop(paper_a(), "pid", 600.0, dt=1e-7)


# ---- controller options (issue 14.7): bounds on the ControllerConfig fields, one line naming the option ----------

@pytest.mark.parametrize("option, fragment", [
    ("horizon=0", "controller option horizon = 0"),
    ("horizon=-3", "controller option horizon = -3"),
    ("q_wob=-1", "controller option q_wob = -1"),
    ("friction_eps=0", "controller option friction_eps = 0 m/s"),
    ("predictor_order=0", "controller option predictor_order = 0"),
    ("sqp_iterations=0", "controller option sqp_iterations = 0"),
    ("observer_sigma_d=0", "controller option observer_sigma_d = 0 N"),
    ("kp=-1", "controller option kp = -1"),
    ("u_max=-5", "controller option u_max = -5.0: set [active].u_max in the parameter file"),
    ("control_rate=0", "controller option control_rate = 0.0: set [active].control_rate"),
    ("control_rate=10", "controller option control_rate = 10.0: set [active].control_rate"),
])
def test_bad_controller_options_exit_2_before_the_run(tmp_path, capsys, paper_a_toml, option, fragment):
    """horizon=0/-3, q_wob=-1, u_max=-5, control_rate=0 gave tracebacks; friction_eps=0 and predictor_order=0
    fell back on every step with exit 0; sqp_iterations=0 silently left the force at zero."""
    code, err = _main(["simulate", paper_a_toml, "--duration", "5", "--out", tmp_path / "o",
                       "--controller", "nonlinear-mpc", "--controller-option", option], capsys)
    _assert_one_line(code, err, fragment)
    assert not (tmp_path / "o").exists()


def test_controller_config_validates_library_use_too():
    import dataclasses

    from heavecomp.controllers.base import ControllerConfig

    c = ControllerConfig(horizon=30.0)
    assert c.horizon == 30 and isinstance(c.horizon, int)
    with pytest.raises(ParameterError, match="controller option horizon: expected a whole number"):
        ControllerConfig(horizon=2.5)
    with pytest.raises(ParameterError, match="controller option sqp_iterations = 0"):
        dataclasses.replace(c, sqp_iterations=0)
    with pytest.raises(ParameterError, match="controller option predictor_window: must be finite"):
        ControllerConfig(predictor_window=math.nan)
    assert ControllerConfig.from_params(paper_a().replace(active={"control_rate": 10.0})).control_rate == 10.0


# ---- reading: encodings and TOML syntax name the problem (issue 14.11) ------------------------------------------

@pytest.mark.parametrize("encode, fragment", [
    (lambda t: t.encode("utf-16"), "is UTF-16 encoded; save it as UTF-8"),
    (lambda t: ("# Größe\n" + t).encode("latin-1"), "is not UTF-8 (byte 0xf6 at line 1, column 5"),
    (lambda t: t.replace("0.72", "0,72").encode(), "not valid TOML at compensator.plunger_diameter"),
])
def test_encodings_and_decimal_comma_get_the_right_explanation(tmp_path, capsys, encode, fragment):
    f = tmp_path / "p.toml"
    f.write_bytes(encode(CONTRACT_EXAMPLE))
    code, err = _main(["params", f], capsys)
    _assert_one_line(code, err, fragment)
    if "TOML" in fragment:
        assert "a decimal comma? TOML numbers use a point" in err


def test_utf8_bom_is_accepted(tmp_path):
    f = tmp_path / "p.toml"
    f.write_bytes(b"\xef\xbb\xbf" + CONTRACT_EXAMPLE.encode())
    assert load(f) == paper_a()


def test_docs_list_every_bound_as_in_the_code():
    from pathlib import Path

    from heavecomp.controllers.base import ControllerConfig
    from heavecomp.params.cmc import TABLES, Active
    from heavecomp.params.core import bounds_rows

    doc = (Path(__file__).resolve().parents[1] / "docs" / "parameters.md").read_text()
    rows = [r for t, c in list(TABLES.items()) + [("active", Active)] for r in bounds_rows(c, t)]
    rows += bounds_rows(ControllerConfig, "")
    assert len(rows) > 40
    for row in rows:
        assert row in doc, row


@pytest.mark.parametrize("target, fragment", [
    ("missing/dir/x.toml", "does not exist"),
    (".", "is a folder"),
])
def test_params_output_path_checked_before_the_work(tmp_path, capsys, target, fragment):
    """Issue 13.3: `heavecomp params paper_a -o /nonexistent/dir/x.toml` gave a traceback."""
    code, err = _main(["params", "paper_a", "-o", tmp_path / target], capsys)
    _assert_one_line(code, err, fragment)


@pytest.mark.parametrize("digits", [400, 5000])
def test_integer_literals_beyond_any_float_are_one_line(digits):
    """Found by tests/test_fuzz_params.py: OverflowError (400 digits) and ValueError (> 4300 digits) tracebacks."""
    with pytest.raises(ParameterError) as ei:
        loads(CONTRACT_EXAMPLE.replace("moving_mass = 80000.0", "moving_mass = 1" + "0" * digits))
    assert "compensator.moving_mass" in str(ei.value) and "\n" not in str(ei.value)


def test_tangential_velocity_zero_means_no_rotation_and_a_tiny_one_is_refused():
    assert paper_a("rotating_eq7").replace(friction={"tangential_velocity": 0.0}).friction.tangential_velocity == 0.0
    with pytest.raises(ParameterError, match=r"^friction.tangential_velocity = 0.0005 m/s: use 0 .* is it in mm/s"):
        paper_a("rotating_eq7").replace(friction={"tangential_velocity": 5e-4})


# ---- issue 21 item 5: no traceback on any TOML, heave.path named, a sea beyond the stroke ----------------------

REPRO = __import__("pathlib").Path(__file__).parent / "data" / "corrupt_2026_11"


@pytest.mark.parametrize("name,key", [
    ("P5_deep_inline_table_500", "nested too deep"),
    ("P6_heave_path_empty", "heave.path"),
    ("P6b_heave_path_devnull", "heave.path"),
    ("P7_hs_16m_hexint", "heave.hs"),
    ("P8_amplitude_mm_as_m", "heave.amplitude"),
    ("P8b_amplitude_5e-324", "heave.amplitude"),
])
def test_reproducers_of_issue_21_are_one_line(capsys, name, key):
    _assert_one_line(*_main(["params", REPRO / f"{name}.toml"], capsys), key)


@pytest.mark.parametrize("nest", ["{a = ", "["])
def test_any_nesting_depth_is_one_line_or_valid(tmp_path, capsys, nest):
    close = "}" if nest.startswith("{") else "]"
    for depth in (10, 2000, 20000):
        f = tmp_path / "deep.toml"
        f.write_text(f"deep = {nest * depth}1{close * depth}\n" + CONTRACT_EXAMPLE)
        code, err = _main(["params", f], capsys)
        assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err


@pytest.mark.parametrize("path,fragment", [("", "empty"), ("/dev/null", "not a regular file"), (".", "a folder"),
                                           ("missing.csv", "file not found"), ("empty.csv", "empty file")])
def test_heave_path_is_checked_when_the_file_is_read(tmp_path, capsys, path, fragment):
    (tmp_path / "empty.csv").write_text("")
    f = _bad_file(tmp_path, 'kind = "sine"\namplitude = 1.0\nperiod = 12.0\n', f'kind = "file"\npath = "{path}"\n',
                  CONTRACT_EXAMPLE.replace("ramp = 24.0\n", ""))
    code, err = _main(["params", f], capsys)
    _assert_one_line(code, err, "heave.path")
    assert fragment in err


def test_heave_file_that_exists_passes(tmp_path):
    (tmp_path / "h.csv").write_text("t,heave\n0,0\n1,0.1\n2,0\n")
    f = _bad_file(tmp_path, 'kind = "sine"\namplitude = 1.0\nperiod = 12.0\n', 'kind = "file"\npath = "h.csv"\n',
                  CONTRACT_EXAMPLE.replace("ramp = 24.0\n", ""))
    assert load(f).heave.path == "h.csv"


@pytest.mark.parametrize("sea,key,ok", [
    ('kind = "sine"\namplitude = 3.8\nperiod = 12.0\n', "heave.amplitude", True),    # 7.6 m crest to trough
    ('kind = "sine"\namplitude = 3.9\nperiod = 12.0\n', "heave.amplitude", False),   # 7.8 m: past a 25 ft stroke
    ('kind = "jonswap"\nhs = 4.0\ntp = 12.0\n', "heave.hs", True),                   # largest wave 7.44 m
    ('kind = "jonswap"\nhs = 4.2\ntp = 12.0\n', "heave.hs", False),                  # largest wave 7.81 m
    ('kind = "sine"\namplitude = 0.0\nperiod = 12.0\n', "heave.amplitude", True),    # no heave: valid
    ('kind = "sine"\namplitude = 0.009\nperiod = 12.0\n', "heave.amplitude", False),  # under 1 cm
])
def test_the_heave_stays_within_the_longest_stroke(tmp_path, capsys, sea, key, ok):
    f = _bad_file(tmp_path, 'kind = "sine"\namplitude = 1.0\nperiod = 12.0\n', sea)
    code, err = _main(["params", f], capsys)
    if ok:
        assert code == 0, err
    else:
        _assert_one_line(code, err, key)
