"""Seal-friction effects' equation-error features (issue 12 item 3): plant-independent columns
built from measured signals, checked against their analytic behaviour."""

from __future__ import annotations

import math

import numpy as np
import pytest

from heavecomp.effects.candidates import ParameterMismatch
from heavecomp.effects.dwell_stiction import DwellStiction
from heavecomp.effects.features import breakaway_dwell, dwell_time, first_order_lag
from heavecomp.effects.friction_lag import FrictionLag
from heavecomp.effects.pressure_friction import PressureFriction
from heavecomp.friction import laws


def _signals(with_pressure=True):
    """Slide forwards, rest 0.4 s, slide backwards (1 kHz)."""
    t = np.arange(0.0, 2.0, 1e-3)
    v = np.where(t < 0.8, 0.05, np.where(t < 1.2, 0.0, -0.05))
    sig = {"t": t, "v": v, "x": np.cumsum(v) * 1e-3, "a": np.gradient(v, t), "dwell": dwell_time(t, v, 1e-3)}
    if with_pressure:
        sig["p"] = 2e5 + 1e5 * np.sin(t)
    return sig


def test_first_order_lag_is_the_exact_solution_on_an_uneven_grid():
    t = np.cumsum(np.r_[0.0, np.random.default_rng(0).uniform(0.5e-3, 1.5e-3, 999)])
    y = first_order_lag(t, np.ones(t.size), 0.1)
    from scipy.integrate import solve_ivp  # here, not at collection (scipy.integrate: ~0.4 s a worker)

    sol = solve_ivp(lambda s, z: (1.0 - z) / 0.1, (0.0, t[-1]), [0.0], t_eval=t, rtol=1e-11, atol=1e-12)
    assert np.max(np.abs(y - sol.y[0])) < 1e-8
    i = np.searchsorted(t, 0.1)
    assert y[i] == pytest.approx(1 - math.exp(-t[i] / 0.1), rel=1e-9)


def test_first_order_lag_uniform_filter_is_the_same_recursion():
    """On a uniform grid the lag runs as a linear filter: the same numbers as the exact step loop."""
    t = np.arange(0.0, 2.0, 1e-3)
    x = np.sign(np.sin(7.0 * t))
    y = first_order_lag(t, x, 0.05, y0=0.3)
    ref = np.empty(t.size)
    yk = 0.3
    for i in range(t.size):
        ref[i] = yk
        yk = x[i] + (yk - x[i]) * math.exp(-1e-3 / 0.05)
    assert np.max(np.abs(y - ref)) < 1e-12 and y[0] == 0.3


def test_dwell_and_the_rest_before_a_breakaway():
    sig = _signals()
    t, dwell = sig["t"], sig["dwell"]
    assert dwell[t < 0.8].max() == 0.0
    assert dwell[np.searchsorted(t, 1.1999) - 1] == pytest.approx(0.4, abs=2e-3)
    b = breakaway_dwell(t, dwell, 0.05)
    moving = (t >= 1.2) & (t < 1.25)
    assert np.all(b[moving] == pytest.approx(0.399, abs=2e-3)) and b[t >= 1.26].max() == 0.0
    assert b[t < 1.2].max() == 0.0                     # no rest before the first slide


def test_friction_lag_column_jumps_at_a_reversal_and_dies_out_while_sliding():
    sig = _signals()
    tau = 0.02
    c = FrictionLag.features(sig, tau)["lag_force"]
    t = sig["t"]
    assert abs(c[np.searchsorted(t, 0.7)]) < 1e-6       # 0.7 s of steady sliding: caught up
    i = np.searchsorted(t, 1.2)                         # the backward start after the rest
    assert c[i + 1] > 0.9             # the lagged sign is still near 0 while sign(v) = -1: it lags by +1
    assert c[i + 1 + int(3 * tau / 1e-3)] == pytest.approx(math.exp(-3) * c[i + 1], rel=0.05)
    assert FrictionLag.features({"v": sig["v"]}, tau) is None     # needs t


def test_dwell_stiction_grows_with_the_rest_and_pushes_with_the_motion():
    sig = _signals()
    short = dict(sig, dwell=sig["dwell"] * 0.25)
    a = DwellStiction.features(sig, 0.5)["breakaway_excess"]
    b = DwellStiction.features(short, 0.5)["breakaway_excess"]
    k = np.searchsorted(sig["t"], 1.21)
    assert a[k] < 0 and a[k] == pytest.approx(2.0 * b[k], rel=1e-9)     # (4 tau)^0.5 = 2 tau^0.5
    assert np.count_nonzero(a) == pytest.approx(DwellStiction.breakaway_window / 1e-3, abs=2)


