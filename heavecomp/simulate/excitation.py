"""Platform heave inputs: sine with fade-in, JONSWAP irregular sea, measured file.

Every excitation is delivered to the stepper as samples of z_h, dz_h/dt and
d^2z_h/dt^2 on a uniform grid of spacing ``dt/2`` (the RK4 stage times); the
stepper interpolates between samples with quintic Hermite polynomials when an
event falls between them.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from pathlib import Path

import numpy as np

from heavecomp.errors import DataError, ParameterError
from heavecomp.io.series import gaps
from heavecomp.io.series import read_series, short
from heavecomp.signals import HEAVE_CUTOFF, flat_zero_phase

#: what a heave file goes through before it drives the plant (metrics.json ``heave.preprocessing``); the diagnosis'
#: replay differs only in its start (docs/diagnosis.md, "Replay a log under several files")
PREPROCESSING = (f"gap-filled, made uniform, zero-phase low-passed at {HEAVE_CUTOFF:g} Hz as the diagnosis' replay; "
                 "the run starts at rest at the operating point with the first filtered sample as the heave "
                 "reference, where the replay starts from the state it estimates from the log's first seconds")

G = 9.81
log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class HeaveSamples:
    """z_h, dz_h, ddz_h sampled every ``spacing`` seconds from t = 0."""

    spacing: float
    z: np.ndarray
    dz: np.ndarray
    ddz: np.ndarray
    info: dict = dataclasses.field(default_factory=dict)
    #: (sample index, left-limit ddz) where the fade-in ends on a sample: d^2r/dt^2 jumps
    #: there (-pi^2/(2 T_r^2) -> 0), so the interval before it needs the left limit
    kink: tuple | None = None
    #: a logged vessel angle on the same grid, (theta [rad], dtheta [rad/s], ddtheta [rad/s^2]), or None:
    #: what a heave effect with a lever arm (``heave_reference``) needs besides the heave
    angle: tuple | None = None

    @property
    def t(self) -> np.ndarray:
        return np.arange(self.z.size) * self.spacing


def ramp_factor(t, ramp):
    """Fade-in r(t) = sin^2(pi/2 min(t/T_r, 1)) and its first two derivatives.

    Parameters
    ----------
    t : float or array [s]
        Time(s).
    ramp : float [s]
        Fade-in duration T_r (<= 0: no fade-in).
    """
    t = np.asarray(t, dtype=float)
    if ramp <= 0:
        one = np.ones_like(t)
        return one, 0 * one, 0 * one
    inside = t < ramp
    x = np.pi * np.minimum(t / ramp, 1.0)
    r = np.where(inside, np.sin(x / 2) ** 2, 1.0)
    dr = np.where(inside, np.pi / (2 * ramp) * np.sin(x), 0.0)
    ddr = np.where(inside, np.pi ** 2 / (2 * ramp ** 2) * np.cos(x), 0.0)
    return r, dr, ddr


def ramp_kink(spacing, z, ddz, ramp):
    """(index, left-limit ddz) of the sample at t = ramp, or None if no sample is there.

    Parameters
    ----------
    spacing : float [s]
        Sample spacing.
    z : (n,) array [m]
        Heave samples (faded in).
    ddz : (n,) array [m/s^2]
        Heave acceleration samples (faded in; right limit at the kink).
    ramp : float [s]
        Fade-in duration T_r (<= 0: no fade-in).
    """
    if ramp <= 0:
        return None
    k = int(round(ramp / spacing))
    if k >= z.size or abs(k * spacing - ramp) > 1e-9 * ramp:
        return None
    return k, float(ddz[k] - np.pi ** 2 / (2 * ramp ** 2) * z[k])


def _apply_ramp(t, z, dz, ddz, ramp):
    """Fade in (z, dz, ddz) by r(t); only the samples with t < ramp change."""
    n = int(np.searchsorted(t, ramp)) if ramp > 0 else 0
    if n == 0:
        return z, dz, ddz
    z, dz, ddz = z.copy(), dz.copy(), ddz.copy()
    r, dr, ddr = ramp_factor(t[:n], ramp)
    z0, d0, a0 = z[:n].copy(), dz[:n].copy(), ddz[:n].copy()
    z[:n], dz[:n], ddz[:n] = r * z0, dr * z0 + r * d0, ddr * z0 + 2 * dr * d0 + r * a0
    return z, dz, ddz


def sine(amplitude, period, ramp, duration, spacing) -> HeaveSamples:
    """z_h = r(t) a sin(2 pi t / T) (cmc-reference.md).

    Parameters
    ----------
    amplitude : float [m]
        Heave amplitude a.
    period : float [s]
        Heave period T.
    ramp : float [s]
        Fade-in duration T_r (<= 0: no fade-in).
    duration : float [s]
        Time covered by the samples.
    spacing : float [s]
        Sample spacing (h/2 of the stepper).
    """
    t = np.arange(int(math.ceil(duration / spacing)) + 1) * spacing
    w = 2 * np.pi / period
    z, dz, ddz = _apply_ramp(t, amplitude * np.sin(w * t), amplitude * w * np.cos(w * t),
                             -amplitude * w * w * np.sin(w * t), ramp)
    return HeaveSamples(spacing, z, dz, ddz, {"kind": "sine", "amplitude": amplitude, "period": period, "ramp": ramp},
                        kink=ramp_kink(spacing, z, ddz, ramp))


def jonswap_spectrum(f, hs, tp, gamma=3.3):
    """One-sided JONSWAP spectral density S(f) [m^2/Hz] scaled to 4 sqrt(m0) = hs.

    DNV-RP-C205 form with sigma = 0.07 (f <= f_p) / 0.09 (f > f_p); the
    normalisation is done numerically so H_s is exact for any gamma.

    Parameters
    ----------
    f : float or array [Hz]
        Frequencies (S = 0 at f <= 0).
    hs : float [m]
        Significant wave height H_s.
    tp : float [s]
        Peak period T_p.
    gamma : float [-]
        Peak enhancement factor.
    """
    f = np.asarray(f, dtype=float)
    fp = 1.0 / tp
    out = np.zeros_like(f)
    pos = f > 0
    fpos = f[pos]
    sigma = np.where(fpos <= fp, 0.07, 0.09)
    shape = fpos ** -5 * np.exp(-1.25 * (fp / fpos) ** 4) * gamma ** np.exp(-((fpos - fp) ** 2) / (2 * sigma ** 2 * fp ** 2))
    out[pos] = shape
    # normalise on a fine reference grid (independent of the caller's grid)
    fr = np.linspace(0.2 * fp, 8 * fp, 20000)
    sr = np.where(fr <= fp, 0.07, 0.09)
    ref = fr ** -5 * np.exp(-1.25 * (fp / fr) ** 4) * gamma ** np.exp(-((fr - fp) ** 2) / (2 * sr ** 2 * fp ** 2))
    m0 = np.trapezoid(ref, fr)
    return out * (hs / 4.0) ** 2 / m0


def jonswap(hs, tp, gamma, seed, ramp, duration, spacing, *, f_cut_factor=6.0, spectra=None) -> HeaveSamples:
    """Irregular platform heave from a JONSWAP spectrum (random phases, deterministic amplitudes).

    Components sit on the FFT grid f_k = k / T_rep with T_rep >= duration, so
    the series is synthesised with one inverse FFT per derivative and its
    variance over T_rep equals the spectrum's m0 exactly (H_s = 4 sqrt(m0)).
    Components above ``f_cut_factor / T_p`` are dropped (they carry < 0.1 % of
    the variance and would only add high-frequency acceleration).  ``spectra``, a dict,
    caches the amplitude spectrum per (H_s, T_p, gamma, grid) across calls (campaigns).

    Parameters
    ----------
    hs : float [m]
        Significant wave height H_s.
    tp : float [s]
        Peak period T_p.
    gamma : float [-]
        Peak enhancement factor.
    seed : int
        Seed of the random phases.
    ramp : float [s]
        Fade-in duration T_r (<= 0: no fade-in).
    duration : float [s]
        Time covered by the samples.
    spacing : float [s]
        Sample spacing (h/2 of the stepper).
    f_cut_factor : float [-]
        Components above ``f_cut_factor / T_p`` are dropped.
    spectra : dict, optional
        Cache of amplitude spectra shared across calls (filled here).
    """
    from scipy import fft as sfft

    n_need = int(math.ceil(duration / spacing)) + 2
    n = sfft.next_fast_len(max(n_need, int(math.ceil(4 * tp / spacing))), real=True)
    T_rep = n * spacing
    f = np.fft.rfftfreq(n, spacing)
    key = (hs, tp, gamma, n, spacing, f_cut_factor)
    amp = None if spectra is None else spectra.get(key)
    if amp is None:
        S = jonswap_spectrum(f, hs, tp, gamma)
        S[f > f_cut_factor / tp] = 0.0
        amp = np.sqrt(2 * S / T_rep)
        if spectra is not None:
            spectra[key] = amp
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 2 * np.pi, size=f.size)
    X = amp * np.exp(1j * phase) * n / 2.0  # irfft scaling: a cos(w t + phi)
    X[0] = 0.0
    if n % 2 == 0:
        X[-1] = 0.0
    w = 2 * np.pi * f
    z = sfft.irfft(X, n)[:n_need]
    dz = sfft.irfft(1j * w * X, n)[:n_need]
    ddz = sfft.irfft(-(w ** 2) * X, n)[:n_need]
    t = np.arange(n_need) * spacing
    z, dz, ddz = _apply_ramp(t, z, dz, ddz, ramp)
    info = {"kind": "jonswap", "hs": hs, "tp": tp, "gamma": gamma, "seed": seed, "ramp": ramp,
            "repeat_period": T_rep}
    return HeaveSamples(spacing, z, dz, ddz, info, kink=ramp_kink(spacing, z, ddz, ramp))


def spectral_hs_tp(z, dt):
    """H_s = 4 std(z) and T_p from a smoothed (Welch) spectrum of a heave series.

    Parameters
    ----------
    z : (n,) array [m]
        Heave series, uniformly sampled.
    dt : float [s]
        Sampling interval.
    """
    from scipy.signal import welch

    z = np.asarray(z, dtype=float)
    nper = min(z.size, int(round(512.0 / dt)))  # ~0.002 Hz resolution
    f, S = welch(z - z.mean(), fs=1.0 / dt, nperseg=nper)
    k = int(np.argmax(S[1:])) + 1
    # parabolic interpolation of the peak
    if 1 <= k < S.size - 1:
        a, b, c = S[k - 1], S[k], S[k + 1]
        den = a - 2 * b + c
        off = 0.5 * (a - c) / den if den != 0 else 0.0
        fpk = f[k] + off * (f[1] - f[0])
    else:
        fpk = f[k]
    return 4.0 * float(np.std(z)), 1.0 / float(fpk)


def read_heave_csv(path, measurement=None) -> tuple[np.ndarray, np.ndarray]:
    """Read a heave file: columns ``t`` [s] and ``heave`` [m], in any shape the measured-run
    reader takes (``docs/contracts/measured-run.md``: any delimiter, decimal comma, header
    case and units, compressed CSV, Parquet, .mat, time in s/ms/ISO timestamps).

    Parameters
    ----------
    path : str or Path
    measurement : Measurement, optional
        The parameter file's ``[measurement]`` table (column mapping, declared units).

    Returns
    -------
    (t, z) : ndarray [s], ndarray [m]
    """

    path = Path(path)
    try:
        missing = not path.exists()
    except OSError:  # e.g. a name too long for the file system: read_series says so
        missing = False
    if missing:
        raise ParameterError(f"heave.path: file not found: {short(path)}")
    cols = getattr(measurement, "columns", None) or {}
    units = getattr(measurement, "units", None) or {}
    s = read_series(path, ("t", "heave"), columns={k: v for k, v in cols.items() if k in ("t", "heave")},
                    units={k: v for k, v in units.items() if k in ("t", "heave")}, what="heave file")
    t, z = s["t"], s["heave"]
    _check_series(t, z, s.source, rows=s.rows)
    return t, z


#: longest hole in a heave record bridged (linearly, with a warning) [s]; longer ones are refused
MAX_HEAVE_GAP = 2.0
#: an interval longer than this many median intervals is a hole
GAP_FACTOR = 1.5
#: a heave sample further than max(SPIKE_MIN, g dt^2, SPIKE_NOISE x noise) from the line through its
#: neighbours is a spike (a sea at <= 1 g moves a sample at most g dt^2 / 2 off that line) [m]
SPIKE_MIN = 0.5
SPIKE_NOISE = 12.0


def _check_series(t, z, src, rows=None):
    """One-line DataError for a heave record that cannot be used as given.

    Too few samples, non-finite values, time not increasing, excursions over 50 m
    (not metres?), a spike (one sample off the line through its neighbours by more than
    max(SPIKE_MIN, g dt^2, SPIKE_NOISE x the noise); it used to end as a diverging stepper
    with the advice "reduce --dt"), or a hole longer than ``max(MAX_HEAVE_GAP, 3 median intervals)``
    (a spline would invent heave there).
    """

    line = (lambda i: int(rows[i])) if rows is not None else (lambda i: f"{int(i) + 1} (data)")
    if t.size < 4:
        raise DataError(f"{src}: column 't': need at least 4 samples, got {t.size}")
    for name, arr in (("t", t), ("heave", z)):
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            raise DataError(f"{src}: column '{name}', row {line(bad[0])}: missing or non-finite value")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        raise DataError(f"{src}: column 't', row {line(back[0] + 1)}: time not strictly increasing "
                        f"({t[back[0]]:g} -> {t[back[0] + 1]:g} s; duplicate or backwards)")
    if np.max(np.abs(z - z[0])) > 50:
        raise DataError(f"{src}: column 'heave': excursions over 50 m — is it in metres?")
    hole = gaps(t, MAX_HEAVE_GAP)
    if hole.size:
        i = hole[0]
        raise DataError(f"{src}: column 't', row {line(i + 1)}: {t[i + 1] - t[i]:.3g} s without heave samples "
                        f"({t[i]:g} -> {t[i + 1]:g} s); holes up to {MAX_HEAVE_GAP:g} s (or 3 sampling "
                        "intervals) are bridged — fill the record or cut it there")
    if z.size >= 5:
        # a spike: one sample far off the line through its neighbours, beyond what a sea (and the noise) makes
        d = np.diff(t)
        dt = float(np.median(d))
        w = d[:-1] / (d[:-1] + d[1:])  # the line through the neighbours, at the sample's own time
        dev = z[1:-1] - ((1.0 - w) * z[:-2] + w * z[2:])
        dev[(d[:-1] > GAP_FACTOR * dt) | (d[1:] > GAP_FACTOR * dt)] = 0.0  # beside a bridged hole: no line
        noise = 1.4826 * float(np.median(np.abs(dev - np.median(dev))))
        limit = max(SPIKE_MIN, G * dt * dt, SPIKE_NOISE * noise)
        bad = np.flatnonzero(np.abs(dev) > limit)
        if bad.size:
            first = bad[bad <= bad[0] + 2]  # a spike also pulls its neighbours' lines: name the worst
            i = int(first[np.argmax(np.abs(dev[first]))]) + 1
            raise DataError(f"{src}: column 'heave', row {line(i)}: a spike of {dev[i - 1]:+.3g} m off its neighbours "
                            f"(more than {limit:.3g} m: a glitch or a dropout value?); remove or fill that sample")


def _bridge(t, z, src):
    """Fill holes longer than GAP_FACTOR median intervals with linear samples (the spline then follows
    the straight line instead of swinging through the hole); logs a warning per record."""
    d = np.diff(t)
    dt = float(np.median(d))
    holes = np.flatnonzero(d > GAP_FACTOR * dt)
    if holes.size == 0:
        return t, z
    log.warning("%s: %d hole(s) in the heave record bridged linearly (longest %.3g s)", src, holes.size,
                float(d[holes].max()))
    ts, zs = [t[: holes[0] + 1]], [z[: holes[0] + 1]]
    for k, i in enumerate(holes):
        n = int(math.ceil(d[i] / dt))
        fill = t[i] + (t[i + 1] - t[i]) * np.arange(1, n) / n
        ts.append(fill)
        zs.append(np.interp(fill, t[i:i + 2], z[i:i + 2]))
        stop = holes[k + 1] + 1 if k + 1 < holes.size else t.size
        ts.append(t[i + 1:stop])
        zs.append(z[i + 1:stop])
    return np.concatenate(ts), np.concatenate(zs)


def from_series(t, z, duration, spacing, src="heave") -> HeaveSamples:
    """Heave from measured samples, pre-processed as the diagnosis' replay does: made uniform, zero-phase
    low-passed at :data:`heavecomp.signals.HEAVE_CUTOFF` and a cubic spline through it, its first filtered
    sample as reference (:data:`PREPROCESSING`).

    Holes of more than 1.5 sampling intervals are first bridged linearly (warning); holes over
    ``max(MAX_HEAVE_GAP, 3 intervals)`` are refused (:func:`_check_series`).

    Parameters
    ----------
    t : (n,) array [s]
        Sample times, strictly increasing.
    z : (n,) array [m]
        Heave samples.
    duration : float [s]
        Time covered by the output samples (at most the record's span).
    spacing : float [s]
        Output sample spacing (h/2 of the stepper).
    src : str
        Name of the record in messages (a file path).
    """
    from scipy.interpolate import CubicSpline

    t = np.asarray(t, dtype=float)
    z = np.asarray(z, dtype=float)
    _check_series(t, z, src)
    t, z = _bridge(t, z, src)
    span = t[-1] - t[0]
    if duration > span + 1e-9:
        raise ParameterError(f"duration {duration:g} s exceeds the heave record's span {span:g} s ({src})")
    # the diagnosis' replay pre-processing (heavecomp.diagnosis.data.heave_filtered): uniform, zero-phase low-pass
    # at HEAVE_CUTOFF (the waves pass unchanged, a measured heave's noise does not drive the plant)
    dt = float(np.median(np.diff(t)))
    tu = np.arange(t[0], t[-1] + 1e-9 * dt, dt)
    zf = flat_zero_phase(np.interp(tu, t, z), 1.0 / dt, HEAVE_CUTOFF)
    cs = CubicSpline(tu - t[0], zf - zf[0])
    tg = np.arange(int(math.ceil(duration / spacing)) + 1) * spacing
    tg = np.minimum(tg, span)
    return HeaveSamples(spacing, cs(tg), cs(tg, 1), cs(tg, 2), {"kind": "file", "source": src, "span": span,
                                                                 "preprocessing": PREPROCESSING})


def make_heave(heave, duration, spacing, base_dir=None, measurement=None) -> HeaveSamples:
    """Samples for a :class:`heavecomp.params.cmc.Heave` table.

    Parameters
    ----------
    heave : Heave
        The parameter file's ``[heave]`` table (:class:`heavecomp.params.cmc.Heave`; sine, jonswap
        or file).
    duration : float [s]
        Time covered by the samples.
    spacing : float [s]
        Sample spacing (h/2 of the stepper).
    base_dir : str or Path, optional
        Folder a relative heave file path is resolved against (the parameter file's).
    measurement : Measurement, optional
        The file's ``[measurement]`` table, for a heave file's column names and units.
    """
    if heave is None:
        raise ParameterError("[heave]: missing table (simulate needs a heave input: sine, jonswap or file)")
    if heave.kind == "sine":
        return sine(heave.amplitude, heave.period, heave.ramp, duration, spacing)
    if heave.kind == "jonswap":
        return jonswap(heave.hs, heave.tp, heave.gamma, heave.seed, heave.ramp, duration, spacing)
    path = Path(heave.path)
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    t, z = read_heave_csv(path, measurement)
    return from_series(t, z, duration, spacing, src=str(path))


def load_waverider(path, start_hours=0.0):
    """Buoy heave from the Datawell Waverider CSV (``heavecomp.data.WAVERIDER``).

    Returns ``(t, z)`` with t from 0 [s] and z the sea-surface heave [m]; rows
    with a bad signal-quality flag or non-finite heave are dropped.

    Parameters
    ----------
    path : str or Path
        The Waverider CSV (columns ``unix_time_s``, ``heave_m``, optional ``sig_qual``).
    start_hours : float [h]
        Rows before this time from the record's start are dropped.
    """
    data = np.genfromtxt(path, delimiter=",", names=True)
    t = data["unix_time_s"]
    z = data["heave_m"]
    ok = np.isfinite(t) & np.isfinite(z)
    if "sig_qual" in data.dtype.names:
        ok &= data["sig_qual"] == 0
    t, z = t[ok], z[ok]
    order = np.argsort(t, kind="stable")
    t, z = t[order], z[order]
    keep = np.concatenate([[True], np.diff(t) > 0])
    t, z = t[keep] - t[0], z[keep]
    sel = t >= start_hours * 3600
    return t[sel] - t[sel][0], z[sel]


def vessel_heave(t, z, natural_period=22.0, damping_ratio=0.15, dt=None):
    """Platform heave from sea-surface heave through a second-order heave RAO.

    ``H(jw) = w_n^2 / (w_n^2 - w^2 + 2 j zeta w_n w)`` with ``w_n = 2 pi / natural_period``:
    a generic semi-submersible (heave natural period ~20-25 s), which passes
    swell, attenuates wind sea (|H| ~ 0.4 at 12 s for the defaults) and adds its
    phase lag.  An assumption, not a particular vessel — supply the real RAO
    for a real rig.  The record is first resampled to a uniform grid ``dt``
    (default: its median sampling interval).

    Returns ``(t_uniform, z_platform)``.

    Parameters
    ----------
    t : (n,) array [s]
        Sample times of the sea-surface record.
    z : (n,) array [m]
        Sea-surface heave.
    natural_period : float [s]
        Heave natural period of the vessel.
    damping_ratio : float [-]
        Damping ratio zeta of the heave RAO.
    dt : float [s], optional
        Uniform grid spacing (default the record's median sampling interval).
    """
    t = np.asarray(t, dtype=float)
    z = np.asarray(z, dtype=float)
    if dt is None:
        dt = float(np.median(np.diff(t)))
    tu = np.arange(t[0], t[-1] + 1e-9, dt)
    zu = np.interp(tu, t, z)
    n = tu.size
    nf = 2 * n  # zero padding against wrap-around
    Z = np.fft.rfft(zu - zu.mean(), nf)
    w = 2 * np.pi * np.fft.rfftfreq(nf, dt)
    wn = 2 * np.pi / natural_period
    H = wn ** 2 / (wn ** 2 - w ** 2 + 2j * damping_ratio * wn * w)
    zp = np.fft.irfft(Z * H, nf)[:n]
    return tu - tu[0], zp
