"""Equation-error columns (Effect.features) of the non-friction effects: least squares of a component
residual made by the effect's own law on its columns gives back the planted coefficients; a signal
the columns need is missing -> None."""

from __future__ import annotations

import numpy as np
import pytest

from heavecomp.effects.registry import effect_class
from heavecomp.params import paper_a
from heavecomp.plants import cmc

T = np.linspace(0.0, 600.0, 12001)
V = 0.4 * np.sin(2 * np.pi * T / 11.0) + 0.15 * np.sin(2 * np.pi * T / 7.3 + 1.0)
S = np.cumsum(V) * (T[1] - T[0])
NOISE = np.random.default_rng(5)


def _coef(cols, r):
    names = list(cols)
    X = np.column_stack([cols[k] for k in names])
    c, *_ = np.linalg.lstsq(X, r, rcond=None)
    return dict(zip(names, c))


def _gas_signals():
    PP = cmc.plant_vectors(paper_a()).PP
    pa = cmc.gas_pressure(S, PP) + PP[cmc.PATM]
    return PP, {"t": T, "v": V, "x": S, "p_gas_abs": pa, "p_charge_abs": float(PP[cmc.P0ABS])}


def test_flow_loss_column_gives_the_resistance():
    r = -2e5 * V + NOISE.normal(0, 500.0, T.size)
    assert _coef(effect_class("flow_loss").features({"t": T, "v": V}), r)["flow_loss"] == pytest.approx(2e5, rel=0.01)


def test_gas_leak_column_gives_the_rate():
    PP, sig = _gas_signals()
    rate = -2.5e-5
    r = rate * T * sig["p_gas_abs"] + NOISE.normal(0, 300.0, T.size)
    assert _coef(effect_class("gas_leak").features(sig), r)["gas_leak"] == pytest.approx(rate, rel=0.01)


def test_gas_heat_transfer_columns_give_index_loss_and_warming():
    """Residual from the effect's own gas/line methods and its warming state (simulated finely);
    the columns at the right warming time give back c_g and w, and n_eff to first order."""
    cls = effect_class("gas_heat_transfer")
    PP, sig = _gas_signals()
    n = float(PP[cmc.N])
    n_eff, cg, w, tw = n - 0.03, 4e4, 0.05, 300.0
    theta = np.zeros(T.size)
    dt = T[1] - T[0]
    for k in range(1, T.size):
        theta[k] = theta[k - 1] + dt * (w * V[k - 1] ** 2 - theta[k - 1]) / tw
    p = np.array([cls.line(v, cls.gas(s, v, 0.0, (th,), PP, n_eff, cg, w, tw), (), PP, n_eff, cg, w, tw)
                  for s, v, th in zip(S, V, theta)])
    r = p - (sig["p_gas_abs"] - PP[cmc.PATM])
    c = _coef(cls.features(sig, shape=tw), r)
    assert c["loss"] == pytest.approx(cg, rel=0.02)
    assert c["warming"] == pytest.approx(w, rel=0.05)
    assert c["index"] == pytest.approx((n_eff - n) / n, rel=0.1)
    assert cls.features({"t": T, "v": V}) is None


def test_string_damping_column_gives_the_damping():
    dz = 0.01 * np.sin(2 * np.pi * T / 9.0)
    r = -3e5 * np.gradient(dz, T) + NOISE.normal(0, 100.0, T.size)
    c = _coef(effect_class("string_damping").features({"t": T, "dz": dz}), r)
    assert c["string_damping"] == pytest.approx(3e5, rel=0.01)


def test_sensor_columns_give_gain_offset_and_delay():
    y = 1e5 + 2e4 * np.sin(2 * np.pi * T / 10.0)
    g = -1.0  # a sign flip: y_meas - y = (1 - 1/g) y_meas
    ym = g * y
    c = _coef(effect_class("sensor_gain").features({"t": T, "y": ym}), ym - y)
    assert c["sensor_gain"] == pytest.approx(1 - 1 / g, rel=1e-9)
    off = effect_class("sensor_offset")
    ym = off.apply(T, T, y, 101325.0, 3.0)
    c = _coef(off.features({"t": T, "y": ym}), ym - y)
    assert c["offset"] == pytest.approx(101325.0, rel=1e-9) and c["drift"] == pytest.approx(3.0, rel=1e-9)
    dl = effect_class("sensor_delay")
    ym = dl.apply(T, T, y, 0.5)
    fits = {d: _coef(dl.features({"t": T, "y": ym}, shape=d), ym - y) for d in dl.feature_grid}
    res = {d: np.std(ym - y - fits[d]["sensor_delay"] * dl.features({"t": T, "y": ym}, shape=d)["sensor_delay"])
           for d in fits}
    assert min(res, key=res.get) == 0.5
    assert fits[0.5]["sensor_delay"] == pytest.approx(1.0, rel=0.01)


def test_heave_reference_columns_give_gain_and_delay():
    cls = effect_class("heave_reference")
    z = 1.2 * np.sin(2 * np.pi * T / 10.0) + 0.4 * np.sin(2 * np.pi * T / 6.5)
    seen = cls.seen(T, z, 0.88, -0.2)
    r = seen - z
    errs = {}
    for d in cls.feature_grid:
        cols = cls.features({"t": T, "heave": z}, shape=d)
        c = _coef(cols, r)
        errs[d] = (np.std(r - sum(c[k] * cols[k] for k in cols)), c)
    best = min(errs, key=lambda d: errs[d][0])
    assert best == -0.2
    assert errs[best][1]["gain"] == pytest.approx(0.88 - 1.0, rel=1e-3)
    assert errs[best][1]["delay"] == pytest.approx(0.88, rel=1e-3)
