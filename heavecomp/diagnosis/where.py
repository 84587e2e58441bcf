"""Where the gap lies: by friction regime, by frequency band, by time segment."""

from __future__ import annotations

import math

import numpy as np

from heavecomp.diagnosis.data import uniform
from heavecomp.plants.cmc import eigenfrequencies  # the plant's linear model; used here and re-exported

REGIMES = ("stuck", "breakaway", "sliding_accelerating", "sliding_decelerating")
BANDS = ("below_wave", "wave", "resonance", "above")
BREAKAWAY_WINDOW = 0.3  #: s after a stuck -> sliding transition counted as "breakaway"
SEGMENT_LENGTH = 5.0    #: s, window of the rolling residual power for "segments"


def wave_band(t, z) -> tuple[float, float]:
    """Frequencies [Hz] holding the central 90 % of the heave variance (5 %..95 %).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (may be non-uniform, with dropouts).
    z : numpy.ndarray [m]
        Measured heave.
    """
    from scipy.signal import welch

    tu, zu = uniform(t, z)
    dt = tu[1] - tu[0]
    f, S = welch(zu - zu.mean(), fs=1 / dt, nperseg=min(zu.size, int(256 / dt)))
    cum = np.cumsum(S)
    cum /= cum[-1]
    return float(f[np.searchsorted(cum, 0.05)]), float(f[np.searchsorted(cum, 0.95)])


def band_edges(run, params):
    """The frequency bands of "where" [Hz]: below the wave band, the wave band, the resonance (up to
    1.3 x the top eigenfrequency, at least 1.5 x the wave band's top) and above.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run (its heave sets the wave band).
    params : heavecomp.params.CMCParams
        Nominal parameters (their eigenfrequencies set the resonance band).
    """
    lo, hi = wave_band(run.t, run["heave"])
    fe = eigenfrequencies(params)
    res = [hi, max(1.3 * max(fe), 1.5 * hi)]  # contiguous: wave | resonance (up to 1.3 x the top mode) | above
    return {"below_wave": [0.0, lo], "wave": [lo, hi], "resonance": res, "above": [res[1], math.inf]}


def residual_spectrum(t, r):
    """Welch PSD of a residual [unit^2/Hz] on a uniform resampling (dropouts bridged).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    r : numpy.ndarray [unit]
        Residual.
    """
    from scipy.signal import welch

    tu, ru = uniform(t, r)
    dt = tu[1] - tu[0]
    return welch(ru - ru.mean(), fs=1 / dt, nperseg=min(ru.size, int(128 / dt)))


TREND_DEGREE = 2  #: degree of the polynomial in time that counts as a slow trend in "where"


def level_shares(t, r) -> dict:
    """Split a residual's mean square into its offset, slow trend and fluctuation [-, shares summing to 1].

    ``offset`` = mean(r)^2 / mean(r^2); ``trend`` = the part a polynomial of degree
    ``TREND_DEGREE`` in time adds beyond the mean (a drift over the whole run: a gas charge that
    leaks, a gas that warms under cycling, a sensor zero that drifts); ``fluctuation`` = the rest,
    which the band spectrum splits.  Also returns the detrended residual.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    r : numpy.ndarray [unit]
        Residual (finite samples).
    """
    ms = float(np.mean(r * r))
    if ms <= 0 or r.size < TREND_DEGREE + 2:
        return {"offset": 0.0, "trend": 0.0, "fluctuation": 1.0}, r - r.mean() if r.size else r
    x = (t - t[0]) / max(t[-1] - t[0], 1e-12) * 2.0 - 1.0
    fit = np.polynomial.legendre.Legendre.fit(x, r, TREND_DEGREE, domain=[-1, 1])
    slow = fit(x)
    mean = float(r.mean())
    offset = mean * mean / ms
    trend = float(np.mean((slow - mean) ** 2)) / ms
    rest = r - slow
    return {"offset": offset, "trend": trend, "fluctuation": float(np.mean(rest * rest)) / ms}, rest


