"""Measured runs: load and check the CSV contract, derive heave velocity/acceleration.

Contract: ``docs/contracts/measured-run.md`` — columns ``t`` [s], ``heave`` [m],
``stroke`` [m], ``pressure`` [Pa], ``wob`` [N]; optional ``pitch`` [rad] (:data:`ANGLES`: the vessel
angle of ``heave_reference``'s lever arm; units converted like the others, gaps treated like the
heave's, an rms over :data:`MAX_ANGLE_RMS` an error); other columns are carried along.

Treatments (documented in ``docs/diagnosis.md``):

- missing column, non-numeric cell, ``t`` not finite / not strictly increasing:
  :class:`~heavecomp.errors.DataError` naming the column (and row);
- dropouts (empty / NaN cells): a channel more than ``MAX_MISSING`` missing is an
  error; otherwise heave gaps are interpolated linearly for the replay input and
  missing samples of stroke/pressure/wob are excluded from the residuals;
- non-uniform sampling: the replay uses the actual times; spectra and filters
  work on a uniform resampling at the median interval;
- wrong units: magnitudes are compared with the nominal operating point
  (pressure with p_0, WOB with W_0, stroke with heave); a channel off by a
  unit factor (bar, kPa, MPa; kN, tonnes; mm) is an error naming the column and
  the likely unit — never converted silently.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from heavecomp.diagnosis import quality
from heavecomp.effects.spec import correct, reading_effects
from heavecomp.errors import DataError
from heavecomp.simulate.excitation import HeaveSamples
from heavecomp.io.series import MAX_DT_S, gaps, iter_chunks, read_series
from heavecomp.signals import flat_zero_phase

P_ATM = 101325.0  #: atmospheric pressure [Pa] (cmc-reference.md)

log = logging.getLogger(__name__)

#: columns every run must have (contract schema 3: heave is the model's input)
REQUIRED = ("t", "heave")
#: the measured outputs, each optional (contract schema 3: any of them may be missing); the diagnosis works
#: on those present (:attr:`MeasuredRun.sensors`)
CHANNELS = ("wob", "stroke", "pressure")
#: the same channels in contract order (the order of :attr:`MeasuredRun.sensors`, the checks and their warnings)
OUTPUTS = ("stroke", "pressure", "wob")
UNITS = {"t": "s", "heave": "m", "stroke": "m", "pressure": "Pa", "wob": "N"}
#: optional vessel-angle columns [rad] (``heave_reference``'s lever arm): unit-checked, gaps bridged like the heave
ANGLES = ("pitch",)
MAX_ANGLE_RMS = 0.5  #: largest plausible rms of a vessel angle [rad] (28 deg): more is degrees read as radians
#: s of the run the heave reference is read from (after the pre-filter's edge; :func:`heavecomp.diagnosis.start.estimate`)
ZREF_WINDOW = (5.0, 30.0)
MAX_MISSING = 0.2  #: largest tolerated fraction of missing samples per column
MAX_GAP = 2.0      #: longest heave dropout (or hole in the time column) bridged by interpolation [s]
MIN_SAMPLES = 50   #: fewest samples of a run
from heavecomp.signals import HEAVE_CUTOFF  # noqa: E402 - the heave low-pass cut-off [Hz], shared with simulate


@dataclasses.dataclass
class MeasuredRun:
    """A checked measured run: arrays per column (NaN where missing) and notes."""

    t: np.ndarray
    columns: dict
    source: str = "<array>"
    warnings: list = dataclasses.field(default_factory=list)
    #: how the file was read: format, columns, units, conversions (heavecomp.io.series)
    measurement: dict = dataclasses.field(default_factory=dict)
    #: corruption found by :func:`heavecomp.diagnosis.quality.assess` (``load_run``), or None
    quality: object = None

    def __getitem__(self, name):
        if name == "t":
            return self.t
        return self.columns[name]

    @property
    def sensors(self) -> tuple:
        """The measured channels the run has, in contract order (contract schema 3): a column with at least
        one finite sample (heave, required, is always one after :func:`check_run`)."""
        return tuple(c for c in ("heave",) + OUTPUTS if c in self.columns and np.isfinite(self.columns[c]).any())

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    @property
    def dt(self) -> float:
        """Median sampling interval [s]."""
        return float(np.median(np.diff(self.t)))

    @property
    def uniform(self) -> bool:
        d = np.diff(self.t)
        return bool(np.ptp(d) <= 1e-6 * np.median(d))


def load_run(path, params=None, *, columns=None, units=None, string_weight=None) -> MeasuredRun:
    """Read and check a measured run in any supported shape (``docs/contracts/measured-run.md``).

    The file is read by :func:`heavecomp.io.series.read_series` (CSV with any delimiter,
    decimal comma, header case/units; gzip/bz2/xz/zip; Parquet; MATLAB .mat; time in s, ms
    or ISO timestamps) and converted to SI; how it was read is kept in ``run.measurement``.
    A DataFrame takes the same path as a file (the reader reads it as a file with its header):
    the same checks, hook-load conversion and ``[[effects]]`` reading corrections.

    Parameters
    ----------
    path : str or Path, or pandas.DataFrame
        A file, or a frame with the contract columns (time as column ``t`` or as the index,
        e.g. ``SimulationResult.to_pandas()``); ``columns``/``units`` apply to a frame too.
    params : CMCParams, optional
        Nominal parameters; when given, the channel magnitudes are checked
        against the operating point (wrong-unit detection), and its ``[measurement]``
        table (if any) maps columns and declares units.
    columns, units : dict, optional
        Contract name -> source column / unit; override ``[measurement]`` key by key
        (``--columns`` / ``--units``).
    string_weight : float [N], optional
        The string weight the WOB is derived from when the log has a hook load and no WOB
        (:func:`wob_from_hook_load`); overrides ``[measurement] string_weight``.

    Raises
    ------
    DataError
        One line naming the column (and row) for every problem.
    """

    cols, uns, weight = _reading(params, columns, units, string_weight)
    s = read_series(path, REQUIRED, optional=CHANNELS + ANGLES + (HOOK_LOAD,), columns=cols, units=uns,
                    what="measured run")
    return _checked_run(s, params, weight)


def check_head(path, params=None, *, columns=None, units=None, string_weight=None) -> None:
    """:func:`load_run`'s checks on the start of a log only, before any work (a fleet checks every log so):
    the first chunk of a text log or the first rows of a Parquet file (:func:`heavecomp.io.series.iter_chunks`
    ``head``) take every check ``load_run`` makes; of a MATLAB file only the variable headers are read (the
    column mapping, the units, a hook load without a string weight, a log without any measured output), its
    magnitudes are checked when the log is read whole.

    Parameters
    ----------
    path : str or Path, or pandas.DataFrame
        The log.
    params : CMCParams, optional
        Nominal parameters (magnitude checks, ``[measurement]``), as :func:`load_run`'s.
    columns, units : dict, optional
        Contract name -> source column / unit, as :func:`load_run`'s.
    string_weight : float [N], optional
        The string weight of a hook load, as :func:`load_run`'s.

    Raises
    ------
    DataError
        One line naming the column (and row), as :func:`load_run` says it.
    """
    cols, uns, weight = _reading(params, columns, units, string_weight)
    chunks = iter_chunks(path, REQUIRED, optional=CHANNELS + ANGLES + (HOOK_LOAD,), columns=cols, units=uns,
                         what="measured run", head=True)
    try:
        s = next(chunks)
    finally:
        chunks.close()
    if s.rows.size:
        _checked_run(s, params, weight)
        return
    data = dict(s.columns)  # a MATLAB file's columns without samples
    data.pop("t")
    wob_from_hook_load(data, s, weight)
    _check_channels(data, s.source)


def _reading(params, columns, units, string_weight):
    """(column mapping, units, string weight) of a log: the keywords over the parameters' ``[measurement]``."""
    spec = getattr(params, "extra", {}).get("measurement") if params is not None else None
    cols = {**(spec.columns if spec else {}), **(columns or {})}
    uns = {**(spec.units if spec else {}), **(units or {})}
    return cols, uns, string_weight if string_weight is not None else getattr(spec, "string_weight", None)


