"""Data quality of a measured run: corruption that passes the contract's per-cell checks.

:func:`heavecomp.diagnosis.data.check_run` refuses what is wrong cell by cell (a missing column, a
non-numeric or non-finite cell, time going backwards, a unit a factor off).  A corrupted log can pass
all of that and still be read with confidence: a frozen sensor, a spike, a time base at the wrong
scale, a clock skew between channels, a torn last row, a WOB in the wrong unit that happens to be a
plausible number.  :func:`assess` is a pure function of the checked run and the nominal parameters;
it raises :class:`~heavecomp.errors.DataError` naming the column where the log cannot describe the
rig at all (*refusals*), and otherwise returns a :class:`Quality` with one warning per problem and a
``confidence_cap`` that :func:`apply_quality` applies to the verdict.  :func:`checked` runs it and
returns the cleaned run (spikes and frozen stretches excluded like dropouts, a torn last row
dropped) with the quality attached (``run.quality``).

Every threshold is a physical argument, not a fit to the reproducers (``docs/contracts/measured-run.md``,
section *Corrupted logs*):

=================  ==================================================================  ===============
check              criterion                                                           outcome
=================  ==================================================================  ===============
torn last row      the last sample off the line through the two before by              row dropped,
                   ``TORN_NOISE`` robust second-difference sigmas (a row cut           warning
                   mid-number loses digits; dropping a row costs nothing)
spike              one sample departs from the median of itself and its neighbours     sample excluded,
                   by > ``SPIKE_NOISE`` x the channel's sample-to-sample scale and     warning, cap low
                   > ``SPIKE_SPREAD`` x the channel's 1-99 % range
frozen channel     the same value repeated exactly for > ``FROZEN_PERIODS`` dominant  excluded, cap low;
                   heave periods (>= ``FROZEN_MIN_S``)                                 refused beyond
                                                                                       ``MAX_MISSING``
impossible         pressure below vacuum or above ``MAX_PRESSURE_RATIO`` p_0; stroke  refused
magnitude          range over ``STROKE_MAX`` (the longest compensator stroke built);
                   heave range over 2 x 15 m; |WOB| over ``MAX_WOB_RATIO`` x the
                   suspended weight
WOB mean           mean above the lower mass's weight m_b g or <= 0 (the string would  refused
                   push / the bit is off bottom)
                   mean more than ``WOB_MEAN_FACTOR`` x off W_0 (another operating     warning, cap low
                   point than the nominal file describes)
time base          dominant heave period outside ``WAVE_PERIOD`` (3-25 s); the WOB's   warning, cap low
                   resonance more than ``MODE_RATIO`` x off the rig's mode
clock skew         heave -> stroke / pressure cross-correlation lag over               warning, cap low
                   ``MAX_SKEW_S`` (the largest sensor lag the diagnosis models), with
                   the correlation at lag 0 clearly weaker (``ZERO_LAG_SHARE``)
quantised          over ``QUANT_ZERO_SHARE`` of consecutive samples repeat exactly     warning; its
                   and ``QUANT_GRID_SHARE`` of the samples lie on one grid of step q   noise floor
                   (:func:`quantum`): the reading's error is q^2/12, which the         includes q^2/12
                   difference estimate of the noise cannot see (it reads ~0)          (no cap)
hum                a spectral line below the wave band (>= 3 cycles in the log, under  warning; its rms
                   1/3 of the heave's mean frequency) standing ``HUM_PROMINENCE`` x   is part of the
                   above its neighbours' median in one output channel and in no other  channel's noise
                   channel (:func:`hum_line`): mains hum aliased by the logger, no     floor (no cap)
                   plant response (the plant answers a heave line in every channel)
=================  ==================================================================  ===============
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from heavecomp.errors import DataError
from heavecomp.diagnosis.policy import DEFAULT as POLICY
from heavecomp.io.series import UNITS
from heavecomp.params.plausibility import HEAVE_MIN, natural_frequencies

log = logging.getLogger(__name__)

G = 9.81  #: gravity [m/s^2] (contract value)
P_ATM = 101325.0  #: atmospheric pressure [Pa]
MAX_MISSING = 0.2  #: as :data:`heavecomp.diagnosis.data.MAX_MISSING`: largest excluded share of a channel
CONFIDENCE = ("low", "medium", "high")  #: verdict confidences, lowest first

# ---- spikes: one-sample departures that no plant motion makes
SPIKE_NOISE = 30.0  #: spike margin in robust sample-to-sample standard deviations of the channel [-]
SPIKE_SPREAD = 0.25  #: spike margin as a share of the channel's 1-99 % range [-]
TORN_NOISE = 30.0  #: torn last row: off the line through the two samples before by this many robust second-difference sigmas [-]
TORN_SPREAD = 1e-3  #: ... and by more than this share of the channel's 1-99 % range (a noise-free channel) [-]
# ---- frozen sensors
FROZEN_PERIODS = 2.0  #: a live channel changes within this many dominant heave periods [-]
FROZEN_MIN_S = 10.0  #: ... and never stays exactly constant this long [s]
# ---- impossible magnitudes
STROKE_MAX = 7.62  #: longest compensator stroke built (25 ft) [m]
HEAVE_MAX = 15.0  #: largest platform heave amplitude (``heave.amplitude``'s bound) [m]
MAX_PRESSURE_RATIO = 10.0  #: largest main-cylinder pressure over p_0 [-]
MAX_WOB_RATIO = 3.0  #: largest |WOB| over the suspended weight (M_c + m_b) g [-]
WOB_MEAN_FACTOR = 2.0  #: a mean WOB outside [W_0 / f, W_0 f] is another operating point [-]
# ---- time base
WAVE_PERIOD = (3.0, 25.0)  #: plausible dominant (mean, T_m01) period of a platform heave [s]
MODE_RATIO = 1.5  #: largest ratio of the WOB resonance's frequency to the nominal mode's [-]
MODE_PROMINENCE = 5.0  #: a resonance is read only when it stands this far above the band's median [-]
# ---- clock skew
MAX_SKEW_S = 3.0  #: largest sensor lag (``sensor_delay.delay``'s bound) [s]
MIN_CORRELATION = 0.5  #: a lag is read only from a cross-correlation peak at least this strong [-]
#: ... and only when the correlation at lag 0 is weaker than this share of the peak's [-]: a regular heave
#: correlates (with the opposite sign) as well half a period away, a skewed clock's channel does not at 0
ZERO_LAG_SHARE = 0.8
# ---- quantisation
#: a channel whose consecutive samples repeat exactly this often is read on a grid coarse against its noise:
#: with white noise of sigma >= 1.4 q on a grid of step q the share is under 0.2 (two samples' difference
#: has sigma 2 sigma >= 2.8 q, and it rounds to 0 with probability about q / (2.8 q sqrt(2 pi)) = 0.14), and
#: there q^2/12 adds 4 % to the noise's variance at most; above it the difference estimate of the noise
#: (:func:`heavecomp.diagnosis.data.noise_floor`) reads the grid, not the noise (a pressure on a 0.25 bar grid
#: with 2 kPa of noise read 51 Pa, issue 30)
QUANT_ZERO_SHARE = 0.2
#: ... and this share of its samples lies on one grid (within ``QUANT_TOL`` of a step): a frozen stretch
#: repeats too, but the rest of a live, unquantised channel is off every grid [-]
QUANT_GRID_SHARE = 0.99
QUANT_TOL = 0.01  #: how far from a grid line [steps] a quantised sample may lie (the text of a CSV, float rounding) [-]
# ---- hum: a line in one channel's spectrum that no other channel shares
#: a periodogram bin of a broadband signal exceeds the median of its neighbours by a factor x with
#: probability 2^-x (chi-square with 2 degrees of freedom): 30 x is a false line once in 1e9 bins; a
#: sinusoid of amplitude A over a log of T s stands (A^2 T / 4) / (the background's density) above it
HUM_PROMINENCE = 30.0
#: ... and the other channels show no line within a bin of it (a plant response to a line in the heave
#: would be in every channel): at most this many times their neighbours' median [-]
HUM_OTHER = 10.0
HUM_CYCLES = 3.0  #: a hum is read only at frequencies with this many cycles in the log [-]
HUM_WAVE = 1.0 / 3.0  #: ... and below this share of the heave's mean frequency 1/T_m01 (under the wave band) [-]
CHANNELS = ("heave", "stroke", "pressure", "wob")


@dataclasses.dataclass
class Quality:
    """What :func:`assess` found.

    Attributes
    ----------
    issues : list of dict
        One per problem: ``kind`` (``spike``, ``torn``, ``frozen``, ``wob_setpoint``, ``time_base``,
        ``clock_skew``), ``column``, ``message`` (one line naming the column), ``cap`` (the largest
        confidence it allows, or None).
    exclude : dict of str to ndarray of int
        Sample indices per column to exclude (treated as dropouts).
    drop_last : bool
        The last row is torn: drop it.
    """

    issues: list = dataclasses.field(default_factory=list)
    exclude: dict = dataclasses.field(default_factory=dict)
    drop_last: bool = False
    #: channel -> rms [SI] of a reading artefact that is part of the channel's noise floor and that the
    #: difference estimate of the noise cannot see (a hum: a slow line)
    reading_noise: dict = dataclasses.field(default_factory=dict)

    @property
    def warnings(self) -> list:
        return [i["message"] for i in self.issues]

    @property
    def confidence_cap(self):
        """The lowest cap of any issue (``"low"``, ...), or None when nothing caps the verdict."""
        caps = [i["cap"] for i in self.issues if i.get("cap")]
        return min(caps, key=CONFIDENCE.index) if caps else None

    def to_json(self) -> dict:
        return {"confidence_cap": self.confidence_cap,
                "issues": [{k: v for k, v in i.items()} for i in self.issues],
                "reading_noise": dict(self.reading_noise)}


def _issue(q, kind, column, message, cap="low"):
    q.issues.append({"kind": kind, "column": column, "message": f"column '{column}': {message}", "cap": cap})


def _liner(rows):
    """Sample index -> file line (``rows`` from the reader; default: header on line 1, one sample a line)."""
    return (lambda i: int(rows[i])) if rows is not None else (lambda i: int(i) + 2)


def _uniform(t, y):
    ok = np.isfinite(y)
    dt = float(np.median(np.diff(t)))
    tu = np.arange(t[0], t[-1] + 1e-9 * dt, dt)
    return tu, np.interp(tu, t[ok], y[ok]) if ok.sum() >= 2 else np.zeros_like(tu)


def mean_period(t, z) -> float:
    """Spectral mean period T_m01 = m0 / m1 [s] of a heave (the band 0.02-1 Hz, Welch spectrum).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample (not necessarily uniform; resampled to the median step).
    z : numpy.ndarray [m]
        Heave at ``t``; NaN where missing.
    """
    from scipy.signal import welch

    tu, zu = _uniform(t, z)
    fs = 1.0 / (tu[1] - tu[0])
    n = int(min(zu.size, max(64, 120.0 * fs)))
    f, P = welch(zu - zu.mean(), fs, nperseg=n)
    m = (f >= 0.02) & (f <= 1.0)
    m1 = float(np.sum(f[m] * P[m]))
    return float(np.sum(P[m]) / m1) if m1 > 0 else math.inf


def spikes(y, last=True):
    """Indices of one-sample spikes of a channel (module table), and whether the last sample is one.

    A sample is a spike when it departs from the median of itself and its two neighbours (the last
    sample: from the one before) by more than ``SPIKE_NOISE`` robust standard deviations of the
    channel's sample-to-sample change *and* by more than ``SPIKE_SPREAD`` of its 1-99 % range.  A
    median of three keeps steps (a stick-slip breakaway) and removes a lone sample.  A plant motion
    sampled at >= 6 samples per period of the rig's fastest mode (0.44 / 1.8 Hz for paper A, 10 Hz
    logs and up) moves a lone sample off that median by at most (1 - cos(2 pi / 6)) = 1/2 of its own
    amplitude, a quarter of the range at most for a mode as large as the whole channel.

    Parameters
    ----------
    y : array_like [unit of the channel]
        One channel's samples; NaN where missing (not tested).
    last : bool
        Also test whether the last sample is a torn row.
    """
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    if ok.sum() < 10:
        return np.array([], dtype=int), False
    yv = y[ok]
    idx = np.flatnonzero(ok)
    d = np.diff(yv)
    scale = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(2.0)
    lo, hi = np.percentile(yv, [1.0, 99.0])
    margin = max(SPIKE_NOISE * scale, SPIKE_SPREAD * float(hi - lo))
    med = np.median(np.stack([yv[:-2], yv[1:-1], yv[2:]]), axis=0)
    r = np.abs(yv[1:-1] - med)
    hit = list(idx[1:-1][r > margin])
    if abs(yv[0] - yv[1]) > margin and abs(yv[1] - yv[2]) <= margin:
        hit.insert(0, idx[0])
    # the last row: a file cut mid-write loses digits; dropping one row costs nothing, so the test is the
    # noise's: the last sample off the line through the two before by TORN_NOISE robust second differences
    d2 = np.diff(yv, 2)
    s2 = 1.4826 * float(np.median(np.abs(d2 - np.median(d2))))
    off = abs(yv[-1] - (2 * yv[-2] - yv[-3]))
    floor = max(TORN_NOISE * s2, TORN_SPREAD * float(hi - lo))  # a tear under 0.1 % of the range does no harm
    torn = last and off > floor and abs(d2[-2]) <= floor
    return np.asarray(hit[:-1] if hit and hit[-1] == idx[-2] and torn else hit, dtype=int), \
        bool(torn and idx[-1] == y.size - 1)


def quantum(y) -> float:
    """The step q of a channel read on a grid that is coarse against its noise, 0.0 when it is not (module
    table: over ``QUANT_ZERO_SHARE`` of consecutive samples repeat exactly and ``QUANT_GRID_SHARE`` of the
    samples lie on the grid through the first sample with step q, q the smallest change between samples).

    The reading's error is then uniform over one step (variance q^2/12 when the signal or its noise crosses
    grid lines at random), which a noise estimate from differences of samples cannot see: most differences
    are exactly 0.  A finer grid (a 16-bit logger, a CSV's last digit) returns 0.0: the noise dithers it and
    the difference estimate already holds its share.

    Parameters
    ----------
    y : array_like [unit of the channel]
        One channel's samples; NaN where missing (left out).
    """
    y = np.asarray(y, dtype=float)
    y = y[np.isfinite(y)]
    if y.size < 10:
        return 0.0
    d = np.abs(np.diff(y))
    if np.mean(d == 0.0) < QUANT_ZERO_SHARE or not np.any(d > 0.0):
        return 0.0
    nz = d[d > 0.0]
    step = float(np.median(nz[nz <= 1.5 * nz.min()]))  # the smallest change, robust to float rounding
    r = (y - y[0]) / step
    on = np.abs(r - np.round(r)) <= QUANT_TOL
    return step if np.mean(on) >= QUANT_GRID_SHARE else 0.0


def frozen_runs(y, min_len):
    """(start, stop) index pairs of stretches where ``y`` repeats one value exactly for >= ``min_len`` samples.

    Parameters
    ----------
    y : array_like [unit of the channel]
        One channel's samples.
    min_len : int
        Fewest samples of a repeated value that count as frozen.
    """
    y = np.asarray(y, dtype=float)
    same = np.concatenate([[False], (np.diff(y) == 0.0) & np.isfinite(y[1:])])
    out = []
    m = np.concatenate([[0], same.astype(int), [0]])
    dm = np.diff(m)
    for a, b in zip(np.flatnonzero(dm == 1), np.flatnonzero(dm == -1)):
        if b - (a - 1) >= min_len:
            out.append((a - 1, b))
    return out


def _lag(t, a, b, max_lag):
    """(lag [s] of b behind a at the largest |normalised cross-correlation|, that correlation, the
    |correlation| at lag 0)."""
    tu, au = _uniform(t, a)
    _, bu = _uniform(t, b)
    dt = tu[1] - tu[0]
    au, bu = au - au.mean(), bu - bu.mean()
    n = au.size
    k = int(min(max_lag / dt, n // 3))
    if k < 1 or not (au.std() > 0 and bu.std() > 0):
        return 0.0, 0.0, 0.0
    nfft = 1 << int(math.ceil(math.log2(2 * n)))
    cc = np.fft.irfft(np.conj(np.fft.rfft(au, nfft)) * np.fft.rfft(bu, nfft), nfft)
    lags = np.concatenate([np.arange(0, k + 1), np.arange(-k, 0)])
    vals = np.concatenate([cc[:k + 1], cc[-k:]]) / (n - np.abs(lags))  # unbiased
    vals = vals / (au.std() * bu.std())
    i = int(np.argmax(np.abs(vals)))
    return float(lags[i] * dt), float(abs(vals[i])), float(abs(vals[0]))


def _mode_peak(t, w, f_mode, f_wave):
    """Frequency [Hz] of the WOB's resonance near ``f_mode`` (the largest of f^2 x PSD between the wave
    band's edge and 3.5 f_mode) when it stands ``MODE_PROMINENCE`` x above the band's median, else None."""
    from scipy.signal import welch

    tu, wu = _uniform(t, w)
    fs = 1.0 / (tu[1] - tu[0])
    n = int(min(wu.size // 4, max(64, 60.0 * fs)))
    if n < 64:
        return None
    f, P = welch(wu - wu.mean(), fs, nperseg=n)
    lo = max(f_mode / (MODE_RATIO * 1.7), 2.0 * f_wave)
    hi = min(3.5 * f_mode, 0.4 * fs)
    m = (f >= lo) & (f <= hi)
    if m.sum() < 8:
        return None
    s = P[m] * f[m] ** 2
    i = int(np.argmax(s))
    if i in (0, s.size - 1) or s[i] < MODE_PROMINENCE * float(np.median(s)):
        return None
    return float(f[m][i])


def assess(run, params=None, *, rows=None) -> Quality:
    """Look for corruption in a checked :class:`~heavecomp.diagnosis.data.MeasuredRun` (module table).

    Parameters
    ----------
    run : MeasuredRun
        As :func:`heavecomp.diagnosis.data.check_run` returns it (times from 0 s, NaN where missing).
    params : CMCParams, optional
        The nominal parameters; the checks against the operating point and the rig's modes need them.
    rows : array of int, optional
        File line of each sample, for messages (default: header on line 1, one sample a line).

    Returns
    -------
    Quality

    Raises
    ------
    DataError
        One line naming the column where the log cannot be the rig's (impossible magnitudes, a WOB
        mean the lower mass cannot make, a channel frozen or spiked over more than ``MAX_MISSING``).
    """
    src = run.source
    line = _liner(rows)
    t = np.asarray(run.t, dtype=float)
    q = Quality()
    cols = {c: np.array(run[c], dtype=float) for c in CHANNELS if c in run.columns}  # the channels the log has
    t, cols = _torn_and_spikes(q, t, cols, line)
    _sample_rate(t, params, src)
    T_wave = mean_period(t, cols["heave"])
    steps = _quantised(q, cols)
    _frozen(q, t, {c: y for c, y in cols.items() if c not in steps}, T_wave, line, src)
    _magnitudes(q, cols, params, src, wob_from=(getattr(run, "measurement", None) or {}).get("wob_from"))
    if not _still(q, cols["heave"]):
        _time_base(q, t, cols.get("wob"), T_wave, params)
    _clock_skew(q, t, cols)
    _hum(q, t, cols, T_wave)
    q.exclude = {c: np.array(sorted(s), dtype=int) for c, s in q.exclude.items() if s}
    return q


def _torn_and_spikes(q: Quality, t, cols: dict, line) -> tuple:
    """A torn last row (dropped) and spikes (excluded) in every channel; returns ``(t, cols)`` without the
    dropped row and with the spikes as NaN.

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    t : numpy.ndarray
        Times [s].
    cols : dict
        Channel -> samples [SI] (copies: changed in place).
    line : callable
        Sample index -> the file's line number, for messages.
    """
    n = t.size
    for c in cols:
        hit, torn = spikes(cols[c])
        if torn:
            q.drop_last = True
            _issue(q, "torn", c, f"row {line(n - 1)} (the last) reads {cols[c][-1]:.6g} against "
                                 f"{cols[c][-2]:.6g} before: torn mid-number? the row is dropped", cap=None)
        if hit.size:
            q.exclude.setdefault(c, set()).update(int(i) for i in hit)
            shown = ", ".join(f"row {line(int(i))} = {cols[c][i]:.4g}" for i in hit[:3])
            _issue(q, "spike", c, f"{hit.size} spike(s) ({shown}{', ...' if hit.size > 3 else ''}) departing from "
                                  "their neighbours by more than the channel's range allows: excluded, confidence low")
    last = n - 1 if q.drop_last else n
    for c, s in q.exclude.items():
        cols[c][sorted(s)] = np.nan
    if q.drop_last:
        t = t[:-1]
        cols = {c: y[:-1] for c, y in cols.items()}
        q.exclude = {c: {i for i in s if i < last} for c, s in q.exclude.items()}
    return t, cols


def _frozen(q: Quality, t, cols: dict, T_wave: float, line, src: str) -> None:
    """Frozen stretches (a value repeated exactly over more than ``FROZEN_PERIODS`` wave periods):
    excluded with confidence low, or refused for the heave or beyond ``MAX_MISSING``.

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    t : numpy.ndarray
        Times [s].
    cols : dict
        Channel -> samples [SI] (frozen stretches set to NaN in place).
    T_wave : float
        The heave's mean period [s] (NaN when unknown).
    line : callable
        Sample index -> the file's line number, for messages.
    src : str
        The log's name, for messages.
    """
    dt = float(np.median(np.diff(t)))
    per = T_wave if math.isfinite(T_wave) else WAVE_PERIOD[1]
    min_len = int(math.ceil(max(FROZEN_MIN_S, FROZEN_PERIODS * min(max(per, WAVE_PERIOD[0]), WAVE_PERIOD[1])) / dt))
    for c in cols:
        runs_ = frozen_runs(cols[c], min_len)
        if not runs_:
            continue
        k = sum(b - a for a, b in runs_)
        a, b = max(runs_, key=lambda r: r[1] - r[0])
        what = (f"{cols[c][a]:.6g} repeated exactly from row {line(a)} for {t[min(b, t.size - 1)] - t[a]:.1f} s"
                f"{f' ({len(runs_)} stretches, {k} samples)' if len(runs_) > 1 else ''}")
        missing = (np.isnan(cols[c]).sum() + k) / t.size
        if c == "heave" or missing > MAX_MISSING:
            raise DataError(f"{src}: column '{c}': frozen: {what} — a stuck sensor or logger "
                            + ("(the heave is the replay's input)" if c == "heave" else
                               f"({100 * missing:.0f} % of the channel unusable, at most {100 * MAX_MISSING:.0f} %)"))
        for a, b in runs_:
            q.exclude.setdefault(c, set()).update(range(a, b))
            cols[c][a:b] = np.nan
        _issue(q, "frozen", c, f"frozen: {what} (a live channel changes within {FROZEN_PERIODS:g} wave periods): "
                               "excluded, confidence low")


def _quantised(q: Quality, cols: dict) -> dict:
    """Channels read on a coarse grid (:func:`quantum`): a warning naming the step and the noise floor the
    diagnosis uses (:func:`heavecomp.diagnosis.data.noise_floor` includes q^2/12); no cap (the floor is
    corrected, nothing is excluded).  Returns ``{channel: step}``: a quantised channel repeats values while
    its signal moves less than a step, which is no frozen sensor (it is left out of that check).

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    cols : dict
        Channel -> samples [SI].
    """
    steps = {}
    for c, y in cols.items():
        step = quantum(y)
        if step > 0.0:
            steps[c] = step
            q.issues.append({"kind": "quantised", "column": c, "step": step,
                             "message": f"column '{c}': read on a grid of {step:.4g} (SI): a reading error of "
                                        f"{step / math.sqrt(12.0):.4g} rms (step/sqrt(12)) is part of its noise floor",
                             "cap": None})
    return steps


def _still(q: Quality, z) -> bool:
    """A heave at its sensor's noise level (no sea): said as such (confidence low), not as a time base at the
    wrong scale, which its noise's "period" suggested.  The heave's significant height 4 std under
    ``HEAVE_MIN`` (:mod:`heavecomp.params.plausibility`: what a motion reference unit resolves) is no heave.

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    z : numpy.ndarray
        Heave samples [m].
    """
    h = 4.0 * float(np.nanstd(z))
    if h >= HEAVE_MIN:
        return False
    _issue(q, "no_heave", "heave", f"no heave motion: its significant height (4 std) is {1e3 * h:.3g} mm, under the "
                                   f"{100 * HEAVE_MIN:g} cm a motion reference unit resolves (a calm sea): nothing moved "
                                   "the compensator, the log shows the sensors' noise; confidence low")
    return True


def hook_load_error(src: str, wm: float, wob_from: dict, W0: float, how: str) -> DataError:
    """The one line for a WOB derived from the hook load (``wob_from``: WOB = string weight - hook load) whose
    mean ``wm`` [N] is ``how`` (against the set-point ``W0`` [N]): it names the hook load and the string weight,
    not a 'wob' column the log lacks, and the hook load's likely unit (:func:`_hook_load_unit`).

    Parameters
    ----------
    src : str
        The log's name.
    wm : float [N]
        The derived WOB's mean.
    wob_from : dict
        The conversion (``string_weight_N``).
    W0 : float [N]
        The WOB set-point.
    how : str
        How the mean is wrong (e.g. ``"not positive"``).
    """
    return DataError(f"{src}: column 'hook_load': the WOB it gives (measurement.string_weight "
                     f"{wob_from.get('string_weight_N', math.nan):.4g} N - hook_load) has mean {wm:.4g} N, {how} "
                     f"(nominal W_0 = {W0:.4g} N): the hook load in another unit, or measurement.string_weight "
                     f"wrong{_hook_load_unit(wm, wob_from)}", option="units")


def _hook_load_unit(wm: float, wob_from: dict) -> str:
    """``; it looks like t`` when the hook load, read in another force unit, would give a WOB near the
    string weight less the set-point; ``; it looks like N`` when it reads a force unit's factor times the string
    weight (a column in N declared in that unit); empty otherwise."""
    sw = float(wob_from.get("string_weight_N", math.nan))
    hl = sw - wm  # the hook load as read [N]
    for unit in ("kn", "t", "kip", "klbf", "lbf"):
        kind, factor, _ = UNITS[unit]
        if kind == "force" and hl > 0 and abs(hl * factor / sw - 1.0) < 0.5:
            return f"; it looks like {unit if unit != 'kn' else 'kN'}: declare its unit, hook_load={unit if unit != 'kn' else 'kN'}"
        if kind == "force" and hl > 0 and abs(hl / (factor * sw) - 1.0) < 0.5:
            return (f"; it reads {hl / sw:.4g} x the string weight, as a column in N declared in "
                    f"{unit if unit != 'kn' else 'kN'} would: declare its unit, hook_load=N")
    return ""


def _magnitudes(q: Quality, cols: dict, params, src: str, wob_from: dict | None = None) -> None:
    """Channel magnitudes no rig makes (refused), and a WOB mean far from the set-point (confidence low).

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    cols : dict
        Channel -> samples [SI].
    params : CMCParams or None
        The nominal parameters (the checks against the operating point need them).
    src : str
        The log's name, for messages.
    """
    z, s, p, w = (cols.get(c) for c in ("heave", "stroke", "pressure", "wob"))  # None: a channel the log lacks
    if np.nanmax(z) - np.nanmin(z) > 2 * HEAVE_MAX:
        raise DataError(f"{src}: column 'heave': range {np.nanmax(z) - np.nanmin(z):.4g} m is more than a platform heaves "
                        f"(at most {2 * HEAVE_MAX:g} m crest to trough)")
    if "stroke" in cols and np.nanmax(s) - np.nanmin(s) > STROKE_MAX:
        raise DataError(f"{src}: column 'stroke': range {np.nanmax(s) - np.nanmin(s):.4g} m is longer than any "
                        f"compensator's stroke (at most {STROKE_MAX:g} m, 25 ft) — wrong unit (cm, in)?")
    if "pressure" in cols and np.nanmin(p) < -P_ATM:
        raise DataError(f"{src}: column 'pressure': {np.nanmin(p):.4g} Pa (gauge) is below vacuum (-{P_ATM:g} Pa)")
    if params is None:
        return
    c_, ds, op = params.compensator, params.drill_string, params.operating_point
    p0, W0 = params.p0, op.wob_setpoint
    if "pressure" in cols and np.nanmax(p) > MAX_PRESSURE_RATIO * p0:
        raise DataError(f"{src}: column 'pressure': {np.nanmax(p):.4g} Pa is over {MAX_PRESSURE_RATIO:g} x the "
                        f"operating pressure p_0 = {p0:.4g} Pa (the gas spring cannot compress that far)")
    weight = (c_.moving_mass + ds.lower_mass) * G
    if w is None:
        return
    if np.nanmax(np.abs(w)) > MAX_WOB_RATIO * weight:
        raise DataError(f"{src}: column 'wob': |WOB| reaches {np.nanmax(np.abs(w)):.4g} N, over {MAX_WOB_RATIO:g} x "
                        f"the suspended weight (M_c + m_b) g = {weight:.4g} N")
    wm = float(np.nanmean(w))
    mbg = ds.lower_mass * G
    if (wm >= mbg or wm <= 0) and wob_from:  # the WOB is the string weight less the hook load: name those
        raise hook_load_error(src, wm, wob_from, W0, f"above the lower mass's weight m_b g = {mbg:.4g} N"
                              if wm > 0 else "not positive")
    if wm >= mbg or wm <= 0:
        raise DataError(f"{src}: column 'wob': mean {wm:.4g} N is "
                        + (f"above the lower mass's weight m_b g = {mbg:.4g} N (the drill string would push; "
                           f"nominal W_0 = {W0:.4g} N) — wrong unit or unit declaration (kN as t?)" if wm > 0 else
                           f"not positive (the bit is off bottom; nominal W_0 = {W0:.4g} N)")
                        + " or wrong parameter file?")
    if not W0 / WOB_MEAN_FACTOR <= wm <= W0 * WOB_MEAN_FACTOR:
        _issue(q, "wob_setpoint", "wob", f"mean {wm:.4g} N is {wm / W0:.2f} x the set-point W_0 = {W0:.4g} N: "
                                        "another operating point than the parameter file's (or a unit): confidence low")


def _sample_rate(t, params, src: str) -> None:
    """Refuse a log sampled too slowly for the rig's fastest mode (``VerdictPolicy.min_samples_per_mode``
    samples a period): its mode aliases onto the waves, and the diagnosis and the monitor would read the
    aliased motion as noise (a 1 Hz log with string damping read ``none``, high).

    Parameters
    ----------
    t : numpy.ndarray
        Times [s].
    params : CMCParams or None
        The nominal parameters (the rig's modes); None: no check.
    src : str
        The log's name, for the message.
    """
    if params is None or t.size < 2:
        return
    modes = [float(f) for f in natural_frequencies(params)[0] if f > 0]
    if not modes:
        return
    rate = 1.0 / float(np.median(np.diff(t)))
    floor = POLICY.min_samples_per_mode * max(modes)
    if rate < floor:
        raise DataError(f"{src}: column 't': sampled at {rate:.3g} Hz, below the {floor:.3g} Hz the rig's fastest "
                        f"mode needs ({max(modes):.3g} Hz from the parameter file, {POLICY.min_samples_per_mode:g} "
                        "samples a period): that mode aliases onto the waves and would be read as noise; log at "
                        f"{floor:.3g} Hz or faster")


def _time_base(q: Quality, t, w, T_wave: float, params) -> None:
    """A time base at the wrong scale: the heave's period outside the sea states', or the WOB resonating
    off every mode of the rig (confidence low).

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    t : numpy.ndarray
        Times [s].
    w : numpy.ndarray
        WOB samples [N].
    T_wave : float
        The heave's mean period [s].
    params : CMCParams or None
        The nominal parameters (the rig's modes).
    """
    if not WAVE_PERIOD[0] <= T_wave <= WAVE_PERIOD[1]:
        _issue(q, "time_base", "t", f"the heave's mean period is {T_wave:.3g} s, outside the {WAVE_PERIOD[0]:g}-"
                                    f"{WAVE_PERIOD[1]:g} s of sea states: time base wrong (scale, unit)? confidence low")
    elif params is not None and w is not None:
        modes = [float(f) for f in natural_frequencies(params)[0] if f > 0]
        f_pk = _mode_peak(t, w, modes[0], 1.0 / T_wave) if modes else None
        near = min(modes, key=lambda f: abs(math.log(f_pk / f))) if f_pk is not None else None
        if near is not None and not 1.0 / MODE_RATIO <= f_pk / near <= MODE_RATIO:  # off every mode of the rig
            _issue(q, "time_base", "t", f"the WOB resonates at {f_pk:.3g} Hz, {f_pk / near:.2f} x the nearest of the rig's "
                                        f"modes ({', '.join(f'{f:.3g}' for f in modes)} Hz from the parameter file): time "
                                        "base at the wrong scale (or the wrong parameter file)? confidence low")


def _clock_skew(q: Quality, t, cols: dict) -> None:
    """Clock skew between channels: stroke and pressure follow the heave through the gas spring, so a
    cross-correlation peak far from zero lag is a clock offset (confidence low).

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    t : numpy.ndarray
        Times [s].
    cols : dict
        Channel -> samples [SI].
    """
    max_lag = min(30.0, 0.25 * float(t[-1] - t[0]))
    lags = {}
    for c in ("stroke", "pressure"):
        if c not in cols:
            continue
        lag, r, r0 = _lag(t, cols["heave"], cols[c], max_lag)
        if r >= MIN_CORRELATION and r0 < ZERO_LAG_SHARE * r:  # a periodic heave correlates at half periods too
            lags[c] = lag
    far = {c: g for c, g in lags.items() if abs(g) > MAX_SKEW_S}
    if far:
        col = "heave" if len(far) == len(lags) == 2 else next(iter(far))
        shown = ", ".join(f"{c} {g:+.2f} s" for c, g in lags.items())
        _issue(q, "clock_skew", col, f"clock skew? offset from the heave by {shown} (cross-correlation peak), more "
                                     f"than any sensor lag ({MAX_SKEW_S:g} s): confidence low")


def _periodogram(t, y):
    """(frequencies [Hz], Hann-windowed periodogram [unit^2/Hz]) of ``y`` at ``t`` less its linear trend."""
    tu, yu = _uniform(t, y)
    yu = yu - np.polyval(np.polyfit(tu - tu[0], yu, 1), tu - tu[0])
    fs = 1.0 / (tu[1] - tu[0])
    w = np.hanning(yu.size)
    P = np.abs(np.fft.rfft(yu * w)) ** 2 / (fs * np.sum(w * w))
    return np.fft.rfftfreq(yu.size, 1.0 / fs), P


def _prominence(P, k, near=2, far=15):
    """Periodogram bin ``k`` over the median of the bins ``near`` + 1 to ``far`` away on either side [-]."""
    idx = np.r_[np.arange(k - far, k - near), np.arange(k + near + 1, k + far + 1)]
    idx = idx[(idx >= 1) & (idx < P.size)]
    bg = float(np.median(P[idx])) if idx.size else 0.0
    return float(P[k] / bg) if bg > 0 else 0.0


def hum_line(t, cols: dict, T_wave: float) -> dict:
    """Lines below the wave band that one output channel has and no other channel shares (module table):
    ``{channel: (frequency [Hz], amplitude [SI], prominence [-])}``.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Time of each sample.
    cols : dict
        Channel -> samples [SI] (the heave and the outputs the log has; NaN where missing).
    T_wave : float [s]
        The heave's mean period (:func:`mean_period`).
    """
    T = float(t[-1] - t[0])
    if not (T > 0 and math.isfinite(T_wave) and T_wave > 0):
        return {}
    spectra = {c: _periodogram(t, y) for c, y in cols.items() if np.isfinite(y).sum() > 64}
    out = {}
    for c in ("stroke", "pressure", "wob"):
        if c not in spectra:
            continue
        f, P = spectra[c]
        band = np.flatnonzero((f >= HUM_CYCLES / T) & (f <= HUM_WAVE / T_wave))
        if band.size == 0:
            continue
        prom = np.array([_prominence(P, int(k)) for k in band])
        i = int(np.argmax(prom))
        k = int(band[i])
        if prom[i] < HUM_PROMINENCE:
            continue
        others = [max(_prominence(spectra[o][1], j) for j in (k - 1, k, k + 1) if 1 <= j < spectra[o][1].size)
                  for o in spectra if o != c and spectra[o][1].size == P.size]
        if others and max(others) > HUM_OTHER:
            continue
        tu, yu = _uniform(t, cols[c])
        X = np.column_stack([np.sin(2 * np.pi * f[k] * tu), np.cos(2 * np.pi * f[k] * tu), np.ones_like(tu),
                             tu - tu[0]])
        coef = np.linalg.lstsq(X, yu, rcond=None)[0]
        out[c] = (float(f[k]), float(math.hypot(coef[0], coef[1])), float(prom[i]))
    return out


def _hum(q: Quality, t, cols: dict, T_wave: float) -> None:
    """A hum (:func:`hum_line`): a warning naming the channel, its frequency and amplitude; its rms joins the
    channel's noise floor (``q.reading_noise``; the replay's output noise), no cap.

    Parameters
    ----------
    q : Quality
        The findings so far, extended in place.
    t : numpy.ndarray
        Times [s].
    cols : dict
        Channel -> samples [SI].
    T_wave : float
        The heave's mean period [s].
    """
    for c, (f, amp, prom) in hum_line(t, cols, T_wave).items():
        rms = amp / math.sqrt(2.0)
        q.reading_noise[c] = float(math.hypot(q.reading_noise.get(c, 0.0), rms))
        q.issues.append({"kind": "hum", "column": c, "frequency": f, "amplitude": amp,
                         "message": f"column '{c}': a line at {f:.3g} Hz ({amp:.4g} SI amplitude, {prom:.0f} x its "
                                    "neighbours) that no other channel has: a reading artefact (mains hum aliased by "
                                    f"the logger?); its rms {rms:.4g} is part of the channel's noise floor",
                         "cap": None})


def cleaned(run, q: Quality):
    """The run with ``q``'s exclusions as dropouts (NaN), its torn last row dropped, ``q``'s warnings
    appended and ``run.quality = q`` (a new :class:`MeasuredRun`; ``run`` is unchanged).

    Parameters
    ----------
    run : MeasuredRun
        The checked run.
    q : Quality
        What :func:`assess` found in it.
    """
    cols = {k: np.array(v, dtype=float) for k, v in run.columns.items()}
    for c, idx in q.exclude.items():
        cols[c][idx] = np.nan
    t = np.asarray(run.t, dtype=float)
    if q.drop_last:
        t = t[:-1]
        cols = {k: v[:-1] for k, v in cols.items()}
    return dataclasses.replace(run, t=t, columns=cols, warnings=list(run.warnings) + q.warnings, quality=q)


def checked(run, params=None, *, rows=None):
    """:func:`assess` then :func:`cleaned`: the run :func:`heavecomp.diagnosis.data.load_run` returns.

    Parameters
    ----------
    run : MeasuredRun
        As :func:`heavecomp.diagnosis.data.check_run` returns it.
    params : CMCParams, optional
        The nominal parameters (:func:`assess`).
    rows : array of int, optional
        File line of each sample, for messages (:func:`assess`).
    """
    return cleaned(run, assess(run, params, rows=rows))


#: the findings that are a channel's reading error, counted in its noise floor (not excluded, no cap)
READING_ARTEFACTS = ("quantised", "hum")


def place_reading_artefacts(verdict: dict, quality) -> dict:
    """A ``none`` verdict on a log whose readings carry artefacts (:data:`READING_ARTEFACTS`: a coarse grid,
    a hum line) names where what differs from an ideal reading lies: ``component: "sensors"`` and
    ``reading_artefacts`` [{kind, column}] (a new dict; otherwise unchanged).  The nominal model explains the
    log once those artefacts are counted as reading error; they are the log's only departure from it, and
    they are in the sensors, not the plant (a pressure read on a 0.25 bar grid with an aliased hum read
    ``inconclusive`` in the gas spring before its floor counted them, issue 30).

    Parameters
    ----------
    verdict : dict
        The diagnosis verdict.
    quality : Quality or None
        The run's quality (``run.quality``); None: unchanged.
    """
    found = [{"kind": i["kind"], "column": i["column"]} for i in getattr(quality, "issues", ()) or ()
             if i.get("kind") in READING_ARTEFACTS]
    if verdict.get("effect") != "none" or not found:
        return verdict
    v = dict(verdict)
    v["component"] = "sensors"
    v["reading_artefacts"] = found
    what = ", ".join(f"{f['kind']} '{f['column']}'" for f in found)
    v["note"] = (f"{v['note']}; " if v.get("note") else "") + (
        f"with the readings' artefacts counted in the noise floor ({what}): the log departs from the nominal model "
        "only in its sensors")
    return v


def apply_quality(verdict: dict, quality) -> dict:
    """The verdict with its confidence at most ``quality.confidence_cap`` (a new dict).

    A capped verdict says so: ``verdict["data_quality"]`` lists the problems' kinds and columns and
    ``confidence_capped_from`` the confidence it had.  ``quality`` None or without a cap: unchanged.

    Parameters
    ----------
    verdict : dict
        The diagnosis verdict (``confidence`` among :data:`CONFIDENCE`).
    quality : Quality or None
        The run's quality (``run.quality``); None: no cap.
    """
    cap = getattr(quality, "confidence_cap", None)
    if cap is None:
        return verdict
    v = dict(verdict)
    was = v.get("confidence", "high")
    v["data_quality"] = [{"kind": i["kind"], "column": i["column"]} for i in quality.issues if i.get("cap")]
    if was in CONFIDENCE and CONFIDENCE.index(was) > CONFIDENCE.index(cap):
        v["confidence"] = cap
        v["confidence_capped_from"] = was
    return v
