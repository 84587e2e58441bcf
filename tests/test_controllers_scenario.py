"""scenarios/controller_design.py --quick: the physics its metrics must show."""

import importlib.util
import json

import pytest

from heavecomp.report.scenario import ROOT


@pytest.mark.slow
def test_controller_design_quick(tmp_path):
    spec = importlib.util.spec_from_file_location("controller_design", ROOT / "scenarios" / "controller_design.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--quick", "--out", str(tmp_path)]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    row = m["table"]["sine"]["stribeck"]
    passive = row["passive"]["wob_std"]
    # full static friction, paper A sine: passive ~50 kN (paper A load case)
    assert 40e3 < passive < 60e3
    # ordering: passive > PID > MPC, and MPC within the 20 % goal
    assert row["pid"]["wob_std"] < passive
    for c in ("linear-mpc", "nonlinear-mpc"):
        assert row[c]["wob_std"] < 0.5 * row["pid"]["wob_std"]
        assert row[c]["wob_std"] <= 0.2 * passive
        assert row[c]["violations_u_max"] == 0 and row[c]["violations_rate"] == 0
        assert row[c]["u_active_max"] <= 60e3 * (1 + 1e-9)
    assert {p.name for p in tmp_path.glob("*.png")} >= {"wob_controllers.png", "wob_std_sine.png", "sweeps.png"}
    assert "| stribeck | linear-mpc |" in (tmp_path / "report.md").read_text()