def _checked_run(s, params, string_weight) -> MeasuredRun:
    """The run of a series read (:func:`load_run`): the WOB from a hook load, the ``[[effects]]`` reading
    corrections, the contract checks and the data-quality pass."""
    data = dict(s.columns)
    t = data.pop("t")
    wob_from_hook_load(data, s, string_weight)
    fixes = reading_effects(params) if params is not None else []
    if fixes:  # [[effects]] sensor effects: the log is read as the rig truly moved (docs/contracts/parameter-file.md)
        data, notes = correct(fixes, t, data)
    run = check_run(t, data, params=params, source=s.source, rows=s.rows,
                    wob_from=(s.measurement or {}).get("wob_from"))
    run.warnings[:0] = s.warnings
    run.measurement = dict(s.measurement or {}, corrections=notes) if fixes else s.measurement
    return quality.checked(run, params, rows=s.rows)  # corruption: refused, or warned about with a confidence cap


HOOK_LOAD = "hook_load"  #: optional column: the hook load [N], from which the WOB is derived when it is not logged


def wob_from_hook_load(data: dict, series, string_weight) -> None:
    """The WOB from the hook load when a log has no WOB column: W = string weight - hook load (the bit
    carries what the hook no longer holds; cmc-reference.md's W is the force on the bit, positive).  In
    place on ``data``; the conversion is recorded in ``series.measurement`` (``wob_from``) and its
    ``conversions``.  A log with a WOB column keeps it (the hook load is carried along).

    Parameters
    ----------
    data : dict
        Contract name -> samples [SI], as read (``hook_load`` [N] among them when the log has one).
    series : heavecomp.io.series.Series
        The series read (its ``source`` names the file; its ``measurement`` records the conversion).
    string_weight : float [N] or None
        The string weight hanging from the hook off bottom (``[measurement] string_weight``).

    Raises
    ------
    DataError
        A hook load without a string weight, or a string weight that is not a positive number.
    """
    if "wob" in data or HOOK_LOAD not in data:
        return
    if string_weight is None:
        raise DataError(f"{series.source}: column 'wob' missing and column 'hook_load' given: the WOB is the string "
                        "weight minus the hook load; give the string weight [N] (measurement.string_weight)")
    w = float(string_weight)
    if not math.isfinite(w) or w <= 0:
        raise DataError(f"{series.source}: measurement.string_weight: expected a positive force in N, got {string_weight!r}")
    data["wob"] = w - data.pop(HOOK_LOAD)
    m = series.measurement = dict(series.measurement or {})
    m["wob_from"] = {"column": HOOK_LOAD, "string_weight_N": w, "formula": "wob = string_weight - hook_load"}
    m["conversions"] = list(m.get("conversions", [])) + [f"wob: string weight {w:.6g} N - hook_load"]


