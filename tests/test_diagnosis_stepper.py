"""The diagnosis' effect-aware replay is the foundation stepper: with every effect off it is
simulate() bit for bit, it inherits the bit lift-off/touchdown events, and the effect terms act
as their equations say (line drop, dwell, thermal)."""

import numpy as np
import pytest

from heavecomp.diagnosis.stepper import CHANNELS, replay_dt, simulate_fx
from heavecomp.benchmark.truth import TruthDwell, TruthOrifice, TruthThermalGas, truth_composition
from heavecomp.effects.registry import effect_class
from heavecomp.params import paper_a
from heavecomp.simulate import simulate
from heavecomp.simulate.layout import CHANNELS as SIM_CHANNELS


@pytest.mark.parametrize("model", ["stribeck", "rotating_eq7", "none"])
def test_no_effect_is_foundation_simulate_bit_for_bit(model):
    """One stepper: EP = 0 reproduces simulate() exactly (the AOT or JIT advance), every channel."""
    p = paper_a(model)
    ref = simulate(p, 120.0, rate=50.0, dt=0.01)  # same explicit step for both
    fx = simulate_fx(p, 120.0, rate=50.0, dt=0.01)
    assert CHANNELS[:len(SIM_CHANNELS)] == SIM_CHANNELS
    for c in SIM_CHANNELS:
        np.testing.assert_array_equal(fx[c], ref[c], err_msg=c)
    np.testing.assert_array_equal(fx["gas_pressure"], ref["pressure"])  # no line drop
    lib = simulate_fx(p, 120.0, ["flow_loss"], rate=50.0, dt=0.01)  # the library's stepper ...
    from heavecomp.effects.compose import library_composition
    from heavecomp.simulate import _kernel as K
    assert K.kernel_for(library_composition()) is not K.advance_fx
    off = simulate_fx(p, 120.0, [effect_class("flow_loss")(resistance=0.0)], rate=50.0, dt=0.01)
    for c in SIM_CHANNELS:  # ... with its line effect at zero size is simulate() bit for bit as well
        np.testing.assert_array_equal(off[c], ref[c], err_msg=c)
    assert np.max(np.abs(lib["wob"] - ref["wob"])) > 10.0


def test_replay_locates_bit_lift_off_and_touchdown_with_effects():
    """With an effect on, the replay stays fourth order through repeated lift-off: lift-off and
    touchdown are events of the shared stepper.  (The former diagnosis-only stepper stepped over
    them: 10-30 N rms at these steps, no convergence.)  EP = 0 still equals simulate() there."""
    p = paper_a("stribeck").replace(heave={"amplitude": 3.0})
    EP = [TruthOrifice(K=3e5)]  # orifice line loss: acts through the pressure, in every regime
    ref = simulate_fx(p, 60.0, EP, rate=10.0, dt=0.000625, comp=truth_composition())
    assert np.count_nonzero(ref["wob"] == 0.0) > 100  # the bit really lifts off, repeatedly
    errs = []
    for dt in (0.02, 0.01, 0.005):
        r = simulate_fx(p, 60.0, EP, rate=10.0, dt=dt, comp=truth_composition())
        errs.append(float(np.sqrt(np.mean((r["wob"] - ref["wob"]) ** 2))))
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(orders >= 3.5), (errs, orders)  # measured 3.98, 3.99
    assert errs[1] < 1.0  # N at 10 ms (measured 0.09)
    # the replay step (replay_dt: 20 ms on this plant) stays two orders under the benchmark's 400 N WOB noise
    assert replay_dt(p, 10.0) == pytest.approx(0.02) and errs[0] < 4.0  # N (measured ~1.4)

    h = replay_dt(p, 50.0)
    sim = simulate(p, 60.0, rate=50.0, dt=h)
    assert sim.stats["n_contact_switch"] > 10
    np.testing.assert_array_equal(simulate_fx(p, 60.0, rate=50.0)["wob"], sim["wob"])


def test_flow_loss_candidate_is_exactly_the_line_drop():
    """p_cyl = p_gas - R v at every recorded sample."""
    r = simulate_fx(paper_a(), 60.0, [("flow_loss", {"resistance": 1e5})], rate=50.0)
    np.testing.assert_allclose(r["pressure"], r["gas_pressure"] - 1e5 * r["stroke_velocity"], atol=1e-6)
    assert np.max(np.abs(r["stroke_velocity"])) > 0.1


def test_dwell_stiction_lengthens_sticking():
    """Static friction growing with the time at rest holds the cylinder longer."""
    p = paper_a().replace(heave={"amplitude": 0.3})
    base = simulate_fx(p, 120.0, rate=50.0)
    dw = simulate_fx(p, 120.0, [TruthDwell(dF=15e3, tau_d=0.5)], rate=50.0, comp=truth_composition())
    m = base["t"] > 24
    assert dw["stuck"][m].mean() > base["stuck"][m].mean() + 0.02
    assert np.std(dw["wob"][m]) > np.std(base["wob"][m])  # larger breakaway jumps reach the bit


def test_thermal_gas_at_rest_relaxes_to_the_isothermal_pressure():
    """Truth thermal model: stuck at rest the gas temperature relaxes to the wall's (theta -> 1)."""
    p = paper_a().replace(heave={"amplitude": 0.0})  # no heave: stays stuck at s = 0
    r = simulate_fx(p, 20.0, [TruthThermalGas(gamma=1.4, tau_th=2.0)], rate=50.0,
                    comp=truth_composition())
    assert np.all(r["stuck"] == 1.0)
    slot = truth_composition().slots["gas_heat_transfer"][0]
    np.testing.assert_allclose(r[f"effect_state_{slot}"], 1.0, atol=1e-9)  # theta, the effect's state  # theta, the effect's state
    np.testing.assert_allclose(r["pressure"], p.p0, rtol=1e-9)