def test_pressure_friction_needs_a_pressure_and_opposes_nothing_by_itself():
    assert PressureFriction.features(_signals(with_pressure=False)) is None
    sig = _signals()
    c = PressureFriction.features(sig)["pressure_friction"]
    assert np.all(c * sig["v"] >= 0) and c.max() == pytest.approx(np.abs(sig["p"][sig["v"] > 0]).max())


def test_parameter_mismatch_columns_are_the_friction_law_regressors():
    sig = _signals(with_pressure=False)
    cols = ParameterMismatch.features(sig, 0.01)
    v = sig["v"]
    assert np.array_equal(cols["friction.coulomb_force"], np.sign(v))
    assert np.array_equal(cols["friction.viscous_coefficient"], v)
    # Stribeck excess exp(-|v|/v_S) sign(v): e^-5 at |v| = 5 v_S
    assert cols["friction.static_force"][0] == pytest.approx(math.exp(-5.0))
    assert ParameterMismatch.features({"t": sig["t"]}, 0.01) is None


def test_asymmetric_friction_columns_are_the_kernel_term_while_sliding():
    """J (1 + a d) sign(v) from the effect's own jump() = J sign(v) + (a J) x its Coulomb column."""
    from heavecomp.effects.asymmetric_friction import AsymmetricFriction

    sig = _signals()
    cols = AsymmetricFriction.features(sig)
    assert set(cols) == {"asymmetric_friction", "asymmetric_pressure_friction", "asymmetric_viscous"}
    v = sig["v"]
    sliding = v != 0
    J, a = 12.0, -0.2
    FP = np.zeros(len(laws.FP_NAMES))
    FP[laws.VS] = 0.01  # the friction law's Stribeck speed (b = 1: no growth speed used)
    kernel = np.array([AsymmetricFriction.jump(0, abs(vi), 0.0, J, 0.0, np.sign(vi), (), FP, a, 1.0, 0.01) * np.sign(vi)
                       for vi in v[sliding]])
    assert np.allclose(kernel, J * np.sign(v[sliding]) + a * J * cols["asymmetric_friction"][sliding], rtol=1e-12)
    assert np.array_equal(cols["asymmetric_viscous"], np.abs(v))
    assert "asymmetric_pressure_friction" not in AsymmetricFriction.features(_signals(with_pressure=False))


def test_position_friction_column_is_the_band_of_the_kernel_on_the_travelled_span():
    from heavecomp.effects.position_friction import PositionFriction

    x = np.linspace(0.2, 0.6, 401)
    sig = {"t": np.arange(x.size) * 1e-3, "x": x, "v": np.full(x.size, -0.01)}
    c = PositionFriction.features(sig, (0.5, 0.2))["position_friction"]
    assert c[200] == pytest.approx(-math.tanh(5.0), rel=1e-9)   # the span's centre (edges 0.1 w), moving backwards
    assert abs(c[0]) < 1e-6 and abs(c[-1]) < 1e-6                # far outside the band
    assert np.count_nonzero(np.abs(c) > 0.5) == pytest.approx(0.2 * 400, abs=2)   # width 20 % of 0.4 m
    assert all(len(s) == 2 for s in PositionFriction.feature_grid)


def test_asymmetric_friction_grows_over_its_own_fitted_speed_not_the_friction_laws():
    """With a symmetric breakaway (b = 0) the asymmetry reaches 1 - 1/e of itself at |v| = v_g, whatever the
    friction law's Stribeck speed (spent 590009: a lip whose asymmetry grows after a reversal more slowly than
    the borrowed 0.01 m/s allowed)."""
    from heavecomp.effects.asymmetric_friction import AsymmetricFriction

    FP = np.zeros(len(laws.FP_NAMES))
    FP[laws.VS] = 0.01
    J, a, vg = 10.0, 0.3, 0.2
    at_vg = AsymmetricFriction.jump(0, vg, 0.0, J, 0.0, 1.0, (), FP, a, 0.0, vg)
    assert at_vg == pytest.approx(J * (1.0 + a * (1.0 - np.exp(-1.0))), rel=1e-12)
    # at ten Stribeck speeds the borrowed scale would have grown it fully; v_g = 0.2 m/s has not
    mid = AsymmetricFriction.jump(0, 0.1, 0.0, J, 0.0, -1.0, (), FP, a, 0.0, vg)
    assert mid == pytest.approx(J * (1.0 - a * (1.0 - np.exp(-0.5))), rel=1e-12)
    assert AsymmetricFriction.jump(0, 0.0, 0.0, J, 0.0, 1.0, (), FP, a, 0.0, vg) == J  # symmetric at rest
