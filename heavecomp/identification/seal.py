"""Seal friction against pressure: fit F_C + C_p dp to steady strokes.

Data: TU Delft pneumatic-cylinder O-ring files (see ``heavecomp/data/README.md``),
whitespace separated, 7 columns: time [ms], laser [V], pressure [V], force [V],
position [mm], pressure [bar], force [N].  The friction is, by the authors'
definition, ``F_f = force - p A`` with ``A = pi 0.0125^2`` m^2 and ``p`` the
gauge pressure [Pa].

The pressure-dependent Coulomb law is paper A eq. 4 without the velocity terms
(one speed only, so no Stribeck curve):

    |F_f| = F_C + C_p |dp|                                        (paper A eq. 4)

Steady sliding is selected by velocity (differentiated position): strokes are
maximal runs of one velocity sign above ``v_min``; the first and last
``trim`` fraction of each stroke (acceleration, reversal) are dropped and each
stroke is summarised by its mean friction and pressure, so that the least-squares
fit works on (nearly) independent points.  A bootstrap over strokes, stratified
by file, gives a robust uncertainty.

The velocity is either the slope over +-0.1 s (default) or paper B's measurement
(``velocity="fir"``: resampled to 100 Hz, differentiated through a 2 Hz zero-phase
FIR, :func:`heavecomp.signals.differentiate`); the stroke summary is the mean or the
median.  :data:`METHOD_VARIANTS` are the analysis choices whose effect on C_p the
study reports (the single seal study: this module + :func:`heavecomp.identification.study.seal_study`).

The same files are also a plant of the gap diagnoser (the door every diagnoser shares,
:class:`heavecomp.estimator.GapEstimator`): :class:`heavecomp.identification.plants.SealFriction`
gives the friction residual against this module's ``split`` law, and
:class:`heavecomp.identification.residual.ResidualDiagnoser` fits the effect library's candidates to it.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from heavecomp.errors import DataError, ParameterError
from heavecomp.identification.inverse import least_squares
from heavecomp.signals import differentiate
from heavecomp.io.series import read_text

log = logging.getLogger(__name__)

#: Piston area of the TU Delft actuator, 25 mm bore [m^2].
BORE_AREA = math.pi * 0.0125 ** 2
#: Bore diameter [m].
BORE_DIAMETER = 0.025
COLUMNS = ("time [ms]", "laser [V]", "pressure [V]", "force [V]", "position [mm]", "pressure [bar]", "force [N]")
BAR = 1e5


@dataclass(frozen=True)
class SealRecord:
    """One constant-pressure file: time [s], position [m], gauge pressure [Pa], force [N]."""

    t: np.ndarray
    x: np.ndarray
    p: np.ndarray
    force: np.ndarray
    name: str = ""

    def friction(self, area: float = BORE_AREA) -> np.ndarray:
        """F_f = force - p A [N] (authors' definition)."""
        return self.force - self.p * area


def load_seal_csv(path) -> SealRecord:
    """Read one O-ring file (7 whitespace-separated columns, no header; may be gzip/bz2/xz/zip).

    Parameters
    ----------
    path : str or Path
        The O-ring file (plain or compressed).

    Raises
    ------
    DataError
        Missing file, wrong number of columns, non-numeric or non-finite cells,
        or a time column (``time [ms]``) that is not strictly increasing.
    """

    path = Path(path)
    try:
        missing = not path.is_file()
    except OSError:  # e.g. a name too long: read_text says so in one line
        missing = False
    if missing:
        raise DataError(f"{path}: no such file")
    rows = []
    text, _ = read_text(path)  # plain or compressed; Latin-1 if not UTF-8; binary: one-line DataError
    for i, line in enumerate(text.splitlines(), start=1):
        cells = line.split()
        if not cells:
            continue
        if len(cells) != len(COLUMNS):
            raise DataError(f"{path.name}: row {i} has {len(cells)} columns, expected {len(COLUMNS)} "
                            f"({', '.join(COLUMNS)})")
        try:
            vals = [float(c) for c in cells]
        except ValueError:
            raise DataError(f"{path.name}: row {i} has a non-numeric cell") from None
        for name, v in zip(COLUMNS, vals):
            if not math.isfinite(v):
                raise DataError(f"{path.name}: column '{name}' is not finite at row {i}")
        rows.append(vals)
    if len(rows) < 100:
        raise DataError(f"{path.name}: only {len(rows)} rows, need at least 100")
    a = np.asarray(rows)
    t = a[:, 0] * 1e-3
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        raise DataError(f"{path.name}: column 'time [ms]' is not strictly increasing at row {bad[0] + 2}")
    return SealRecord(t=t, x=a[:, 4] * 1e-3, p=a[:, 5] * BAR, force=a[:, 6], name=path.name)


def velocity(t, x, half_window: int = 10, max_span: float = 0.5) -> np.ndarray:
    """Velocity [m/s] as the slope over +-``half_window`` samples; NaN where that span
    exceeds ``max_span`` [s] (a gap in the log) or at the ends.

    Parameters
    ----------
    t : array [s]
        Sample times (may have jitter and gaps).
    x : array [m]
        Position.
    half_window : int
        Half the slope's span [samples].
    max_span : float [s]
        Longest span accepted (a longer one is a gap in the log: NaN).
    """
    n = len(t)
    v = np.full(n, np.nan)
    k = half_window
    dt = t[2 * k:] - t[:-2 * k]
    slope = (x[2 * k:] - x[:-2 * k]) / dt
    slope[dt > max_span] = np.nan
    v[k:n - k] = slope
    return v


def velocity_fir(t, x, fs: float = 100.0, cutoff: float = 2.0) -> np.ndarray:
    """Velocity [m/s] by paper B's method: ``x`` resampled to ``fs`` [Hz] by linear
    interpolation (the logger clock has jitter and gaps), differentiated through a
    zero-phase FIR low-pass of ``cutoff`` [Hz], interpolated back onto ``t``.

    Parameters
    ----------
    t : array [s]
        Sample times (may have jitter and gaps).
    x : array [m]
        Position.
    fs : float [Hz]
        Uniform rate the position is resampled to.
    cutoff : float [Hz]
        Cut-off of the zero-phase FIR low-pass (paper B: 2 Hz).
    """
    tu = np.arange(t[0], t[-1], 1.0 / fs)
    _, vu = differentiate(tu, np.interp(tu, t, x), cutoff, order=1, name="position [mm]")
    return np.interp(t, tu, vu)


#: velocity estimators of :func:`strokes`
VELOCITY_METHODS = {"slope": velocity, "fir": velocity_fir}
#: stroke summaries of :func:`strokes`
STATISTICS = {"mean": np.mean, "median": np.median}
#: analysis choices whose effect on C_p the seal study reports: label -> SealFrictionFit settings
#: (changed from the defaults one at a time, then all four of paper B's friction measurement at once)
METHOD_VARIANTS = {
    "headline: slope over +-0.1 s, speed > 2 mm/s, 20 % trim, stroke mean": {},
    "velocity by paper B's 2 Hz zero-phase FIR": {"velocity": "fir"},
    "speed > 5 mm/s": {"v_min": 5e-3},
    "no trim": {"trim": 0.0},
    "stroke median": {"statistic": "median"},
    "paper B's measurement: FIR, speed > 5 mm/s, no trim, median": {"velocity": "fir", "v_min": 5e-3, "trim": 0.0,
                                                                   "statistic": "median"},
}


def strokes(rec: SealRecord, v_min: float = 2e-3, trim: float = 0.2, min_samples: int = 40,
            area: float = BORE_AREA, velocity: str = "slope", statistic: str = "mean") -> list[dict]:
    """Steady-sliding strokes of one file.

    ``velocity`` names the estimator (:data:`VELOCITY_METHODS`), ``statistic`` the
    stroke summary of friction and pressure (:data:`STATISTICS`).

    Returns a list of dicts: ``direction`` (+1/-1), ``friction`` [N], ``dp`` gauge
    pressure [Pa] (the stroke's mean or median), ``speed`` mean |v| [m/s], ``n`` samples
    kept, ``t0``, ``t1`` [s], ``std`` of the friction within the stroke [N], ``file``.

    Parameters
    ----------
    rec : SealRecord
        One constant-pressure O-ring file (:func:`load_seal_csv`).
    v_min : float [m/s]
        Speed above which a sample counts as sliding.
    trim : float
        Fraction of each stroke dropped at either end (acceleration, reversal) [-].
    min_samples : int
        Fewest samples a trimmed stroke must keep to be used.
    area : float [m^2]
        Piston area of F_f = force - p A.
    velocity : {"slope", "fir"}
        Velocity estimator (:data:`VELOCITY_METHODS`).
    statistic : {"mean", "median"}
        Stroke summary (:data:`STATISTICS`).
    """
    if velocity not in VELOCITY_METHODS:
        raise ParameterError(f"velocity = {velocity!r}: must be one of {', '.join(VELOCITY_METHODS)}")
    if statistic not in STATISTICS:
        raise ParameterError(f"statistic = {statistic!r}: must be one of {', '.join(STATISTICS)}")
    stat = STATISTICS[statistic]
    v = VELOCITY_METHODS[velocity](rec.t, rec.x)
    f = rec.friction(area)
    s = np.where(np.abs(v) > v_min, np.sign(v), 0.0)
    s[~np.isfinite(v)] = 0.0
    out = []
    i, n = 0, len(s)
    while i < n:
        if s[i] == 0:
            i += 1
            continue
        j = i
        while j < n and s[j] == s[i]:
            j += 1
        m = j - i
        lo, hi = i + int(trim * m), j - int(trim * m)
        if hi - lo >= min_samples:
            sl = slice(lo, hi)
            out.append({"direction": int(s[i]), "friction": float(stat(f[sl])), "std": float(f[sl].std()),
                        "dp": float(stat(rec.p[sl])), "speed": float(np.abs(v[sl]).mean()),
                        "n": hi - lo, "t0": float(rec.t[lo]), "t1": float(rec.t[hi - 1]), "file": rec.name})
        i = j
    return out


def _design(rows, model):
    dp = np.array([r["dp"] for r in rows])
    d = np.array([r["direction"] for r in rows], dtype=float)
    f = np.array([r["friction"] for r in rows])
    if model == "magnitude":          # |F| = F_C + C_p dp
        return np.column_stack([np.ones_like(dp), dp]), np.abs(f)
    if model == "split":              # F = d (F_C + C_p dp) + (F_0 + C_0 dp)
        return np.column_stack([d, d * dp, np.ones_like(dp), dp]), f
    raise ParameterError(f"unknown seal model '{model}'")


class SealFrictionFit:
    """Fit |F_f| = F_C + C_p dp over strokes of several constant-pressure files.

    Parameters
    ----------
    v_min : float, m/s
        Speed above which a sample counts as sliding.
    trim : float
        Fraction of each stroke dropped at either end (acceleration, reversal).
    n_boot : int
        Bootstrap resamples over strokes (stratified by file); 0 skips the bootstrap
        (its fields are then None).
    seed : int
        Bootstrap random seed.
    area : float, m^2
        Piston area used in F_f = force - p A.
    velocity : {"slope", "fir"}
        Velocity estimator (:data:`VELOCITY_METHODS`).
    statistic : {"mean", "median"}
        Stroke summary (:data:`STATISTICS`).

    Attributes
    ----------
    strokes_ : list of dict
        Every steady stroke kept (see :func:`strokes`).
    fits_ : dict
        ``pooled`` (both directions, |F|), ``positive``, ``negative`` (one direction
        each, |F|) and ``split`` (F = d (F_C + C_p dp) + F_0 + C_0 dp: the
        direction-independent part F_0 + C_0 dp takes sensor offset and any effective
        area error): each with ``F_C`` [N], ``C_p`` [N/Pa], their least-squares
        standard errors ``F_C_se``, ``C_p_se``, bootstrap standard deviations
        ``F_C_boot``, ``C_p_boot`` and 95 % intervals ``C_p_ci95`` [N/Pa], ``rms`` [N],
        ``n_strokes``.
    C_p_, C_p_se_, F_C_ : float
        The headline: C_p [N/Pa] of the ``split`` fit (the friction part that changes
        sign with the stroke direction), its uncertainty [N/Pa] — the larger of the
        stroke bootstrap and the standard error of ``file_means`` (one point per file:
        (mean F+ - mean F-)/2 vs dp; it sees the file-to-file scatter that a bootstrap
        within files cannot) — and its F_C [N].  The ``pooled`` |F_f| fit gives nearly the same C_p, but its
        residual is dominated by the direction asymmetry, so its standard error
        measures that misfit rather than the uncertainty of C_p.
    """

    def __init__(self, v_min: float = 2e-3, trim: float = 0.2, n_boot: int = 2000, seed: int = 0,
                 area: float = BORE_AREA, velocity: str = "slope", statistic: str = "mean"):
        self.v_min, self.trim, self.n_boot, self.seed, self.area = v_min, trim, n_boot, seed, area
        self.velocity, self.statistic = velocity, statistic

    def fit(self, records) -> "SealFrictionFit":
        rows = []
        for rec in records:
            got = strokes(rec, self.v_min, self.trim, area=self.area, velocity=self.velocity,
                          statistic=self.statistic)
            if not got:
                raise DataError(f"{rec.name}: no steady stroke faster than v_min = {self.v_min * 1e3:g} mm/s")
            rows += got
        if len({round(r["dp"] / BAR) for r in rows}) < 2:
            raise DataError("seal friction fit needs files at two or more pressures")
        self.strokes_ = rows
        rng = np.random.default_rng(self.seed)
        files = sorted({r["file"] for r in rows})
        subsets = {"pooled": rows, "positive": [r for r in rows if r["direction"] > 0],
                   "negative": [r for r in rows if r["direction"] < 0], "split": rows}
        self.fits_ = {}
        for key, sub in subsets.items():
            model = "split" if key == "split" else "magnitude"
            X, y = _design(sub, model)
            res = least_squares(X, y)
            by_file = [[r for r in sub if r["file"] == f] for f in files]
            boot = []
            for _ in range(self.n_boot):
                pick = [g[i] for g in by_file if g for i in rng.integers(0, len(g), len(g))]
                Xb, yb = _design(pick, model)
                boot.append(np.linalg.lstsq(Xb, yb, rcond=None)[0][:2])
            boot = np.asarray(boot)
            fit = {"F_C": float(res.theta[0]), "C_p": float(res.theta[1]),
                   "F_C_se": float(res.stderr[0]), "C_p_se": float(res.stderr[1]),
                   "F_C_boot": None, "C_p_boot": None, "C_p_ci95": None, "rms": res.rms, "n_strokes": len(sub)}
            if self.n_boot > 1:
                fit.update({"F_C_boot": float(boot[:, 0].std(ddof=1)), "C_p_boot": float(boot[:, 1].std(ddof=1)),
                            "C_p_ci95": [float(x) for x in np.percentile(boot[:, 1], [2.5, 97.5])]})
            if model == "split":
                fit.update({"F_0": float(res.theta[2]), "C_0": float(res.theta[3]),
                            "F_0_se": float(res.stderr[2]), "C_0_se": float(res.stderr[3])})
            self.fits_[key] = fit
        # file level: one point per file, (mean F+ - mean F-)/2 vs mean dp
        Xf, yf = [], []
        for f in files:
            sub = [r for r in rows if r["file"] == f]
            pos = [r["friction"] for r in sub if r["direction"] > 0]
            neg = [r["friction"] for r in sub if r["direction"] < 0]
            if pos and neg:
                Xf.append([1.0, np.mean([r["dp"] for r in sub])])
                yf.append(0.5 * (np.mean(pos) - np.mean(neg)))
        if len(yf) >= 3:
            res = least_squares(np.asarray(Xf), np.asarray(yf))
            self.fits_["file_means"] = {"F_C": float(res.theta[0]), "C_p": float(res.theta[1]),
                                        "F_C_se": float(res.stderr[0]), "C_p_se": float(res.stderr[1]),
                                        "F_C_boot": None, "C_p_boot": None, "C_p_ci95": None,
                                        "rms": res.rms, "n_strokes": len(rows), "n_files": len(yf)}
        self.C_p_ = self.fits_["split"]["C_p"]
        self.F_C_ = self.fits_["split"]["F_C"]
        self.C_p_se_ = max(self.fits_["split"]["C_p_boot"] or 0.0,
                           self.fits_.get("file_means", {}).get("C_p_se", 0.0))
        log.info("seal friction: C_p = %.3f +- %.3f N/bar over %d strokes", self.C_p_ * BAR,
                 self.C_p_se_ * BAR, len(rows))
        return self


def scale_by_circumference(C_p: float, d_from: float, d_to: float) -> float:
    """C_p scaled by seal circumference: C_p d_to / d_from (same seal, same contact
    pressure per unit length; an assumption, not a law).

    Parameters
    ----------
    C_p : float [N/Pa]
        Pressure coefficient of the seal of diameter ``d_from``.
    d_from : float [m]
        Diameter the coefficient was measured on.
    d_to : float [m]
        Diameter it is scaled to.
    """
    return C_p * d_to / d_from
