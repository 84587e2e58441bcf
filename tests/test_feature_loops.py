"""The equation-error features' sample loops run compiled (numba, the same source): pinned to the
interpreter's result bit for bit, and gas_thermal's affine integration to the step-by-step loop over its
own rates that it replaced."""

import numpy as np
import pytest

from heavecomp.effects import features as FT
from heavecomp.effects.gas_thermal import GasThermal
from heavecomp.params import paper_a
from heavecomp.plants.cmc import plant_vectors


def test_compiled_lag_is_the_interpreted_loop_bit_for_bit():
    rng = np.random.default_rng(3)
    x, decay = rng.normal(size=500), rng.uniform(0.0, 1.0, 499)
    np.testing.assert_array_equal(FT.compiled(FT._lag_steps)(x, decay, 0.3), FT._lag_steps(x, decay, 0.3))


def test_compiled_euler_is_the_interpreted_loop_bit_for_bit():
    rng = np.random.default_rng(4)
    c0, c1 = rng.normal(size=400), -rng.uniform(0.0, 30.0, 400)
    dt = rng.uniform(0.01, 0.03, 400)
    np.testing.assert_array_equal(FT.compiled(FT.euler_affine)(c0, c1, dt, 0.01, 1.0),
                                  FT.euler_affine(c0, c1, dt, 0.01, 1.0))


@pytest.mark.parametrize("tau", [0.05, 5.0])
def test_gas_thermal_feature_integrates_its_own_rates(tau):
    """theta from the effect's own rates at every explicit sub-step (the former loop), then its own gas law."""
    PP = plant_vectors(paper_a()).PP
    t = np.arange(0.0, 60.0, 0.02)
    s = 0.5 * np.sin(2 * np.pi * t / 10.0)
    v = 0.1 * np.pi * np.cos(2 * np.pi * t / 10.0)
    gamma = GasThermal.Params().gamma
    theta, th = np.ones(t.size), 1.0
    for k in range(1, t.size):
        sub = max(1, int(np.ceil((t[k] - t[k - 1]) / (0.2 * tau))))
        h = (t[k] - t[k - 1]) / sub
        for _ in range(sub):
            th = th + h * GasThermal.rates(s[k - 1], v[k - 1], 0.0, (th,), PP, None, gamma, tau)[0]
        theta[k] = th
    ref = GasThermal.gas(s, v, 0.0, (theta,), PP, gamma, tau)
    got = GasThermal.features({"t": t, "x": s, "v": v, "PP": PP}, shape=tau)["thermal"]
    assert np.ptp(theta) > 1e-4  # the gas really warms and cools over the stroke (4e-4 at tau 0.05 s)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-9 * np.abs(ref).max())
