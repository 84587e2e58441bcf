"""The calibrated model's start state (issue 22): a drift that began before the log.

A log starts mid-operation.  A gas leak that began before it has already moved the charge when the
log starts, while the fitted ``gas_leak`` counts its change from the log's first sample: without the
start state the calibrated model replays a charge that is off by a constant from the first sample
on, which a re-diagnosis reads as a pressure offset.  The truth is the benchmark generator's laminar
leak (mass fraction mu, p_abs ~ mu^n), never the candidate's linear drift.
"""

from __future__ import annotations

import numpy as np
import pytest

from heavecomp.diagnosis.calibrate import _replay, calibrate, start_state
from heavecomp.diagnosis.data import load_run
from heavecomp.diagnosis.replay import output_noise

pytestmark = pytest.mark.slow

START = 90.0  # s of leak before the log starts
DURATION = 300.0


@pytest.fixture(scope="module")
def leak(tmp_path_factory):
    from heavecomp.benchmark import Case, generate

    tr = generate(Case("gas_leak", 7, "named", sea="buoy", duration=DURATION, rate=10.0, start=START))
    run = load_run(tr.to_csv(tmp_path_factory.mktemp("leak") / "run.csv"), tr.nominal)
    return tr, run


def _rms(params, run, lo):
    p = _replay(params, run)["pressure"]
    m = (run.t >= lo) & np.isfinite(run["pressure"])
    return float(np.sqrt(np.mean((p[m] - run["pressure"][m]) ** 2)))


def test_a_leak_that_began_before_the_log_is_carried_as_the_charge_at_its_start(leak):
    tr, run = leak
    n = tr.nominal.compensator.polytropic_index
    L = tr.truth["parameters"]["gas_leak"]["leak_rate"]  # the laminar leak rate 1/T_l [1/s]
    diag = {"verdict": {"effect": "gas_leak", "confidence": "high", "shrink": 0.5, "shrink_channel": "pressure",
                        # the drift the candidate would fit: the charge's relative rate, -n L (p ~ p_0)
                        "parameters": {"leak_rate": -n * L}},
            "split": {"fit": [0.0, 200.0], "validate": [200.0, DURATION], "settle": 30.0},
            "noise_floor": output_noise(run)}
    cal = calibrate(tr.nominal, diag)
    got = start_state(cal, run, diag)
    (entry,) = [v for name, v in got.params.effects if name == "charge_drift"]
    # the charge lost over the START s before the log: (1 - L START)^n - 1 ~ -n L START
    assert entry["charge_error"] == pytest.approx(-n * L * START, rel=0.3)
    assert got.verdict_shrink == 0.5 and got.block()["verdict_shrink"] == 0.5
    # the held-out pressure gap: the start state removes the constant offset the drift alone leaves
    assert _rms(got.params, run, 200.0) < 0.5 * _rms(cal.params, run, 200.0)


def test_a_model_without_a_drift_is_left_as_it_is(leak):
    tr, run = leak
    cal = calibrate(tr.nominal, {"verdict": {"effect": "string_damping", "parameters": {"damping": 4e4},
                                             "shrink": 0.6}})
    assert start_state(cal, run, {"split": {}}) is cal