def check_run(t, columns: dict, *, params=None, source="<array>", rows=None, wob_from=None) -> MeasuredRun:
    """Check arrays against the contract (see the module docstring); returns a :class:`MeasuredRun`.

    ``rows`` (optional) gives the file line of each sample, for messages (default: header on
    line 1, one sample per line).

    Parameters
    ----------
    t : array_like [s]
        Sample times (strictly increasing, else DataError).
    columns : dict
        {column: array} in SI: ``heave``, ``stroke`` [m], ``pressure`` [Pa] (gauge), ``wob`` [N],
        optionally ``pitch`` [rad].
    params : heavecomp.params.CMCParams, optional
        Nominal parameters; given, the channel magnitudes are checked against them (:func:`check_units`).
    source : str
        Name of the data's origin, for messages.
    rows : sequence of int, optional
        File line of each sample, for messages; None: header on line 1, one sample per line.
    wob_from : dict or None
        How the WOB was derived from a hook load (:func:`check_units`).
    """

    t = np.asarray(t, dtype=float)
    columns = {k: np.asarray(v, dtype=float) for k, v in columns.items()}
    checked = ("heave",) + tuple(c for c in OUTPUTS if c in columns) \
        + tuple(a for a in ANGLES if a in columns)
    line = (lambda i: int(rows[i])) if rows is not None else (lambda i: int(i) + 2)
    for col in checked:  # the contract: non-finite values are an error (an inf, e.g. 1e400, is no dropout)
        if col in columns and np.isinf(columns[col]).any():
            raise DataError(f"{source}: column '{col}', row {line(np.flatnonzero(np.isinf(columns[col]))[0])}: non-finite value")
    _check_channels(columns, source)
    _check_time(t, source, line)
    # a channel the log lacks (contract schema 3): diagnosed without it, said once, with the way to map it
    warnings = [f"no column '{c}': diagnosed with the channels present (if the log has it under another name, map "
                f"it, {c}=NAME)" for c in OUTPUTS if c not in columns]
    warnings += _check_missing(t, columns, checked, source, line)
    angles = tuple(a for a in ANGLES if a in columns)
    for col in angles:
        rms = float(np.sqrt(np.nanmean(columns[col] ** 2)))
        if rms > MAX_ANGLE_RMS:
            raise DataError(f"{source}: column '{col}': rms {rms:.4g} rad ({math.degrees(rms):.0f} deg) is no vessel "
                            f"angle — degrees? convert the column to rad or declare its unit, {col}=deg",
                            option="units", example=f"{col}=deg")
    d = np.diff(t)
    # a clock read in s (epoch 1.7e9 s) carries its float rounding, a few spacings of its largest value, into
    # every interval: that much spread is no non-uniform sampling
    if np.ptp(d) > max(1e-6 * np.median(d), 4.0 * float(np.spacing(np.max(np.abs(t))))):
        warnings.append(f"non-uniform sampling (intervals {d.min():.4g}..{d.max():.4g} s): replay uses the "
                        "actual times, spectra a uniform resampling")
    run = MeasuredRun(t=t - t[0], columns=columns, source=source, warnings=warnings)
    if params is not None:
        check_units(run, params, wob_from=wob_from)
    return run


