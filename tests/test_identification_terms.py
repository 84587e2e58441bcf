"""Identification helpers: candidate friction terms against their analytic limits,
the zero-phase filters, least-squares standard errors, residual localisation, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from heavecomp.errors import ParameterError
from heavecomp.identification import terms as T
from heavecomp.identification.filtering import derivatives, parallel_decimate, zero_phase_lowpass
from heavecomp.identification.inverse import least_squares
from heavecomp.identification.residual import get_candidates, localise


def test_dahl_step_is_the_exact_solution_and_relaxes_over_the_presliding_length():
    delta, v, h = 1e-3, -0.02, 0.01
    sol = solve_ivp(lambda t, z: (v - abs(v) * z) / delta, (0, h), [0.3], rtol=1e-11, atol=1e-12)
    assert T.dahl_step(0.3, v, h, delta) == pytest.approx(sol.y[0, -1], abs=1e-9)
    # from z = -1 (sliding backwards) forward: after sliding 5 delta, z = 1 - 2 e^-5
    z = T.run_state(T.dahl_step, np.full(501, 0.01), 1e-3, 1e-3 / 1.0, y0=-1.0)
    assert z[-1] == pytest.approx(1 - 2 * math.exp(-5.0), rel=1e-9)
    assert T.dahl_step(0.4, 0.0, 1.0, delta) == 0.4         # at rest the state holds (memory)


def test_lag_step_unit_step_and_stribeck_shape():
    y = T.run_state(T.lag_step, np.ones(1001), 1e-3, 0.1)
    assert y[100] == pytest.approx(1 - math.exp(-1.0), rel=1e-9)   # one time constant
    v = np.array([1e-9, 0.01, -0.01, 1.0])
    s = T.stribeck_excess(v, 0.01)
    assert s[0] == pytest.approx(1.0) and s[1] == pytest.approx(math.exp(-1)) and s[2] == -s[1]
    assert s[3] < 1e-40
    assert T.positive_direction(-0.2) == 0.0 and T.positive_direction(0.2) == 1.0
    assert T.fourier_position(0.2, 0.1, 0.4, 1, -0.5 * np.pi) == pytest.approx(math.sin(math.pi / 2))


def test_zero_phase_filters_keep_phase_and_differentiate():
    fs, f = 1000.0, 2.0
    t = np.arange(0, 5, 1 / fs)
    x = np.sin(2 * np.pi * f * t)
    y = zero_phase_lowpass(x, fs, 50.0)
    mid = slice(500, -500)
    assert np.max(np.abs(y[mid] - x[mid])) < 1e-4            # no lag, no attenuation far below cut-off
    _, dq, ddq = derivatives(x, fs, 50.0)
    w = 2 * np.pi * f
    assert np.max(np.abs(dq[mid] - w * np.cos(w * t[mid]))) < 1e-3 * w
    assert np.max(np.abs(ddq[mid] + w * w * x[mid])) < 2e-3 * w * w
    d = parallel_decimate(x, 10)[50:-50]          # zero phase: no cosine component; passband ripple ~1 %
    ts = t[::10][50:-50]
    a, b = np.linalg.lstsq(np.column_stack([np.sin(w * ts), np.cos(w * ts)]), d, rcond=None)[0]
    assert abs(b) < 1e-4 and a == pytest.approx(1.0, abs=0.015)
    with pytest.raises(ParameterError, match=r"cutoff must be in \(0, fs/2\) = \(0, 500\) Hz, got 600"):
        zero_phase_lowpass(x, fs, 600.0)


def test_least_squares_standard_error_matches_theory():
    rng = np.random.default_rng(0)
    n, sigma = 4000, 0.5
    X = np.column_stack([np.ones(n), rng.standard_normal(n)])
    y = X @ [2.0, -1.0] + sigma * rng.standard_normal(n)
    res = least_squares(X, y)
    assert res.theta == pytest.approx([2.0, -1.0], abs=4 * sigma / math.sqrt(n))
    assert res.stderr[0] == pytest.approx(sigma / math.sqrt(n), rel=0.05)
    with pytest.raises(ParameterError, match="more samples"):
        least_squares(X[:2], y[:2])


def test_localise_shares_add_up():
    rng = np.random.default_rng(1)
    v = rng.uniform(-0.1, 0.1, 500)
    r = np.where(v < 0, 3.0, 0.5) * rng.standard_normal(500)
    w = localise(r, v, rng.uniform(0, 0.2, 500), rng.standard_normal(500), dead_band=0.0)
    assert sum(b["share"] for b in w["velocity"]) == pytest.approx(1.0)
    assert sum(b["share"] for b in w["position"]) == pytest.approx(1.0)
    assert w["direction"]["negative"]["share"] > 0.9
    assert w["rms"] == pytest.approx(float(np.sqrt(np.mean(r * r))))


def test_unknown_candidate_names_the_known_ones():
    with pytest.raises(ParameterError, match=r"unknown candidate 'stribek' \(did you mean 'stribeck'\?\); known: "):
        get_candidates(["stribek"])