def locate(run, nom, params, mask, channel="wob") -> dict:
    """Shares of the squared residual by regime and band, and the worst segments.

    ``bands`` are shares of the mean-removed spectrum (schema 1); ``levels`` splits the whole squared
    residual into ``offset``, ``trend`` and the bands of the detrended rest (schema-2 addition: until
    2026-11 an offset or a slow drift vanished from "where" -- a gas leak whose residual was 72 %
    trend read as 90 % "resonance"); ``offset`` and ``trend`` are repeated at the top level.

    Regimes come from the replayed nominal model (noise-free): stuck; breakaway
    (the first ``BREAKAWAY_WINDOW`` s after a stuck -> sliding transition); sliding
    with |v| growing (v a > 0) or shrinking.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    nom : dict
        The nominal replay ({channel: array} [SI], ``stuck``, ``stroke_velocity`` [m/s]) at the run's times.
    params : heavecomp.params.CMCParams
        Nominal parameters.
    mask : numpy.ndarray of bool
        Samples counted (e.g. after the settling window).
    channel : str
        Channel whose residual (nominal minus measured) is located.
    """
    t = run.t
    y = run[channel]
    ok = mask & np.isfinite(y)
    r = np.where(ok, nom[channel] - np.where(np.isfinite(y), y, 0.0), np.nan)
    r2 = np.where(ok, r * r, 0.0)
    stuck = nom["stuck"] > 0.5
    v = nom["stroke_velocity"]
    a = np.gradient(v, t)
    start = np.flatnonzero(stuck[:-1] & ~stuck[1:]) + 1
    brk = np.zeros_like(stuck)
    for i in start:
        brk |= (t >= t[i]) & (t < t[i] + BREAKAWAY_WINDOW)
    brk &= ~stuck
    acc = ~stuck & ~brk & (v * a > 0)
    dec = ~stuck & ~brk & ~acc
    tot = r2.sum() or 1.0
    regimes = {k: float(r2[m].sum() / tot) for k, m in zip(REGIMES, (stuck, brk, acc, dec))}
    regimes_time = {k: float(np.mean(m[ok])) for k, m in zip(REGIMES, (stuck, brk, acc, dec))}
    edges = band_edges(run, params)
    f, S = residual_spectrum(t[ok], r[ok])
    Stot = S.sum() or 1.0
    bands = {}
    for k in BANDS:
        lo, hi = edges[k]
        bands[k] = float(S[(f >= lo) & (f < hi)].sum() / Stot)
    lv, rest = level_shares(t[ok], r[ok])
    f2, S2 = residual_spectrum(t[ok], rest)
    S2tot = S2.sum() or 1.0
    levels = {"offset": lv["offset"], "trend": lv["trend"]}
    for k in BANDS:
        lo, hi = edges[k]
        levels[k] = float(lv["fluctuation"] * S2[(f2 >= lo) & (f2 < hi)].sum() / S2tot)
    # worst segments: rolling mean square over SEGMENT_LENGTH, top 3 disjoint windows
    dt = float(np.median(np.diff(t)))
    n = max(1, int(SEGMENT_LENGTH / dt))
    power = np.convolve(r2, np.ones(n) / n, mode="same")
    segs = []
    order = np.argsort(power)[::-1]
    for i in order:
        c = t[i]
        if any(abs(c - 0.5 * (s0 + s1)) < SEGMENT_LENGTH for s0, s1 in segs):
            continue
        segs.append([float(max(c - 0.5 * SEGMENT_LENGTH, 0.0)), float(min(c + 0.5 * SEGMENT_LENGTH, t[-1]))])
        if len(segs) == 3:
            break
    return {"regimes": regimes, "bands": bands, "segments": segs, "offset": levels["offset"],
            "trend": levels["trend"], "levels": levels, "regime_time_share": regimes_time,
            "band_edges_hz": {k: [float(x) if math.isfinite(x) else None for x in e] for k, e in edges.items()},
            "eigenfrequencies_hz": eigenfrequencies(params), "channel": channel}