def _check_time(t, source, line) -> None:
    """The time column: enough samples, finite, strictly increasing, in seconds, without long holes
    (one line naming column 't' and the row, else nothing)."""
    if t.size < MIN_SAMPLES:
        raise DataError(f"{source}: column 't': need at least {MIN_SAMPLES} samples, got {t.size}")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise DataError(f"{source}: column 't', row {line(bad[0])}: missing or non-finite time")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        i = back[0]
        raise DataError(f"{source}: column 't', row {line(i + 1)}: time not strictly increasing "
                        f"({t[i]:g} -> {t[i + 1]:g} s; duplicate or backwards)")
    dt_med = float(np.median(np.diff(t)))
    if dt_med > MAX_DT_S:
        raise DataError(f"{source}: column 't': median interval {dt_med:.4g} s is too coarse for heave "
                        "(waves need > 1 Hz) — time in milliseconds? convert to s or declare its unit, t=ms",
                        option="units", example="t=ms")
    hole = gaps(t, MAX_GAP)
    if hole.size:
        i = hole[0]
        raise DataError(f"{source}: column 't', row {line(i + 1)}: {t[i + 1] - t[i]:.3g} s without samples "
                        f"({t[i]:g} -> {t[i + 1]:g} s; longest bridged gap {MAX_GAP:g} s)")


def _check_missing(t, columns, checked, source, line) -> list:
    """Missing samples per checked column: at most :data:`MAX_MISSING` of each, and the replay's inputs
    (heave, vessel angles) without a dropout longer than :data:`MAX_GAP`; returns the warnings."""
    warnings = []
    for col in checked:
        miss = ~np.isfinite(columns[col])
        frac = float(miss.mean())
        if frac > MAX_MISSING:
            raise DataError(f"{source}: column '{col}': {100 * frac:.0f} % of samples missing "
                            f"(at most {100 * MAX_MISSING:.0f} % tolerated)")
        if miss.any():
            warnings.append(f"column '{col}': {int(miss.sum())} missing samples "
                            + ("interpolated in the replay input" if col not in CHANNELS else "excluded from the residuals"))
    for col in ("heave",) + tuple(a for a in ANGLES if a in columns):  # the replay's inputs: gaps bridged by interpolation
        miss = ~np.isfinite(columns[col])
        for a, b in _runs(miss) if miss.any() else ():
            lo = t[max(a - 1, 0)]
            hi = t[min(b, t.size - 1)]
            if hi - lo > MAX_GAP:
                raise DataError(f"{source}: column '{col}', row {line(a)}: dropout of {hi - lo:.3g} s "
                                f"(longest bridged gap {MAX_GAP:g} s)")
    return warnings


