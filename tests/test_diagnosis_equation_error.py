"""The equation-error engine (heavecomp.diagnosis.equation_error): candidate columns and the open
search on a component residual; synthetic data with a planted term, and pure noise."""

import numpy as np
import pytest

from heavecomp.diagnosis import equation_error as E
from heavecomp.effects.base import Effect


def _signals(seed=0, n=6001):
    t = np.linspace(0.0, 300.0, n)
    v = 0.2 * np.sin(0.31 * t) * np.cos(0.047 * t + 0.3)
    x = np.cumsum(v) * (t[1] - t[0])
    p = 4e6 + 2e5 * np.sin(0.23 * t + 1.0)
    return {"t": t, "v": v, "x": x, "p": p}, t < 200.0, t >= 200.0, np.random.default_rng(seed)


@pytest.mark.parametrize("planted, coef, feature", [
    (lambda s: (s["v"] > 0).astype(float), 1.9e3, "sign_v_pos"),
    (lambda s: s["p"] * np.sign(s["v"]), 2e-3, "p_sign_v"),
    (lambda s: s["t"] - s["t"][0], 4.0, "t"),
])
def test_open_search_recovers_a_planted_term(planted, coef, feature):
    sig, fit, val, rng = _signals()
    r = coef * planted(sig) + rng.normal(0.0, 0.3 * coef * np.std(planted(sig)), sig["t"].size)
    d = E.open_search(r, sig, fit, val, component="friction")
    assert d is not None and d["features"] == [feature]
    assert d["coefficients"][feature] == pytest.approx(coef, rel=0.05)
    assert d["shrink"] > 0.6 and d["component"] == "friction"
    assert d["term"].endswith(E.library(sig)[feature][1])


@pytest.mark.parametrize("seed", range(6))
def test_open_search_rejects_pure_noise(seed):
    sig, fit, val, rng = _signals(seed)
    white = rng.normal(0.0, 500.0, sig["t"].size)
    coloured = np.convolve(white, np.ones(25) / 25, mode="same")  # a filtered residual: autocorrelated
    assert E.open_search(white, sig, fit, val) is None
    assert E.open_search(coloured, sig, fit, val) is None


class _Band(Effect):
    name = "test_band"
    hook = "seal_friction"
    feature_grid = (0.2, 0.5, 0.8)

    @classmethod
    def features(cls, sig, shape=None):
        x = sig["x"]
        return {"extra": np.sign(sig["v"]) * (x > np.quantile(x, shape))}


def test_rank_effects_picks_the_shape_and_coefficient():
    sig, fit, val, rng = _signals(3)
    x = sig["x"]
    r = 700.0 * np.sign(sig["v"]) * (x > np.quantile(x, 0.5)) + rng.normal(0.0, 200.0, x.size)
    rows = E.rank_effects(r, sig, [_Band, Effect], fit, val)
    assert len(rows) == 1  # the base Effect has no equation-error form
    best = rows[0]
    assert best["effect"] == "test_band" and best["component"] == "friction" and best["shape"] == 0.5
    assert best["coefficients"]["extra"] == pytest.approx(700.0, rel=0.1)
    assert best["shrink"] > 0.3 and best["delta_bic"] < 0


def test_fit_columns_refits_the_base_columns_in_the_reference():
    sig, fit, val, rng = _signals(4)
    r = 3.0 * sig["v"] + 50.0 * np.sign(sig["v"]) + rng.normal(0.0, 1.0, sig["t"].size)
    res = E.fit_columns(r, {"coulomb": np.sign(sig["v"])}, fit, val, base={"viscous": sig["v"]})
    assert res["base"]["viscous"] == pytest.approx(3.0, rel=0.05)
    assert res["coefficients"]["coulomb"] == pytest.approx(50.0, rel=0.02)
    # the reference is the base-only refit, so the shrink is the candidate's own
    only = E.fit_columns(r, {}, fit, val, base={"viscous": sig["v"]})
    assert res["rms_before"] == pytest.approx(only["rms_after"])
    assert res["shrink"] > 0.9


