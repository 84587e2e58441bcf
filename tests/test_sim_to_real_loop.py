"""scenarios/sim_to_real_loop.py --quick: the loop closes, and its metrics hold the physics."""

import importlib.util
import json

import pytest

from heavecomp.report.scenario import ROOT


@pytest.mark.slow
def test_sim_to_real_loop_quick(tmp_path):
    spec = importlib.util.spec_from_file_location("sim_to_real_loop", ROOT / "scenarios" / "sim_to_real_loop.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--quick", "--out", str(tmp_path)]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())["effects"]
    # a seal friction with stiction the nominal controller does not know: knowing the true law
    # (its friction feed-forward) can only help the WOB on the truth plant
    fr = m["pressure_friction"]["loop"]
    assert fr["true"]["wob_std"] <= fr["nominal"]["wob_std"]
    # a WOB load cell reading g x the true WOB: the unaware controller holds the wrong WOB; the
    # diagnosis names the fault and the calibrated controller, reading through it, removes its error
    sg = m["sensor_gain"]
    assert sg["verdict"]["effect"] == "sensor_gain"
    err = {k: abs(x["wob_mean_error"]) for k, x in sg["loop"].items()}
    assert err["calibrated"] < 0.5 * err["nominal"]
    assert err["true"] < 0.5 * err["nominal"]
    # the runs are deterministic (same sea, same noise): a repeat is bit-identical, so a difference
    # between controllers is resolved down to the QP tolerance
    assert all(e["resolution"]["repeat_identical"] for e in m.values())
    # a seal-friction effect changes the friction the MPC forecasts, not its linear predictions
    mc = m["pressure_friction"]["model_change"]["calibrated"]
    assert mc["friction"] > 0.01 and mc["force"] == 0.0 and mc["heave"] == 0.0
    for e in m.values():
        for x in e["loop"].values():
            assert x["violations"] == 0 and x["u_max_used"] <= 1.0 + 1e-9
    assert (tmp_path / "wob_loop.png").exists() and (tmp_path / "report.html").exists()
    assert "| pressure_friction | linear-mpc | calibrated |" in (tmp_path / "report.md").read_text()
