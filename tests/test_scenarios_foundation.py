"""The foundation scenarios run in --quick mode and their metrics say what the physics says."""

import json
import runpy
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run_scenario(name, out):
    mod = runpy.run_path(str(ROOT / "scenarios" / f"{name}.py"), run_name="scenario")
    assert mod["main"](["--quick", "--out", str(out)]) == 0
    assert (out / "report.md").is_file()
    return json.loads((out / "metrics.json").read_text())


def test_paper_a_wob(tmp_path):
    m = run_scenario("paper_a_wob", tmp_path)
    r = m["regimes"]
    # friction makes the WOB worse in the order of paper A: none < eq. 7 < eq. 4
    assert r["none"]["wob_p2p"] < r["rotating_eq7"]["wob_p2p"] < r["stribeck"]["wob_p2p"]
    # frictionless p2p close to eq. 13-14's static estimate (eigenfrequency above the wave frequency)
    assert r["none"]["wob_p2p"] == pytest.approx(m["static_estimate_p2p"], rel=0.08)
    # paper A's conclusion: eq. 7 improves distinctly but modestly vs removing friction
    assert m["verdict_p2p"]["holds"]
    # stick phases exist with full static friction, none without friction
    assert r["stribeck"]["stick_fraction"] > 0.05 and r["none"]["stick_fraction"] == 0.0
    assert list((tmp_path).glob("*.png"))


def test_irregular_sea(tmp_path):
    m = run_scenario("irregular_sea", tmp_path)
    hs = m["jonswap"]["heave_hs_tp"]
    assert hs["hs"] == pytest.approx(2.0, rel=0.1) and hs["tp"] == pytest.approx(12.0, rel=0.1)
    for sea in ("jonswap", "buoy"):
        assert m[sea]["none"]["wob_std"] < m[sea]["stribeck"]["wob_std"]


def test_sensitivity(tmp_path):
    m = run_scenario("sensitivity", tmp_path)
    nominal = next(iter(m))
    soft = "k_ds = 208 kN/m (as printed)"
    assert m[soft]["k_eff"] < m[nominal]["k_eff"]
    assert m[soft]["none"]["wob_p2p"] < m[nominal]["none"]["wob_p2p"]


def test_friction_laws(tmp_path):
    m = run_scenario("friction_laws", tmp_path)
    lim = m["static_limit_N"]
    assert lim["rotating_eq7"] < lim["rotating_eq6"] < lim["stribeck"]
    assert lim["stribeck"] == pytest.approx(23e3 + 2e-3 * m["p0_Pa"])


def test_out_help_names_the_report_folder(capsys):
    """--help names the folder a scenario writes (reports/<name>), not the script path."""
    from heavecomp.report.scenario import parse_args
    with pytest.raises(SystemExit):
        parse_args(["--help"], "paper_a_wob")
    text = " ".join(capsys.readouterr().out.split())
    assert "(default reports/paper_a_wob)" in text
