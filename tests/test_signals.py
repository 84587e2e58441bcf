"""Zero-phase FIR filtering/differentiation (paper B's method): no lag, correct derivatives, friction recovery."""

import numpy as np
import pytest

from heavecomp import signals as S
from heavecomp.errors import DataError, InputError


def test_sine_passes_with_zero_phase_lag():
    fs, f0 = 1000.0, 1.0
    t = np.arange(0, 10, 1 / fs)
    x = np.sin(2 * np.pi * f0 * t)
    y = S.hamming_zero_phase(x, fs, cutoff=10.0)
    m = slice(2000, 8000)
    # phase of the filtered sine by projection on sin/cos: exactly 0 up to rounding
    ph = np.arctan2(np.dot(y[m], np.cos(2 * np.pi * f0 * t[m])), np.dot(y[m], np.sin(2 * np.pi * f0 * t[m])))
    assert abs(ph) < 1e-6
    # a one-pass (causal) filter of the same taps lags by (N-1)/2 samples: the test can tell
    from scipy.signal import lfilter

    b = S.design_lowpass(fs, 10.0)
    yc = lfilter(b, [1.0], x)
    phc = np.arctan2(np.dot(yc[m], np.cos(2 * np.pi * f0 * t[m])), np.dot(yc[m], np.sin(2 * np.pi * f0 * t[m])))
    assert phc == pytest.approx(-2 * np.pi * f0 * (b.size - 1) / 2 / fs, rel=1e-3)


def test_twice_differentiated_sine():
    fs, f0 = 500.0, 0.8
    w = 2 * np.pi * f0
    t = np.arange(0, 12, 1 / fs)
    x = 0.01 * np.sin(w * t)
    xf, v, a = S.differentiate(t, x, cutoff=8.0)
    m = slice(1000, 5000)
    np.testing.assert_allclose(v[m], 0.01 * w * np.cos(w * t[m]), atol=1e-2 * 0.01 * w)  # passband ripple of the repeated filter < 1 %
    np.testing.assert_allclose(a[m], -0.01 * w * w * np.sin(w * t[m]), atol=1e-2 * 0.01 * w * w)


def test_bad_time_column_is_named():
    t = np.array([0.0, 0.01, 0.02, 0.05, 0.06])
    with pytest.raises(DataError, match="column t: sampling is not uniform"):
        S.sample_rate(t)
    with pytest.raises(DataError, match="column t: time must be strictly increasing"):
        S.sample_rate(np.array([0.0, 0.01, 0.01, 0.02]))
    with pytest.raises(InputError, match="cutoff = 600 Hz must lie in"):
        S.design_lowpass(1000.0, 600.0)


def test_friction_recovered_from_synthetic_pneumatic_measurement():
    """Plant with known three-regime friction, 12.5 um encoder, 200 Pa pressure noise."""
    from heavecomp.pneumatic.measurement import synthetic_validation

    r = synthetic_validation(duration=2.5)
    assert r["rms_error_N"] < 0.02 * r["friction_span_N"]
    assert r["velocity_rms_error"] < 1e-3  # m/s, vs u_0 = 30 mm/s


def test_filtfilt_fir_is_scipy_filtfilt():
    """The closed-form FIR initial condition gives scipy's filtfilt (odd padding, 3 lengths)."""
    from scipy.signal import filtfilt

    from heavecomp.signals import design_flat_lowpass, filtfilt_fir

    x = np.cumsum(np.random.default_rng(2).normal(size=3000)) + 5.0
    for b in (design_flat_lowpass(50.0, 1.0, 0.75), np.array([0.25, 0.5, 0.25])):
        ref = filtfilt(b, [1.0], x, padtype="odd", padlen=3 * b.size)
        assert np.max(np.abs(filtfilt_fir(x, b) - ref)) <= 1e-9 * np.max(np.abs(ref))
