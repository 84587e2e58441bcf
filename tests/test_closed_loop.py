"""Closed loop (issue 5): limits respected, MPC beats PID with a perfect model, failures handled."""

import json
import subprocess
import sys

import numpy as np
import pytest

from heavecomp.params import dumps, paper_a
from heavecomp.simulate.closed_loop import simulate_closed_loop


def _u_rate(res):
    u = res["u_active"]
    return np.abs(np.diff(u)) / np.diff(res.t)


def test_passive_closed_loop_reproduces_the_open_loop_simulator():
    """Stepping the kernel one RK4 step at a time (u = 0) is the open-loop run."""
    from heavecomp.simulate import simulate

    p = paper_a("stribeck")
    cl = simulate_closed_loop(p, "passive", 40.0)
    ol = simulate(p, 40.0, rate=20.0)
    assert cl.dt == pytest.approx(ol.dt)
    np.testing.assert_allclose(cl["wob"], ol["wob"], rtol=0, atol=1e-6 * 98.1e3)
    assert cl.metrics()["u_active_max"] == 0.0


def test_linear_mpc_respects_tight_limits_and_reports_saturation():
    p = paper_a("stribeck").replace(active={"u_max": 25e3, "rate_max": 100e3})
    res = simulate_closed_loop(p, "linear-mpc", 60.0)
    m = res.metrics()
    u = res["u_active"]
    assert np.max(np.abs(u)) <= 25e3 * (1 + 1e-9)
    assert np.max(_u_rate(res)) <= 100e3 * (1 + 1e-6)
    assert m["violations_u_max"] == 0 and m["violations_rate"] == 0
    assert m["saturated_steps"] > 0 and m["u_active_max"] == pytest.approx(25e3)
    # even a small actuator removes part of the friction/gas-spring WOB variation
    passive = simulate_closed_loop(p, "passive", 60.0).metrics()["wob_std"]
    assert m["wob_std"] < 0.8 * passive


def test_with_a_perfect_model_mpc_beats_pid_and_reaches_the_goal():
    """Perfect heave preview, no sensor noise, full static friction (eq. 4)."""
    p = paper_a("stribeck")
    kw = dict(noise=None, preview="perfect")
    passive = simulate_closed_loop(p, "passive", 72.0, **kw).metrics()
    pid = simulate_closed_loop(p, "pid", 72.0, **kw).metrics()
    mpc = simulate_closed_loop(p, "linear-mpc", 72.0, **kw).metrics()
    assert pid["wob_std"] < passive["wob_std"]
    assert mpc["wob_std"] < 0.5 * pid["wob_std"]
    assert mpc["wob_std"] <= 0.2 * passive["wob_std"]  # the goal
    assert mpc["violations_u_max"] == 0 and mpc["violations_rate"] == 0


def test_osqp_failure_falls_back_and_is_counted():
    from heavecomp.controllers import make

    p = paper_a("stribeck")
    ctrl = make("linear-mpc", p)
    ctrl.solver.update_settings(max_iter=1)  # osqp returns "maximum iterations reached"
    res = simulate_closed_loop(p, ctrl, 20.0)
    m = res.metrics()
    assert m["solver_failures"] > 0 and m["fallbacks"] == m["solver_failures"]
    assert np.all(np.isfinite(res["wob"])) and m["violations_u_max"] == 0 and m["violations_rate"] == 0


def test_a_crashing_controller_never_stops_the_run():
    from heavecomp.controllers import make

    p = paper_a("stribeck")
    ctrl = make("pid", p)

    def broken(t, meas, preview):
        if t > 5.0:
            raise RuntimeError("solver exploded")
        return 1e3

    ctrl._step = broken
    res = simulate_closed_loop(p, ctrl, 10.0)
    m = res.metrics(start=0.0)
    assert m["fallbacks"] == 99  # t = 5.05 .. 9.95 s at 20 Hz
    assert np.all(res["u_active"][res.t > 5.1] == 1e3)  # held the last good command


def test_nonlinear_mpc_runs_within_limits_and_falls_back_on_nlp_failure():
    from heavecomp.controllers import make

    p = paper_a("stribeck")
    ctrl = make("nonlinear-mpc", p, horizon=10)
    res = simulate_closed_loop(p, ctrl, 40.0, noise=None, preview="perfect")
    m = res.metrics()
    passive = simulate_closed_loop(p, "passive", 40.0).metrics()
    assert m["wob_std"] < 0.3 * passive["wob_std"]
    assert m["violations_u_max"] == 0 and m["violations_rate"] == 0 and m["solver_failures"] == 0

    real = ctrl.solver

    def failing(**kw):
        raise RuntimeError("Error in Function::call for 'nmpc'")

    ctrl.solver = failing
    res = simulate_closed_loop(p, ctrl, 5.0)
    assert res.metrics(start=0.0)["solver_failures"] == 100
    ctrl.solver = real