def _check_channels(columns, source) -> None:
    """The heave and at least one measured output (any of stroke, pressure and wob may be missing: contract
    schema 3), else one line naming them."""
    for col in REQUIRED[1:]:
        if col not in columns:
            raise DataError(f"{source}: missing column '{col}'")
    if not any(c in columns for c in CHANNELS):
        raise DataError(f"{source}: no measured output: need at least one of columns 'stroke', 'pressure', 'wob'")


def _runs(mask):
    """(start, stop) index pairs of True runs."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    dm = np.diff(m)
    return list(zip(np.flatnonzero(dm == 1), np.flatnonzero(dm == -1)))


def _check_mean(run, src, column, unit, symbol, nominal, band, other_units, hint):
    """One-line DataError when a column's mean looks like another unit (within 50 % of the
    nominal value converted to it) or lies outside ``band`` x the nominal value."""
    m = float(np.nanmedian(run[column]))  # the median: one spike (1e9 N) is no unit
    for factor, other in other_units:
        if abs(m / (nominal * factor) - 1.0) < 0.5:
            raise DataError(f"{src}: column '{column}': mean {m:.4g} looks like {other}, expected {unit} "
                            f"(nominal {symbol} = {nominal:.4g} {unit}); convert the column to {unit} or declare "
                            f"its unit, {column}={other}", option="units", example=f"{column}={other}")
    if not (band[0] * nominal < m < band[1] * nominal):
        raise DataError(f"{src}: column '{column}': mean {m:.4g} {unit} is far from the nominal {symbol} = "
                        f"{nominal:.4g} {unit} ({hint})")


def check_units(run: MeasuredRun, params, *, wob_from=None) -> None:
    """Compare channel magnitudes with the nominal operating point; DataError naming the likely unit.

    Pressure: the mean gauge pressure should be near p_0 (cmc-reference.md); a mean near
    p_0 + p_atm adds a warning (absolute pressure?) to ``run.warnings``;
    WOB: its mean near W_0; stroke: its spread comparable to the heave's.

    Parameters
    ----------
    run : MeasuredRun
        The measured run.
    params : heavecomp.params.CMCParams
        Nominal parameters (p_0 [Pa], the WOB set-point W_0 [N]).
    wob_from : dict or None
        How the WOB was derived from the hook load (``measurement.wob_from``, :func:`wob_from_hook_load`): a bad
        mean is then the hook load's or the string weight's, and the message names them.
    """
    src = run.source
    p0 = params.p0
    W0 = params.operating_point.wob_setpoint
    have = run.columns
    if "pressure" in have:
        pm = float(np.nanmedian(run["pressure"]))
        if abs(pm - p0 - P_ATM) < 0.3 * P_ATM < abs(pm - p0):
            run.warnings.append(f"column 'pressure': mean {pm:.4g} Pa is p_0 + {(pm - p0) / 1e5:.2f} bar — absolute "
                                "pressure? the contract is gauge; if so declare --units pressure=bara (or Pa_abs)")
        _check_mean(run, src, "pressure", "Pa", "p_0", p0, (0.2, 5.0),
                    ((1e-5, "bar"), (1e-3, "kPa"), (1e-6, "MPa"), (1.45038e-4, "psi")),
                    "wrong unit, absolute pressure of another rig, or wrong parameter file?")
    if "wob" in have:
        try:
            _check_mean(run, src, "wob", "N", "W_0", W0, (0.05, 20.0),
                        ((1e-3, "kN"), (1.0 / 9810.0, "tonnes"), (1.0 / 4448.22, "kip")),
                        "wrong unit or wrong parameter file?")
        except DataError:
            if not wob_from:
                raise
            raise quality.hook_load_error(src, float(np.nanmedian(run["wob"])), wob_from, W0,
                                          "far from the set-point") from None
    if "stroke" not in have:
        return
    sz = float(np.nanstd(run["heave"]))
    ss = float(np.nanstd(run["stroke"]))
    if sz > 0 and ss > 100 * sz and ss > 1.0:
        raise DataError(f"{src}: column 'stroke': spread {ss:.4g} is {ss / sz:.0f} x the heave's — looks like mm, "
                        "expected m; convert the column to m or declare its unit, stroke=mm",
                        option="units", example="stroke=mm")
    if ss > 0 and sz > 100 * ss and sz > 1.0:
        raise DataError(f"{src}: column 'heave': spread {sz:.4g} is {sz / ss:.0f} x the stroke's — looks like mm, "
                        "expected m; convert the column to m or declare its unit, heave=mm",
                        option="units", example="heave=mm")


def fill_gaps(t, y):
    """Linear interpolation over NaN samples (for the replay input).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (increasing; may be non-uniform).
    y : numpy.ndarray [unit of the channel]
        The channel's samples (NaN: missing).
    """
    ok = np.isfinite(y)
    if ok.all():
        return y
    return np.interp(t, t[ok], y[ok])


def uniform(t, y, dt=None):
    """Resample (t, y) to a uniform grid of spacing ``dt`` (default: median interval); NaNs bridged.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (increasing; may be non-uniform).
    y : numpy.ndarray [unit of the channel]
        The channel's samples (NaN: missing).
    dt : float [s], optional
        Grid spacing; None: the median interval.
    """
    dt = float(np.median(np.diff(t))) if dt is None else dt
    tu = np.arange(t[0], t[-1] + 1e-9 * dt, dt)
    return tu, np.interp(tu, t, fill_gaps(t, y))


def heave_filtered(run: MeasuredRun, cutoff=HEAVE_CUTOFF):
    """The replay's heave before its reference is removed: gap-filled, uniformly resampled,
    zero-phase FIR low-passed (``cutoff`` [Hz]); a cubic spline of it (callable t -> z [m],
    ``.derivative()`` for dz_h, ddz_h).

    Parameters
    ----------
    run : MeasuredRun
        The measured run.
    cutoff : float [Hz]
        Cut-off of the zero-phase low-pass.
    """
    from scipy.interpolate import CubicSpline

    tu, zu = uniform(run.t, run["heave"])
    return CubicSpline(tu, flat_zero_phase(zu, 1.0 / (tu[1] - tu[0]), cutoff))


def heave_samples(run: MeasuredRun, h: float, n_steps: int, cutoff=HEAVE_CUTOFF, reference=None, spline=None):
    """Heave input for the replay: :func:`heave_filtered` minus the operating point's heave
    reference, z_h, dz_h, ddz_h on the stepper grid (h/2).

    ``reference`` [m]: the heave the operating point belongs to (estimated by
    :func:`heavecomp.diagnosis.start.estimate` for a log that starts anywhere); default the first
    filtered sample (cmc-reference.md: a run that starts at rest at the operating point).
    ``spline``: the run's :func:`heave_filtered` at ``cutoff`` when already made (it is not made again).

    Parameters
    ----------
    run : MeasuredRun
        The measured run.
    h : float [s]
        Stepper step (the samples are spaced h/2).
    n_steps : int
        Stepper steps.
    cutoff : float [Hz]
        Cut-off of the zero-phase low-pass.
    reference : float [m], optional
        Heave of the operating point; None: the first filtered sample.
    spline : scipy.interpolate.CubicSpline, optional
        The run's :func:`heave_filtered` at ``cutoff`` when already made; None: made here.
    """

    cs = heave_filtered(run, cutoff) if spline is None else spline
    ref = float(cs(run.t[0])) if reference is None else float(reference)
    sp = 0.5 * h
    tg = np.minimum(np.arange(2 * n_steps + 2) * sp, run.t[-1])
    info = {"kind": "measured", "cutoff_hz": cutoff, "reference_m": ref}
    angle = None
    for col in ANGLES:  # the logged vessel angle, filtered as the heave, on the same grid
        if col in run.columns:
            ca = heave_filtered(MeasuredRun(run.t, {"heave": run[col]}), cutoff)
            angle = (ca(tg), ca(tg, 1), ca(tg, 2))
            info.update(angle=col, angle_reference=_angle_reference(run, ca, reference))
            break
    return HeaveSamples(sp, cs(tg) - ref, cs(tg, 1), cs(tg, 2), info, angle=angle)


def _angle_reference(run, ca, reference) -> float:
    """sin(theta) [-] where the heave reference was read: the first sample (``reference`` None) or the
    mean over :data:`ZREF_WINDOW` (where :func:`heavecomp.diagnosis.start.estimate` reads it).  A heave
    measured at a lever arm carries L sin(theta) into its reference; ``heave_reference`` removes
    L (sin(theta) - this) so that the seen heave keeps the operating point."""
    if reference is None:
        return float(np.sin(ca(run.t[0])))
    rel = run.t - run.t[0]
    w = (rel >= ZREF_WINDOW[0]) & (rel <= ZREF_WINDOW[1])
    return float(np.mean(np.sin(ca(run.t[w])))) if w.sum() >= 8 else float(np.sin(ca(run.t[0])))


def lowpass_zero_phase(t, y, cutoff):
    """A channel zero-phase FIR low-passed (linear interpolation back to the original times ``t``),
    and its velocity and acceleration by spline differentiation of the same filtered samples.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (increasing; may be non-uniform).
    y : numpy.ndarray [unit of the channel]
        The channel's samples (NaN: missing).
    cutoff : float [Hz]
        Cut-off of the zero-phase low-pass.
    """
    from scipy.interpolate import CubicSpline

    tu, yu = uniform(t, y)
    yf = flat_zero_phase(yu, 1.0 / (tu[1] - tu[0]), cutoff)
    cs = CubicSpline(tu, yf)
    return np.interp(t, tu, yf), cs(t, 1), cs(t, 2)


NOISE_ORDERS = (2, 3, 4, 5, 6)  #: difference orders of the noise estimate


def noise_floor(y, t=None) -> float:
    """Measurement-noise standard deviation of a channel [its unit], robust to the signal itself.

    For white noise of standard deviation sigma the k-th difference has standard deviation
    sigma sqrt(C(2k, k)); a smooth signal's k-th difference shrinks as (2 sin(pi f dt))^k, which is
    below 1 for f < fs/6.  The estimate is the smallest over ``NOISE_ORDERS`` of
    1.4826 MAD(d^k y) / sqrt(C(2k, k)) (median absolute deviation: robust to stick-slip events).
    Second differences alone (until 2026-11) hold at 50-100 Hz but read the waves as noise at 10 Hz
    (1.8x too high for 2 mm on a 2.5 m sea, 6x for 0.5 mm); from 10 to 100 Hz this estimate is within
    a few % (``tests/test_diagnosis_preprocessing.py``).  A non-uniform ``t`` is resampled first.
    A channel read on a grid coarse against its noise (:func:`heavecomp.diagnosis.quality.quantum`: most
    differences are exactly 0, so the estimate reads the grid, not the noise) adds the reading's error,
    step^2/12, in quadrature.

    Parameters
    ----------
    y : array_like [unit of the channel]
        The channel's samples (non-finite ones are dropped).
    t : numpy.ndarray [s], optional
        Sample times of a non-uniformly sampled channel (resampled first); None: uniform.
    """
    from scipy.special import comb

    y = np.asarray(y, dtype=float)
    if t is not None:
        _, y = uniform(t, y)
    y = y[np.isfinite(y)]
    best = math.inf
    for k in NOISE_ORDERS:
        if y.size <= k + 2:
            break
        d = np.diff(y, k)
        best = min(best, float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(comb(2 * k, k))))
    best = best if math.isfinite(best) else 0.0
    step = quality.quantum(y)  # a coarse grid: most differences are 0, the reading's error is step^2/12
    return math.hypot(best, step / math.sqrt(12.0)) if step > 0.0 else best
