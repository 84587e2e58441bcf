"""Identification helpers: the zero-phase filters, least-squares standard errors, residual
localisation, errors.  (The candidate terms are the effects' features: tests/test_friction_features.py.)"""

from __future__ import annotations

import math

import numpy as np
import pytest
from heavecomp.errors import ParameterError
from heavecomp.identification.filtering import derivatives, parallel_decimate
from heavecomp.signals import butterworth_zero_phase
from heavecomp.identification.inverse import least_squares
from heavecomp.identification.residual import get_candidates, localise


def test_zero_phase_filters_keep_phase_and_differentiate():
    fs, f = 1000.0, 2.0
    t = np.arange(0, 5, 1 / fs)
    x = np.sin(2 * np.pi * f * t)
    y = butterworth_zero_phase(x, fs, 50.0)
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
        butterworth_zero_phase(x, fs, 600.0)


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
    """The axis' candidates are the effect library's: one registry, one error."""
    with pytest.raises(ParameterError, match=r"unknown effect 'frictoin_lag' \(did you mean 'friction_lag'\?\); known: "):
        get_candidates(["frictoin_lag"])
