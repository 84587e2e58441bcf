"""A heave spike is named as such, never as a step-size problem (issue 14.11): the heave reader
refuses a one-sample spike by row before the run; one under its limit that still accelerates
beyond what a rig floor can is logged by the stepper with its time; only a run whose input is
plausible is told to reduce --dt."""

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


def test_a_heave_spike_that_would_blow_up_the_run_is_named_not_the_step(tmp_path, capsys):
    """A 40 m one-sample spike (703 m/s^2 through the spline) would make the run diverge: the heave
    reader refuses it first, naming the column and row, and nothing suggests --dt."""
    from heavecomp.errors import DataError

    p = _params(tmp_path, 40.0)
    with pytest.raises(DataError) as exc:
        simulate(p, 400.0)
    msg = str(exc.value)
    assert "column 'heave', row 402" in msg and "spike" in msg
    assert "--dt" not in msg
    # the command: one line, exit code 2
    params_file = tmp_path / "p.toml"
    save(p, params_file)
    assert main(["simulate", str(params_file), "--duration", "400", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "spike" in err and "--dt" not in err


def test_a_smaller_spike_runs_with_a_warning_naming_its_time(tmp_path, caplog):
    """A 2 m spike (35 m/s^2; under the reader's spike limit for this record) does not diverge:
    the run completes and the implausible heave acceleration is logged with its time."""
    with caplog.at_level(logging.WARNING, logger="heavecomp.simulate.core"):
        res = simulate(_params(tmp_path, 2.0), 300.0)
    assert np.isfinite(res.data).all()
    assert "accelerates at 34.9 m/s^2 at t = 200 s" in caplog.text


def test_a_step_too_large_for_a_plausible_heave_still_suggests_reducing_dt():
    """The paper-A case at dt = 0.5 s (h lambda ~ 6, beyond RK4's stability) diverges with a
    plain sine heave: then the step is the problem and the message says so."""
    with pytest.raises(SimulationError, match=r"reduce the step dt \(now 0.5 s\)"):
        simulate(paper_a("stribeck"), 120.0, dt=0.5)
