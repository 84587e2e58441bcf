"""Parameter files: the TOML contract, round trip, and every class of bad input (one line, exit 2)."""

import math
import subprocess
import sys

import pytest

from heavecomp.errors import ParameterError
from heavecomp.params import dumps, load, loads, paper_a

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


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "heavecomp.cli", *args], capture_output=True, text=True, cwd=cwd)


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
