"""The effect-aware stepper: pinned to the foundation simulate() with every effect off, and the
effect terms act as their equations say (line drop, dwell, thermal)."""

import numpy as np
import pytest

from heavecomp.diagnosis.stepper import simulate_fx
from heavecomp.effects import terms as T
from heavecomp.params import paper_a
from heavecomp.simulate import simulate


@pytest.mark.parametrize("model", ["stribeck", "rotating_eq7", "none"])
def test_no_effect_reproduces_foundation_simulate(model):
    p = paper_a(model)
    ref = simulate(p, 120.0, rate=50.0, dt=0.01)  # same explicit step for both
    fx = simulate_fx(p, 120.0, rate=50.0, dt=0.01)
    assert fx["t"].shape == ref["t"].shape
    scale = np.std(ref["wob"])
    assert np.max(np.abs(fx["wob"] - ref["wob"])) < 1e-6 * scale
    assert np.max(np.abs(fx["stroke"] - ref["stroke"])) < 1e-9
    np.testing.assert_array_equal(fx["stuck"][1:], ref["stuck"][1:])  # smooth laws: foundation starts sliding


def test_flow_loss_candidate_is_exactly_the_line_drop():
    """p_cyl = p_gas - R v at every recorded sample."""
    EP = T.zero_ep()
    EP[T.FLOW_R_CAND] = 1e5
    r = simulate_fx(paper_a(), 60.0, EP, rate=50.0)
    np.testing.assert_allclose(r["pressure"], r["gas_pressure"] - 1e5 * r["stroke_velocity"], atol=1e-6)
    assert np.max(np.abs(r["stroke_velocity"])) > 0.1


def test_dwell_stiction_lengthens_sticking():
    """Static friction growing with the time at rest holds the cylinder longer."""
    p = paper_a().replace(heave={"amplitude": 0.3})
    base = simulate_fx(p, 120.0, rate=50.0)
    EP = T.zero_ep()
    EP[T.DWELL_DF_TRUTH], EP[T.DWELL_TAU_TRUTH] = 15e3, 0.5
    dw = simulate_fx(p, 120.0, EP, rate=50.0)
    m = base["t"] > 24
    assert dw["stuck"][m].mean() > base["stuck"][m].mean() + 0.02
    assert np.std(dw["wob"][m]) > np.std(base["wob"][m])  # larger breakaway jumps reach the bit


def test_thermal_gas_at_rest_relaxes_to_the_isothermal_pressure():
    """Truth thermal model: stuck at rest the gas temperature relaxes to the wall's (theta -> 1)."""
    p = paper_a().replace(heave={"amplitude": 1e-6})  # essentially no heave: stays stuck at s = 0
    EP = T.zero_ep()
    EP[T.TH_GAMMA_TRUTH], EP[T.TH_TAU_TRUTH] = 1.4, 2.0
    r = simulate_fx(p, 20.0, EP, rate=50.0)
    assert np.all(r["stuck"] == 1.0)
    np.testing.assert_allclose(r["theta"], 1.0, atol=1e-9)
    np.testing.assert_allclose(r["pressure"], p.p0, rtol=1e-9)
