"""The stepper's failure message names the likely cause (issue 14.11): a spike in a heave
record (an acceleration no rig floor can have) is reported as such, with its time, and
only a run whose input is plausible is told to reduce --dt."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from heavecomp.cli import main
from heavecomp.params import paper_a, save
from heavecomp.simulate import simulate
from heavecomp.simulate.core import SimulationError


def _heave_file(path, spike):
    """600 s of a 1 m, 12 s sine sampled every 0.5 s, plus ``spike`` [m] in the sample at t = 200 s."""
    t = np.arange(0.0, 600.001, 0.5)
    z = np.sin(2 * np.pi * t / 12.0)
    z[400] += spike
    np.savetxt(path, np.column_stack([t, z]), delimiter=",", header="t,heave", comments="", fmt="%.6f")
    return path


def _params(tmp_path, spike):
    return paper_a("stribeck").replace(heave={"kind": "file", "path": str(_heave_file(tmp_path / "heave.csv", spike)),
                                              "amplitude": None, "period": None, "ramp": None})


def test_a_heave_spike_that_blows_up_the_run_is_named_not_the_step(tmp_path, capsys):
    """A 40 m one-sample spike (703 m/s^2 through the spline) makes the run diverge: the message
    names the heave input and the time of the spike, and does not suggest --dt."""
    p = _params(tmp_path, 40.0)
    with pytest.raises(SimulationError) as exc:
        simulate(p, 400.0)
    msg = str(exc.value)
    assert "heave input" in msg and "at t = 200 s" in msg and "m/s^2" in msg
    assert "--dt" not in msg
    # the command: one line, exit code 2
    params_file = tmp_path / "p.toml"
    save(p, params_file)
    assert main(["simulate", str(params_file), "--duration", "400", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "heave input" in err and "--dt" not in err


def test_a_smaller_spike_runs_with_a_warning_naming_its_time(tmp_path, caplog):
    """A 5 m spike (88 m/s^2) does not diverge: the run completes and the implausible heave
    acceleration is logged with its time."""
    with caplog.at_level(logging.WARNING, logger="heavecomp.simulate.core"):
        res = simulate(_params(tmp_path, 5.0), 300.0)
    assert np.isfinite(res.data).all()
    assert "accelerates at 87.6 m/s^2 at t = 200 s" in caplog.text


def test_a_step_too_large_for_a_plausible_heave_still_suggests_reducing_dt():
    """The paper-A case at dt = 0.5 s (h lambda ~ 6, beyond RK4's stability) diverges with a
    plain sine heave: then the step is the problem and the message says so."""
    with pytest.raises(SimulationError, match=r"reduce --dt \(now 0.5 s\)"):
        simulate(paper_a("stribeck"), 120.0, dt=0.5)
