"""`heavecomp analyse` with every registered plant effect in the parameter file (issue 22), and the
physics of an effect state that integrates: a leaking gas charge."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from heavecomp.analysis.frequency import dc_gain, drift_states, frozen
from heavecomp.analysis.linear import linearise_details
from heavecomp.analysis.summary import analyse
from heavecomp.benchmark.truth.gas_leak import TruthLaminarLeak
from heavecomp.cli import main
from heavecomp.effects.registry import library
from heavecomp.params import dumps, paper_a

PLANT = [n for n, c in library().items() if c.kind == "plant"]


@pytest.mark.slow
@pytest.mark.parametrize("name", PLANT)
def test_analyse_runs_for_every_plant_effect_in_the_file(tmp_path, name):
    cls = library()[name]
    p = paper_a("stribeck").replace(effects=((name, dataclasses.asdict(cls.Params())),))
    f = tmp_path / "p.toml"
    f.write_text(dumps(p))
    out = tmp_path / "o"
    assert main(["analyse", str(f), "--out", str(out), "--points", "60", "--sliding-velocity", "0.1", "--quiet"]) == 0
    s = json.loads((out / "analysis.json").read_text())
    assert math.isfinite(s["k_eff_dc"]) and s["k_eff_dc"] > 0
    assert len(s["natural_frequencies"]) == 2 and all(math.isfinite(w) and w > 0 for w in s["natural_frequencies"])
    T = s["transmissibility_at_wave_periods"]
    assert all(math.isfinite(x) and x > 0 for x in T.values())
    assert math.isfinite(s["sliding"]["k_eff_dc"])
    assert (out / "bode.png").stat().st_size > 1000 and "k_eff_dc" in (out / "report.md").read_text()


def test_static_gain_of_an_integrator_the_input_never_drives():
    """x1' = 0 (a pole at 0 the input does not reach), x0' = -2 x0 + x1 + u, y = x0: A is singular;
    holding x1 at its operating value leaves y/u = 1/2, the gain of the controllable part."""
    import control as ct

    sys = ct.ss([[-2.0, 1.0], [0.0, 0.0]], [[1.0], [0.0]], [[1.0, 0.0]], [[0.0]], states=["x0", "x1"],
                inputs=["heave"], outputs=["wob"])
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.solve(sys.A, sys.B)
    assert drift_states(sys) == ["x1"]
    assert dc_gain(sys, hold=drift_states(sys)) == pytest.approx(0.5, rel=1e-12)


def test_a_leaking_charge_is_held_and_leaves_the_wave_band_response_unchanged():
    """The library's gas_leak (a charge drifting at a fixed rate) adds a pole at exactly 0 the heave
    never excites: k_eff, the modes and the transmissibility are the nominal ones at the present
    charge.  The benchmark's laminar leak at its largest draw (15 % of the charge over a 300 s log)
    adds a slow real pole near -r; without holding it the static gain would read the leak's hours-long
    response (less than half the spring), and at wave periods the response is the no-leak one."""
    p = paper_a("stribeck")
    nominal = analyse(p, n_points=200)["summary"]
    L = linearise_details(p, effects=[("gas_leak", {"leak_rate": -1e-4})])
    lam = np.linalg.eigvals(L.sys.A)
    assert np.min(np.abs(lam)) < 1e-12
    s = analyse(p, n_points=200, effects=[("gas_leak", {"leak_rate": -1e-4})])["summary"]
    assert s["drift_states"] == ["gas_leak.charge_change"]
    assert s["k_eff_dc"] == pytest.approx(p.k_eff, rel=1e-9)
    np.testing.assert_allclose(s["natural_frequencies"], nominal["natural_frequencies"], rtol=1e-9)
    for T, x in nominal["transmissibility_at_wave_periods"].items():
        assert s["transmissibility_at_wave_periods"][T] == pytest.approx(x, rel=1e-9)

    r = 0.15 / 300.0
    truth = [TruthLaminarLeak(leak_rate=r)]
    Lt = linearise_details(p, effects=truth)
    slow = np.min(np.abs(np.linalg.eigvals(Lt.sys.A)))
    assert 0.2 * r < slow < 5 * r
    st = analyse(p, n_points=200, effects=truth)["summary"]
    assert st["drift_states"] == ["gas_leak.mu"]
    full = -float(Lt.sys.D[0, 0] - Lt.sys.C[0] @ np.linalg.solve(Lt.sys.A, Lt.sys.B[:, 0]))
    assert full < 0.6 * st["k_eff_dc"]  # the unheld DC value is the leak's, not the spring's
    assert st["k_eff_dc"] == pytest.approx(dc_gain(frozen(Lt.sys, ["gas_leak.mu"])) * -1, rel=1e-12)
    for T, x in nominal["transmissibility_at_wave_periods"].items():
        assert st["transmissibility_at_wave_periods"][T] == pytest.approx(x, rel=1e-4)
