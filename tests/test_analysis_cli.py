"""`heavecomp analyse` (issue 3): contract keys, values, bad input -> one line, exit 2."""

import csv
import json

import numpy as np
import pytest

from heavecomp.cli import main
from heavecomp.params import dumps, paper_a


@pytest.fixture
def params_file(tmp_path):
    f = tmp_path / "pa.toml"
    f.write_text(dumps(paper_a("stribeck")))
    return f


def test_analyse_writes_contract_outputs(params_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["analyse", str(params_file), "--out", str(out), "--points", "200"]) == 0
    s = json.loads((out / "analysis.json").read_text())
    p = paper_a("stribeck")
    assert s["k_eff_dc"] == pytest.approx(p.k_eff, rel=1e-9)
    wn = s["natural_frequencies"]
    assert wn == sorted(wn) and len(wn) == 2 and len(s["damping_ratios"]) == 2
    kg, kd, kF = p.compensator.gas_stiffness, p.drill_string.stiffness, p.formation.stiffness
    K = np.array([[kg + kd, -kd], [-kd, kd + kF]])
    Minv = np.diag([1 / p.compensator.moving_mass, 1 / p.drill_string.lower_mass])
    np.testing.assert_allclose(wn, np.sqrt(np.sort(np.linalg.eigvals(Minv @ K).real)), rtol=1e-10)
    assert all(0 < z < 1 for z in s["damping_ratios"])
    with open(out / "frequency_response.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 200 and float(rows[0]["k_eff_mag"]) == pytest.approx(p.k_eff, rel=1e-5)
    assert (out / "bode.png").stat().st_size > 1000
    assert "k_eff_dc" in (out / "report.md").read_text()
    assert "natural frequencies" in capsys.readouterr().out


@pytest.mark.parametrize("argv,msg", [
    (["--points", "1"], "--points must be between 2 and 1000000, got 1"),
    (["--omega-min", "-1"], "--omega-min must be a positive number of rad/s, got -1.0"),
    (["--sliding-velocity", "0"], "--sliding-velocity must be a non-zero number of m/s, got 0.0"),
])
def test_bad_arguments_exit_2_with_one_line(params_file, tmp_path, capsys, argv, msg):
    assert main(["analyse", str(params_file), "--out", str(tmp_path / "o")] + argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"heavecomp analyse: error: {msg}"


def test_bad_parameter_file_names_the_key(tmp_path, capsys):
    f = tmp_path / "bad.toml"
    f.write_text(dumps(paper_a("none")).replace("stiffness = 1000000.0", "stifness = 1000000.0"))
    assert main(["analyse", str(f), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("heavecomp analyse: error: ") and "stifness" in err and "\n" not in err