def test_cli_simulate_with_controller_writes_u_active_and_metrics(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text(dumps(paper_a()))
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "simulate", str(f), "--duration", "30",
                        "--out", str(tmp_path / "o"), "--controller", "linear-mpc"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    header = (tmp_path / "o" / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert header[:5] == ["t", "heave", "stroke", "pressure", "wob"] and "u_active" in header
    m = json.loads((tmp_path / "o" / "metrics.json").read_text())
    for key in ("wob_std", "wob_p2p", "u_active_max", "solve_time_ms_p50", "solve_time_ms_p99",
                "violations_u_max", "violations_rate", "solver_failures", "fallbacks"):
        assert key in m
    assert m["u_active_max"] <= 60e3


def test_cli_bad_active_table_exits_2_with_one_line(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text(dumps(paper_a()) + "\n[active]\nu_max = -1.0\n")
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "simulate", str(f), "--duration", "10",
                        "--out", str(tmp_path / "o"), "--controller", "pid"], capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.strip() == ("heavecomp simulate: error: active.u_max = -1 N is outside the possible "
                                "range [1000, 1e+07] N")


def test_cli_closed_loop_rate_must_divide_the_control_rate(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text(dumps(paper_a()))
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "simulate", str(f), "--duration", "10",
                        "--out", str(tmp_path / "o"), "--controller", "pid", "--rate", "7"],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.strip() == ("heavecomp simulate: error: --rate 7 Hz: a closed-loop run writes at the control "
                                "rate [active].control_rate = 20 Hz or an integer fraction of it")
    assert not (tmp_path / "o").exists()  # checked before simulating


def test_pid_is_stable_without_friction():
    """No friction = least damping of the top-mass mode: the default PID must not slowly diverge."""
    p = paper_a("none")
    res = simulate_closed_loop(p, "pid", 300.0)
    w, t = res["wob"], res.t
    early = np.std(w[(t >= 100) & (t < 200)])
    late = np.std(w[t >= 200])
    assert late < 1.1 * early
    assert res.metrics()["wob_std"] < simulate_closed_loop(p, "passive", 300.0).metrics()["wob_std"]


def test_measured_heave_record_covering_just_the_run_is_enough():
    """A heave record as long as the run works (the predictor needs no future data);
    the perfect-preview study option needs the horizon beyond the end and says so."""
    from heavecomp.errors import ParameterError

    t = np.arange(0.0, 30.0 + 1e-9, 0.1)
    z = 0.5 * np.sin(2 * np.pi * t / 10.0) * np.minimum(t / 10.0, 1.0)
    p = paper_a("stribeck")
    res = simulate_closed_loop(p, "linear-mpc", 30.0, heave=(t, z))
    assert res.t[-1] == pytest.approx(30.0)
    np.testing.assert_allclose(res["heave"], np.interp(res.t, t, z), atol=2e-3)
    with pytest.raises(ParameterError, match="exceeds the heave record's span 30 s"):
        simulate_closed_loop(p, "linear-mpc", 30.0, heave=(t, z), preview="perfect")


@pytest.mark.parametrize("opt, msg", [
    ("horizn=30", "controller option 'horizn': unknown (did you mean 'horizon'?)"),
    ("horizon=ten", "controller option horizon = 'ten': not a finite int"),
    ("q_wob=nan", "controller option q_wob = 'nan': not a finite float"),
    ("horizon", "--controller-option 'horizon': expected KEY=VALUE"),
    ("model_frame=ship", "controller option model_frame = 'ship': not one of earth, stroke"),
])
def test_cli_bad_controller_option_exits_2_with_one_line(tmp_path, opt, msg):
    f = tmp_path / "p.toml"
    f.write_text(dumps(paper_a()))
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "simulate", str(f), "--duration", "10",
                        "--out", str(tmp_path / "o"), "--controller", "linear-mpc", "--controller-option", opt],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.strip() == f"heavecomp simulate: error: {msg}"


def test_cli_controller_options_reach_the_controller(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text(dumps(paper_a()))
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "simulate", str(f), "--duration", "10",
                        "--out", str(tmp_path / "o"), "--controller", "linear-mpc", "--controller-option",
                        "horizon=12", "--controller-option", "friction_feedforward=false"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    m = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert m["config"]["horizon"] == 12 and m["config"]["friction_feedforward"] is False