def test_a_near_constant_column_does_not_swamp_the_others():
    """A column of ones with a rounding-level spread (e.g. decimated) is an intercept, not a column
    to divide by its ~1e-16 spread: the other coefficient comes back."""
    from heavecomp.diagnosis.equation_error import fit_columns

    rng = np.random.default_rng(0)
    n = 2000
    x = rng.normal(size=n)
    ones = np.ones(n) + rng.normal(0.0, 1e-16, n)
    r = 3.0 * x + 5.0 + rng.normal(0.0, 0.01, n)
    fit = np.arange(n) < 1400
    res = fit_columns(r, {"x": x, "one": ones}, fit, ~fit)
    assert res["coefficients"]["x"] == pytest.approx(3.0, rel=1e-2)
    assert res["coefficients"]["one"] == pytest.approx(5.0, rel=1e-2)


def test_shape_is_chosen_on_the_fit_part_only():
    """The held-out part scores, never chooses: with the fit part made by shape 2 and the held-out
    part by shape 5, the chosen shape is 2 (choosing by held-out shrink would pick 5)."""
    from heavecomp.diagnosis.equation_error import rank_effects
    from heavecomp.effects.base import Effect

    class Shaped(Effect):
        name = "shaped"
        hook = "seal_friction"
        feature_grid = (1.0, 2.0, 5.0)

        @classmethod
        def features(cls, sig, shape=None):
            return {"c": np.sin(shape * sig["t"])}

    t = np.linspace(0.0, 100.0, 5000)
    fit = t < 60.0
    r = np.where(fit, np.sin(2.0 * t), np.sin(5.0 * t))
    ranked = rank_effects(r, {"t": t}, [Shaped], fit, ~fit)
    assert ranked[0]["shape"] == 2.0


def test_open_search_prunes_on_the_fit_part_only():
    """The held-out part scores, never chooses the terms: a residual made of two features on the fit
    part keeps both whatever the held-out part holds; with the held-out part made by the first
    feature alone (the second one then only costs held-out shrink) pruning by held-out shrink would
    drop the second term, a choice made by the data that is meant to judge it."""
    sig, fit, val, rng = _signals(seed=3)
    a = sig["v"] * np.abs(sig["v"])
    b = (sig["v"] > 0).astype(float)
    noise = rng.normal(0.0, 0.05, sig["t"].size)
    both = 40.0 * a / np.std(a) + 12.0 * b / np.std(b) + noise
    first_only = np.where(fit, both, 40.0 * a / np.std(a) + noise)
    lib = {k: E.library(sig)[k] for k in ("v_abs_v", "sign_v_pos", "p", "x")}
    d_same = E.open_search(both, sig, fit, val, features=lib)
    d_other = E.open_search(first_only, sig, fit, val, features=lib)
    assert sorted(d_same["features"]) == ["sign_v_pos", "v_abs_v"]
    assert d_other["features"] == d_same["features"]
    assert d_other["coefficients"] == pytest.approx(d_same["coefficients"])
    assert d_other["shrink"] < d_same["shrink"]  # the held-out part still scores


def test_rest_durations_match_the_sample_loop():
    """The vectorised rest durations (one function for the dwell feature, the component signals and the
    open search) equal the plain loop over samples, on uneven times with rests at both ends."""
    from heavecomp.effects.features import rest_durations

    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.01, 0.03, 3000))
    still = np.repeat(rng.random(300) < 0.4, 10)
    still[:7] = True
    still[-5:] = True
    so_far, held = np.zeros(t.size), np.zeros(t.size)
    start, last = None, 0.0
    for i in range(t.size):
        if still[i]:
            start = t[i] if start is None else start
            so_far[i] = held[i] = t[i] - start
        else:
            if start is not None:
                last, start = t[i] - start, None
            held[i] = last
    got = rest_durations(t, still)
    assert np.array_equal(got[0], so_far) and np.array_equal(got[1], held)
