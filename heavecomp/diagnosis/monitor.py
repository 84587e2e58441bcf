"""Monitor a long log: when and where the sim-to-real gap appears or changes (issue 23 item 2).

The component residuals (equation error, :mod:`heavecomp.diagnosis.components`: each model equation
evaluated on the measured signals, split into the model components' parts) are local in time and
cheap.  The monitor computes them window by window over a log of any length and follows, per block
of :data:`BLOCK` seconds, the mean square of each equation residual and of each component's part of
it over the equation's noise variance.

Three passes, each streaming over the log (peak memory set by :data:`CHUNK`, not by the log):

1. **operating point** per block: the mean WOB, stroke, pressure and heave.  A two-sided CUSUM on
   the block-mean WOB finds set-point changes.  A change counts as *operating* only when the load
   balance carries it: the mean pressure moves with it, ``A dp = -dW`` within :data:`CONSISTENT`
   of ``dW`` (a new set-point is a new charge pressure; a WOB channel that starts to misread moves
   the WOB alone, and is reported as an effect in ``sensors``);
2. **component residuals** in chunks of :data:`CHUNK` seconds (plus :data:`PAD` on each side for
   the filters), each operating segment with its own operating point (``wob_setpoint`` from its
   median block-mean WOB, the heave reference from its median block-mean heave), so a new
   operating point does not read as a gap; blocks within :data:`BLANK` of an operating change are
   left out (the filters straddle it);
3. **changes**: a two-sided, self-starting, clipped CUSUM (:func:`cusum`; threshold :data:`THRESHOLD`
   on the block coefficients, :data:`THRESHOLD_EQ` on the equations' mean squares) with, on the block
   coefficients, a Shewhart rule beside it (:data:`JUMP_BLOCKS` blocks in a row beyond :data:`JUMP`
   sigmas alarm at once) on every monitored series (:func:`columns`): per equation, log(1 + block
   statistic), standardised by
   :func:`null_sigma` (the larger of the robust block-to-block noise, 1.4826 MAD of first differences
   / sqrt 2, and the tail scale that puts the :data:`TAIL_Q` quantile of the |first differences|
   where a normal series has it: a heavy-tailed series is not scaled by its quiet bulk alone; floored
   at :data:`SIGMA_MIN`); and per equation and feature of its split (``components.SPLIT``; the seal
   friction's sign(v) and v in the top-mass balance), the block's joint least-squares
   **coefficient** of the equation residual on those features (:meth:`BlockSums.coefficients`),
   signed and standardised the same way, a block whose coefficient's standard error exceeds
   :data:`SE_MAX` times the median block's left out (with :data:`BALANCE_CONSTANT` every equation's
   constant among them: the top-mass balance's is the force balance of the mean, which a misread
   load moves); and per stroke band (:data:`STROKE_BANDS`) the block mean of the top-mass residual
   times sign(v) (:meth:`BlockSums.band_means`: a worn band of the bore adds friction in one band of
   the stroke, which a whole-block coefficient dilutes; threshold :data:`THRESHOLD_BAND`).  A
   coefficient series carries its own baseline (what the nominal model's filters and stick events
   leave in it), which the self-starting CUSUM learns at the start of each stretch and subtracts: a
   softer formation moves the lower-mass coefficient of the relative displacement by Delta k although
   the equation's mean square, dominated by that baseline, hardly moves.  The component of a change
   comes from the structure (:func:`_attribute_change`): the equations that moved with it (any of
   their series by :data:`MOVED` sigmas); exactly the equations that read one channel
   (``components.READS``) -> ``sensors`` (or ``heave_input``); else the component of the feature
   coefficient that moved most in the equations that moved (its law's own shape); else the
   component part of the alarming equation that grew.  Every CUSUM then restarts.  Effect alarms
   an operating change explains (:func:`absorbed`) are dropped.

Why CUSUM and not ``ruptures``: ruptures' PELT (l2 cost, exact search in Python) took 3 s on 500
blocks, 15 s on 1000 and 77 s on 2000 here (O(n^2.3) when changes are few): a 24 h log has 8640
blocks of 10 s, tens of minutes against the 60 s budget of the whole pass.  A CUSUM is O(n),
sequential (its alarm time *is* the detection delay) and its change-point estimate (the last time the
sum was zero) gives the segment boundary.

``changes[].t`` is the alarm time (end of the block in which the CUSUM crossed), ``onset`` the
CUSUM's estimate of when the change began.  ``size_to_noise``: the mean shift of the standardised
statistic between onset and alarm [block noise sigmas] (for an operating change: of the block-mean
WOB).  ``segments[].gap_to_noise``: per component, sqrt(1 + gap) over the segment, the gap as
:meth:`ComponentResiduals.gap` computes it (no nominal-replay floor: the monitor runs no replay).

Settings (:data:`DRIFT`, :data:`THRESHOLD`, :data:`THRESHOLD_OP`, :data:`JUMP`, :data:`TAIL_Q`,
:data:`SE_MAX`, :data:`LEARN`, :data:`CLIP`, :data:`MOVED`, :data:`MIN_EXCITATION`) were chosen on the
tuning set of ``scenarios/monitor_validation.py`` (false alarms first) and frozen (its settings hash)
before its scoring set ran; docs/monitoring.md gives each one's reason.

``--diagnose`` (:func:`diagnose_segments`): each segment that starts at an effect change is diagnosed
by :class:`heavecomp.diagnosis.estimator.GapDiagnoser` on that segment, sliced from the log
(:func:`segment_run`; the diagnosis estimates the state it starts from).

The chunked residuals are fitted on the chunk (the split of an equation residual into components is
a least-squares fit over the chunk): the monitor is offline over a finished log; a block's statistic
may use up to one chunk of data after it.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import warnings

import numpy as np

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import replay as R
from heavecomp.diagnosis.data import HEAVE_CUTOFF, MeasuredRun, heave_samples, lowpass_zero_phase, noise_floor
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.diagnosis.start import string_balance_heave
from heavecomp.diagnosis.structure import equation_channels
from heavecomp.effects.base import COMPONENTS
from heavecomp.io.arrays import monitor_dataset
from heavecomp.errors import DataError, InputError

log = logging.getLogger(__name__)

SCHEMA = 1  #: monitor.json schema (diagnosis-contract.md, schema 3 section)
BLOCK = 10.0  #: statistic block [s] (about one wave period)
CHUNK = 600.0  #: component-residual window [s]: the monitor's memory is set by this
PAD = 15.0  #: extra samples on each side of a chunk for the zero-phase filters [s] (> components.EDGE)
WINDOW = 180  #: blocks of the CUSUM's reference (30 min of 10 s blocks): a slowly changing sea is followed [-]
LEARN = 30  #: blocks the reference is learnt from before any alarm, at the log's start and after an operating change [-]
RELEARN = 12  #: the same after an effect alarm (shorter: the detector is blind meanwhile) [-]
MOVED_BLOCKS = 3  #: the last blocks up to an alarm compared with the reference to see what moved [-]
#: an equation moved with a change: one of its series (mean square or a block coefficient) by this many
#: sigmas and this share of the alarming series' move (monitor2, tuning set: at 1 sigma one of 20 series
#: moved by chance at almost every alarm, and a seal friction read as a misread stroke)
MOVED, MOVED_SHARE = 3.0, 0.2
COEF_MOVED = 1.0  #: a block coefficient that moved less than this [sigmas] does not name the component
OP_SLACK = 120.0  #: s around an operating change within which an effect alarm is the operating change
CLIP = 4.0  #: largest deviation one block adds to a CUSUM [block sigmas]
DRIFT = 1.0  #: CUSUM allowance k [block sigmas]: shifts below it are not accumulated
THRESHOLD = 8.0  #: CUSUM decision threshold h of the block coefficients [block sigmas] (tuning set: scenarios/monitor_validation.py)
#: Shewhart rule beside the CUSUM (a combined Shewhart-CUSUM scheme): an alarm as soon as JUMP_BLOCKS blocks in a
#: row deviate from the reference by JUMP sigmas or more, the same sign: a large step is alarmed after two blocks,
#: where the clipped CUSUM needs THRESHOLD / (CLIP - DRIFT) = 3 (the block coefficients; JUMP_EQ for the mean squares)
JUMP, JUMP_BLOCKS = 6.0, 2
#: the CUSUM threshold for the equations' mean squares [block sigmas]: higher than the coefficients' (fourth method:
#: every false alarm of the third method's scoring set came from the top-mass balance's mean square, whose stick
#: events come in wave groups over several blocks)
THRESHOLD_EQ = 12.0
JUMP_EQ = math.inf  #: the Shewhart rule's deviation for the equations' mean squares: none (the same reason) [block sigmas]
#: the same on a log too short for the long reference (:func:`learning_window`): the clipped sum needs
#: THRESHOLD_EQ / (CLIP - DRIFT) = 4 blocks after the reference, which a 130 s log may not hold after a change
#: (a 30 kN WOB step 26 s before its end moved the balances' mean squares by 13 and 43 sigmas and was missed).
#: The fourth method's tuning set (131 h): a rule at 8-10 sigmas on the mean squares gave 1 more false alarm
#: or none [block sigmas]
JUMP_EQ_SHORT = 10.0
#: the standardising scale of a monitored series is at least the one that puts this quantile of its |first
#: differences| / sqrt 2 where a normal series has it (:func:`null_sigma`): a heavy-tailed series (stick-slip
#: bursts, a sea that changes) is not scaled by its quiet bulk alone [-]
TAIL_Q = 0.95
#: a block coefficient whose standard error (:meth:`BlockSums.coefficients`) exceeds this many times the
#: median block's is left out of its series (NaN): nearly collinear or hardly excited features give heavy tails [-]
SE_MAX = 3.0
THRESHOLD_OP = 10.0  #: the same for the block-mean WOB [block sigmas]
CONSISTENT = 0.35  #: an operating change: |dW + A dp| at most this share of |dW| [-]
BLANK = 2  #: blocks on each side of an operating change left out of the component statistics [-]
#: smallest block-to-block noise of a standardised statistic [log units]: the spread of log(1 + z) of a
#: block at the noise level, z a mean of about 2 x CUTOFF x BLOCK independent squares, is ~sqrt(2/20)/2
SIGMA_MIN = 0.15
REFERENCE = 30  #: blocks before an onset the naming compares with [-]
#: a chain of at least this many effect alarms on one series, in one direction, each starting within DRIFT_LINK
#: blocks of the previous alarm, is one drift (:func:`merge_drifts`): a gas leak of the tuning set (350004-like,
#: 1.5e-6 /s) raised 11 alarms in 50 min, 170-210 s apart (RELEARN blocks, then the sum's climb); two alarms
#: can be a step and its relearning [-]
DRIFT_ALARMS = 3
DRIFT_LINK = RELEARN + 6  #: blocks from one alarm to the next one's onset within a drift [-]
#: features of the equations' own split (components.SPLIT) left out of the block coefficients: within
#: one block the time ``t`` is the constant again
NOT_PER_BLOCK = ("t",)
MIN_BLOCK_SAMPLES = 10  #: a block coefficient needs this many analysed samples (else NaN) [-]
#: a block coefficient needs its feature's sum of squares to reach this share of the median block's
#: (else NaN): a block in which the feature hardly varies (a small stroke for a position feature) gives a
#: coefficient of heavy tails, which a CUSUM reads as a change [-]
MIN_EXCITATION = 0.5
#: smallest block-to-block noise of a standardised block coefficient, as a share of its median
#: magnitude (a feature the residual never carries would otherwise be standardised by ~0) [-]
COEF_SIGMA_MIN = 1e-3
#: follow every equation's block constant (the top-mass balance has none in its split): the force balance of
#: the mean.  A WOB load-cell gain scales the measured WOB as a whole while the stroke, pressure and heave,
#: and the compensator's balance that sets the static WOB, are unchanged: the top-mass balance's constant
#: moves by the misread mean load, with the lower-mass balance (both read the WOB: ``sensors``).  A softer
#: formation changes the dynamics (the lower-mass coefficients) and leaves the mean's balance.  Without it
#: the top-mass balance was seen only through its mean square, which stick-slip bursts under a JONSWAP sea
#: standardise by a wide scale: a WOB gain moved it 2.6 sigmas (buoy: 12) and was named string_formation
BALANCE_CONSTANT = True
#: stroke bands (equal shares of the first chunk's stroke about its static value) in which the monitor follows
#: the block mean of the seal friction's residual times sign(v) (the friction the balance needs beyond the
#: nominal law, per direction): a worn band of the bore adds friction in one band of the stroke only, which
#: a block coefficient over the whole stroke dilutes (spent scoring sets: 3 of 4 position frictions missed) [-]
STROKE_BANDS = 4
#: the equation whose residual is followed per stroke band: the top-mass balance (its own component, the
#: seal friction, is odd in v)
BAND_EQUATION = "top_mass"
#: CUSUM threshold and Shewhart deviation of the stroke-band series [block sigmas]: a band holds a quarter of a
#: block's samples, and the outer bands the turnarounds' stick events, so its block means have heavier tails
#: than a block coefficient.  Tuning set (229 logs, 341 h of exposure): the coefficients' 8 sigmas and Shewhart
#: rule at 6: 22 false alarms, 18 of them in the bands, most by the Shewhart rule; 8 and no rule: 12; 10 and no
#: rule: 6 (as many as without the bands), goal changes 55 of 59 found, median 2.87 wave periods; 12-16: 6,
#: 3.00-3.09 periods; a rule at 10 sigmas: 13
THRESHOLD_BAND, JUMP_BAND = 10.0, math.inf
RIDGE = 1e-6  #: relative ridge of a block's normalised normal equations (features of unit scale) [-]
OP_CHANNELS = ("heave", "stroke", "pressure", "wob")
#: a log whose gap level (its largest component gap/noise over the whole log) reaches this is worth a diagnosis
#: (the fleet's "What next"): logs of the nominal plant itself read 1.00-1.24 from 5 to 50 Hz, 10 min and 2 h
#: (benchmarks/monitor/gap_levels.py); a seal friction 30 % high throughout 2.76 [-]
GAP_NOTABLE = 1.5
MIN_DURATION = 120.0  #: shortest log monitored [s]: a reference stretch of LEARN blocks and as many to compare
#: fewest blocks a log must hold to be monitored (MIN_DURATION at the default BLOCK): the upper bound of a
#: block (:func:`block_bounds`) [-]
MIN_BLOCKS = 12
#: a log of fewer than 2 LEARN blocks learns its reference over this share of its blocks (the rest is
#: compared with it), and says so (:func:`learning_window`): with the 300 s reference of a long log a 130 s log
#: was never compared with anything and a 30 kN WOB step in it passed without a word [-]
SHORT_LEARN_SHARE = 0.5
#: a block holds at least this share of the log's mean wave period (:func:`block_bounds`): a wave-driven
#: residual's square swings at twice the wave frequency, so half a period averages it; shorter blocks read
#: the wave phase as changes (0.1 s blocks: 79 "effect" changes on a clean 10 min log) [-]
BLOCK_MIN_PERIODS = 0.5


@dataclasses.dataclass
class MonitorResult:
    """What :func:`monitor` found (``to_json()``: the contract's ``monitor.json``).

    Attributes
    ----------
    t_blocks : array [s]  start of every block
    block : float [s]
    stats : {component: array}  block statistic (mean square of its parts / noise variance) [-]
    op : {channel: array}  block means [SI]
    sums : BlockSums  per block sums of the equation residuals and their parts
    changes : list of dict  (contract keys ``t``, ``component``, ``size_to_noise``, ``kind``; plus
        ``onset`` [s])
    segments : list of dict  (``start``, ``end``, ``operating_point``, ``gap_to_noise``)
    noise : {channel: sigma [SI]}
    sensors : list of channels the log had
    skipped : dict  what a missing channel left out: ``equations`` {equation: [missing channels it reads]},
        ``operating_point`` (why set-point changes are not detected or not checked by the load balance)
    """

    t_blocks: np.ndarray
    block: float
    stats: dict
    op: dict
    sums: object
    changes: list
    segments: list
    noise: dict
    sensors: list
    duration: float
    skipped: dict = dataclasses.field(default_factory=dict)
    #: blocks the reference was learnt from (:func:`learning_window`) [-]
    learn: int = LEARN
    #: what the reader should know of how the log was monitored (a shortened reference, ...)
    notes: list = dataclasses.field(default_factory=list)
    #: {component: gap/noise over the whole log} (:func:`segment_gap` over every block) [-]
    gap: dict = dataclasses.field(default_factory=dict)

    def gap_level(self) -> dict:
        """The log's gap level: its largest component gap/noise over the whole log (:func:`gap_level`)."""
        return gap_level(self.gap)

    def to_xarray(self, **attrs):
        """The result as an ``xarray.Dataset`` over ``segment`` (x ``component``) and ``change``
        (:func:`heavecomp.io.arrays.monitor_dataset`; units in each variable's ``attrs``).

        Parameters
        ----------
        **attrs : str
            Dataset attributes (e.g. ``source``).
        """
        return monitor_dataset(self.to_json(), attrs)

    def to_json(self) -> dict:
        extra = {"skipped": self.skipped} if self.skipped else {}
        if self.notes:
            extra["notes"] = list(self.notes)
        if self.gap:
            extra["gap_to_noise"] = dict(self.gap)
            extra["gap_level"] = self.gap_level()
        return {**extra, "schema": SCHEMA, "changes": self.changes, "segments": self.segments,
                "sensors": list(self.sensors), "block_s": self.block, "duration_s": self.duration,
                "noise": self.noise,
                "method": {"statistic": "log of the block mean square of each equation residual over its noise "
                                        "variance, and the block least-squares coefficients of each equation "
                                        "residual on its split's features",
                           "detector": "two-sided clipped CUSUM with a Shewhart rule", "drift_sigmas": DRIFT,
                           "threshold_sigmas": THRESHOLD, "threshold_equation_sigmas": THRESHOLD_EQ,
                           "jump_sigmas": JUMP, "jump_equation_sigmas": JUMP_EQ, "jump_blocks": JUMP_BLOCKS,
                           "threshold_op_sigmas": THRESHOLD_OP, "learn_blocks": self.learn, "chunk_s": CHUNK}}


# ---------------------------------------------------------------------------- helpers
def _block_edges(t, block):
    """Sample index where each block starts (and the end)."""
    starts = t[0] + block * np.arange(int(math.floor((t[-1] - t[0]) / block)) + 1)
    edges = np.searchsorted(t, starts)
    return np.unique(np.append(edges, t.size))


def _block_means(y, edges):
    ok = np.isfinite(y)
    s = np.add.reduceat(np.where(ok, y, 0.0), edges[:-1])
    n = np.add.reduceat(ok.astype(float), edges[:-1])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, s / np.maximum(n, 1), np.nan)


def robust_sigma(x) -> float:
    """Block-to-block noise of a series: 1.4826 MAD of its first differences / sqrt 2 (a step is
    one outlier among the differences, not a spread) [unit of x].

    Parameters
    ----------
    x : array
        A block series [any unit].
    """
    d = np.diff(np.asarray(x, float))
    d = d[np.isfinite(d)]
    if d.size < 4:
        return math.nan
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))


def null_sigma(x) -> float:
    """The scale a monitored block series is standardised by [unit of x]: the larger of its robust
    block-to-block noise (:func:`robust_sigma`) and the tail scale, the :data:`TAIL_Q` quantile of its
    |first differences - their median| / sqrt 2 over the normal quantile of the same two-sided
    probability.  For a normal series both agree; for a heavy-tailed one (a block statistic swept by
    stick-slip bursts, a block coefficient of a poorly conditioned block, a slowly changing sea) the
    bulk's MAD is far below its tails, and a CUSUM standardised by it is driven by the tails: the
    second method's false alarms (15 per 24 h on its scoring set) were all of that kind.

    Parameters
    ----------
    x : array
        A block series [any unit]; NaN blocks skipped.
    """
    s1 = robust_sigma(x)
    d = np.diff(np.asarray(x, float))
    d = d[np.isfinite(d)]
    if d.size < 20:
        return s1
    from statistics import NormalDist

    q = float(np.quantile(np.abs(d - np.median(d)), TAIL_Q)) / math.sqrt(2.0)
    st = q / NormalDist().inv_cdf(0.5 + TAIL_Q / 2.0)
    return max(s1, st) if math.isfinite(s1) else st


def cusum(u, learn=LEARN, drift=DRIFT, threshold=THRESHOLD, start=0, window=WINDOW, clip=CLIP, jump=JUMP,
          jump_blocks=JUMP_BLOCKS):
    """First alarm of a two-sided CUSUM on the columns of ``u`` (blocks x series, standardised).

    Self-starting: each column's reference is the mean of its finite values over the ``window`` blocks
    (from ``start`` on) before the CUSUM's current change-point estimate (the last block at which the
    sum was zero), so a change in progress does not leak into it and a slow drift of the sea state is
    followed; no alarm before ``learn`` finite values.  NaN blocks are skipped.  Each block's
    deviation is clipped at +-``clip`` sigmas (a robust CUSUM: one stick-slip burst in one block
    cannot raise an alarm alone; a lasting shift still adds every block).  Beside it a Shewhart rule:
    ``jump_blocks`` blocks in a row whose (unclipped) deviation is ``jump`` sigmas or more, of one sign,
    raise an alarm at once, the onset at the first of them (a large step is seen in two blocks, where
    the clipped sum needs ``threshold / (clip - drift)``).

    Returns (alarm block, column, onset block, mean shift between onset and alarm [sigmas]) or None.

    Parameters
    ----------
    u : array (blocks,) or (blocks, series)
        Standardised series [block sigmas]; NaN blocks skipped.
    learn : int
        Finite blocks before any alarm [-].
    drift : float [sigmas]
        Allowance k.
    threshold : float or array (series,) [sigmas]
        Decision threshold h, for all series or per series.
    start : int
        First block of the stretch.
    window : int
        Blocks of the reference before the change-point estimate.
    clip : float [sigmas]
        Largest deviation one block adds.
    jump : float or array (series,) [sigmas]
        Deviation of the Shewhart rule, for all series or per series (``math.inf``: none).
    jump_blocks : int
        Blocks in a row of the Shewhart rule.
    """
    u = np.asarray(u, float)
    if u.ndim == 1:
        u = u[:, None]
    n, m = u.shape
    jump = np.broadcast_to(np.asarray(jump, float), (m,))
    ok = np.isfinite(u[start:])
    v = np.where(ok, u[start:], 0.0)
    cs = np.vstack([np.zeros((1, m)), np.cumsum(v, axis=0)])   # prefix sums from ``start``
    cn = np.vstack([np.zeros((1, m)), np.cumsum(ok, axis=0)])
    hi, lo = np.zeros(m), np.zeros(m)
    z_hi, z_lo = np.zeros(m, int), np.zeros(m, int)  # local index of the change-point estimates
    r_hi, r_lo = np.zeros(m, int), np.zeros(m, int)  # blocks in a row beyond +-jump (Shewhart rule)
    big = np.zeros(m)
    for i in range(n - start):
        row = v[i]
        big[:] = 0.0
        for j in range(m):
            if not ok[i, j]:
                continue
            cut = min(z_hi[j], z_lo[j])
            w0 = max(0, cut - window)
            nref = cn[cut, j] - cn[w0, j]
            if cn[cut, j] < learn or nref < 1:  # still learning: no evidence of change yet
                z_hi[j] = z_lo[j] = i + 1
                continue
            d0 = row[j] - (cs[cut, j] - cs[w0, j]) / nref
            r_hi[j] = r_hi[j] + 1 if d0 >= jump[j] else 0
            r_lo[j] = r_lo[j] + 1 if d0 <= -jump[j] else 0
            if max(r_hi[j], r_lo[j]) >= jump_blocks:
                big[j] = abs(d0)
            d = min(max(d0, -clip), clip)
            hi[j] = max(0.0, hi[j] + d - drift)
            lo[j] = max(0.0, lo[j] - d - drift)
            if hi[j] == 0.0:
                z_hi[j] = i + 1
            if lo[j] == 0.0:
                z_lo[j] = i + 1
        over = np.maximum(hi, lo) / threshold
        over = np.where(big > 0, np.maximum(over, 1.0 + big), over)
        if (over >= 1.0).any():
            j = int(np.argmax(over))
            if big[j] > 0:  # the Shewhart rule: the change began with its run of large deviations
                on = i + 1 - jump_blocks
            else:
                on = int(z_hi[j] if hi[j] >= lo[j] else z_lo[j])
            cut = min(z_hi[j], z_lo[j])
            w0 = max(0, cut - window)
            ref = (cs[cut, j] - cs[w0, j]) / max(cn[cut, j] - cn[w0, j], 1)
            k = cn[i + 1, j] - cn[on, j]
            shift = (cs[i + 1, j] - cs[on, j]) / k - ref if k > 0 else 0.0
            return start + i, j, start + on, float(abs(shift))
    return None


# ---------------------------------------------------------------------------- pass 1: operating point
def operating_changes(op, block_t, block, params, *, threshold=THRESHOLD_OP, learn=LEARN):
    """Changes of the block-mean WOB; each classified by the load balance (module docstring).

    Returns (list of change dicts, list of operating boundaries as block indices).

    Parameters
    ----------
    op : dict
        Block means per channel (``wob``, ``pressure``, ...) [SI].
    block_t : array [s]
        Start of every block.
    block : float [s]
        Block length.
    params : CMCParams
        Nominal parameters (the cylinder area of the load balance).
    threshold : float [sigmas]
        CUSUM threshold of the block-mean WOB.
    learn : int
        Blocks learnt before any alarm.
    """
    w, p = op["wob"], op["pressure"]
    sw = robust_sigma(w)
    out, bounds = [], []
    if not (sw > 0):
        return out, bounds
    u = (w / sw)[:, None]
    start = 0
    while True:
        hit = cusum(u, learn=learn, threshold=threshold, start=start, jump=math.inf)
        if hit is None:
            break
        b, _, onset, size = hit
        before = w[max(onset - learn, 0):onset]
        after = w[onset + 1:min(onset + 1 + learn, w.size)]
        pb, pa = p[max(onset - learn, 0):onset], p[onset + 1:min(onset + 1 + learn, w.size)]
        dW = float(np.nanmedian(after) - np.nanmedian(before)) if after.size and before.size else math.nan
        dp = float(np.nanmedian(pa) - np.nanmedian(pb)) if pa.size and pb.size else math.nan
        checked = bool(np.isfinite(p).any())
        operating = not checked or (math.isfinite(dW) and math.isfinite(dp)
                                    and abs(dW + params.area * dp) <= CONSISTENT * abs(dW))
        out.append({"t": float(block_t[b] + block), "component": "operating_point" if operating else "sensors",
                    "size_to_noise": size, "kind": "operating" if operating else "effect",
                    "onset": float(block_t[onset]), "wob_step": dW, "pressure_step": dp if checked else None})
        if not checked:
            out[-1]["load_balance"] = "unchecked: no pressure channel"
        if operating:
            bounds.append(onset)
        start = b + 1
    return out, bounds


# ---------------------------------------------------------------------------- pass 2: residuals
def _chunks(lo, hi, per):
    """Block-index ranges [a, b) of at most ``per`` blocks covering blocks lo..hi."""
    a = lo
    while a < hi:
        yield a, min(a + per, hi)
        a = min(a + per, hi)


@dataclasses.dataclass
class BlockSums:
    """Per block: sums of squares of each equation residual and of each component's part of it, and
    the samples they cover (raw, in the equation's unit squared); ``noise`` {equation: [unit]} is the
    equation noise of the first chunk, which normalises every block (a per-chunk noise estimate
    would step at every chunk edge)."""

    eq: dict
    parts: dict
    count: dict
    noise: dict
    xtx: dict = dataclasses.field(default_factory=dict)
    xtr: dict = dataclasses.field(default_factory=dict)
    #: {equation: (blocks x bands)} sums of residual x sign(v) and sample counts per stroke band
    #: (:data:`STROKE_BANDS`), and the bands' inner edges [m from the segment's static stroke]
    band_sum: dict = dataclasses.field(default_factory=dict)
    band_count: dict = dataclasses.field(default_factory=dict)
    band_edges: object = None
    #: {(component, equation): per block sum of squares of the nominal replay's part} (the floor
    #: :func:`segment_gap` subtracts, as the diagnosis does: what the equations make of the nominal model's own
    #: replay, filters and stick events, :func:`nominal_replay`) [equation unit squared]
    floor: dict = dataclasses.field(default_factory=dict)

    def band_means(self, e) -> np.ndarray:
        """Block mean of equation ``e``'s residual times sign(v) in each stroke band (blocks x bands)
        [residual unit]; NaN where a band has fewer than :data:`MIN_BLOCK_SAMPLES` analysed samples."""
        n = self.band_count[e]
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n >= MIN_BLOCK_SAMPLES, self.band_sum[e] / np.maximum(n, 1), np.nan)

    def coefficients(self, e, with_se=False):
        """Block least-squares coefficients of equation ``e``'s residual on its features
        (:func:`coefficient_features`), jointly per block (blocks x features) [residual unit per feature
        unit]; NaN where the block has fewer than :data:`MIN_BLOCK_SAMPLES`, and for a feature whose
        sum of squares in the block is below :data:`MIN_EXCITATION` of the median block's (it is left
        out of that block's fit).  ``with_se``: also each block coefficient's standard error (blocks x
        features): the block's residual rms after its fit times sqrt of the diagonal of the inverse
        normal equations (the feature's variance inflation by the others, over its scale)."""
        A, y = self.xtx[e], self.xtr[e]
        nb, m = y.shape
        d = np.einsum("bii->bi", A).copy()
        ok_b = self.count[e] >= MIN_BLOCK_SAMPLES
        ex = np.zeros((nb, m), bool)
        for k in range(m):
            good = ok_b & (d[:, k] > 0)
            if good.any():
                ex[:, k] = good & (d[:, k] >= MIN_EXCITATION * float(np.median(d[good, k])))
        sc = np.where(ex, np.sqrt(np.where(ex, d, 1.0)), 1.0)
        An = A / (sc[:, :, None] * sc[:, None, :])
        yn = y / sc
        mask2 = ex[:, :, None] & ex[:, None, :]
        eye = np.broadcast_to(np.eye(m), An.shape)
        An = np.where(mask2, An, eye) + RIDGE * eye  # a feature left out: its own row, coefficient 0
        yn = np.where(ex, yn, 0.0)
        beta = np.linalg.solve(An, yn[..., None])[..., 0] / sc
        beta = np.where(ex, beta, np.nan)
        if not with_se:
            return beta
        inv = np.einsum("bii->bi", np.linalg.inv(An))
        rss = self.eq[e] - np.einsum("bi,bi->b", np.nan_to_num(beta), y)
        with np.errstate(invalid="ignore", divide="ignore"):
            rms = np.sqrt(np.maximum(rss, 0.0) / np.maximum(self.count[e] - m, 1))
        return beta, np.where(ex, np.sqrt(np.maximum(inv, 0.0)) / sc * rms[:, None], np.nan)

    def z_eq(self, e) -> np.ndarray:
        """Block mean square of equation ``e``'s residual over its noise variance [-]."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.count[e] > 0, self.eq[e] / np.maximum(self.count[e], 1), np.nan) / self.noise[e] ** 2

    def z_part(self, c, e) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.count[e] > 0, self.parts[(c, e)] / np.maximum(self.count[e], 1),
                            np.nan) / self.noise[e] ** 2

    def stats(self) -> dict:
        """{component: block mean square of its parts over their equations' noise variances} [-]."""
        out = {}
        for c in COMPONENTS:
            zs = [self.z_part(c2, e) for (c2, e) in self.parts if c2 == c]
            out[c] = np.sum(zs, axis=0) if zs else np.full(next(iter(self.eq.values())).size, np.nan)
        return out


def _stand_in(channel, params, n) -> np.ndarray:
    """A constant in place of a channel the log lacks (its nominal static value: the WOB set-point, the
    charge pressure, mid-stroke 0), read only by equations the monitor leaves out [SI]."""
    v = {"wob": params.operating_point.wob_setpoint, "pressure": params.p0}.get(channel, 0.0)
    return np.full(n, float(v))


def usable_equations(sensors) -> tuple:
    """(equations every channel of which the log has, {left-out equation: [missing channels it reads]})
    from the model's structure (:func:`heavecomp.diagnosis.structure.equation_channels`).

    Parameters
    ----------
    sensors : sequence of str
        The channels the log has.
    """
    eqc = equation_channels()
    use = tuple(e for e, chs in eqc.items() if all(c in sensors for c in chs))
    skip = {e: [c for c in chs if c not in sensors] for e, chs in eqc.items() if e not in use}
    return use, skip


def coefficient_features() -> dict:
    """{equation: ((component, feature), ...)}: the features whose block coefficients the monitor follows
    (the equation's own split, :data:`heavecomp.diagnosis.components.SPLIT`, less :data:`NOT_PER_BLOCK`;
    the own component's nominal structure, ``components.STRUCTURE``, where the split lists none: the
    seal friction's sign(v) and v in the top-mass balance; with :data:`BALANCE_CONSTANT`, every
    equation's constant, under its own component: the top-mass balance's is the force balance of the
    mean, which a misread load moves and a seal friction, odd in v, does not)."""
    out = {}
    for e, split in CR.SPLIT.items():
        keys = [(c, f) for c, fs in split.items() for f in fs if f not in NOT_PER_BLOCK]
        own = CR.OWN[e]
        if not split.get(own):
            keys += [(own, f) for f in CR.STRUCTURE.get(own, ())]
        if BALANCE_CONSTANT and not any(f == "const" for _, f in keys):
            keys.append((own, "const"))
        out[e] = tuple(keys)
    return out


def _new_sums(cr, nb, feats) -> BlockSums:
    """Empty block sums for the equations of the first chunk's residuals ``cr`` over ``nb`` blocks."""
    sums = BlockSums({e: np.zeros(nb) for e in cr.equations}, {}, {e: np.zeros(nb) for e in cr.equations},
                     {e: cr.noise[e] for e in cr.equations})
    for e in cr.equations:
        m = len(feats.get(e, ()))
        sums.xtx[e], sums.xtr[e] = np.zeros((nb, m, m)), np.zeros((nb, m))
    return sums


def _open_bands(sums, cr, nb, xs) -> None:
    """The stroke bands of :data:`BAND_EQUATION`: edges at the quantiles of the first chunk's stroke about
    the segment's static stroke ``xs`` [m], and empty per-band sums over ``nb`` blocks."""
    r = cr.equations[BAND_EQUATION]
    ok = cr.mask & np.isfinite(r)
    xr = cr.signals["x"][ok] - xs
    sums.band_edges = (np.quantile(xr, np.arange(1, STROKE_BANDS) / STROKE_BANDS) if xr.size
                       else np.zeros(STROKE_BANDS - 1))
    sums.band_sum[BAND_EQUATION] = np.zeros((nb, STROKE_BANDS))
    sums.band_count[BAND_EQUATION] = np.zeros((nb, STROKE_BANDS))


def _add_chunk(sums, cr, blocks, loc, feats, xs) -> None:
    """Add one chunk's residuals ``cr`` into ``sums`` for the blocks ``blocks`` (a slice), which start at the
    chunk's samples ``loc[:-1]``: squared residual, count, regression sums, per-band sums and component
    parts per equation."""
    at = loc[:-1]
    for e, r in cr.equations.items():
        ok = cr.mask & np.isfinite(r)
        sums.eq[e][blocks] = np.add.reduceat(np.where(ok, r * r, 0.0), at)
        sums.count[e][blocks] = np.add.reduceat(ok.astype(float), at)
        X = [np.where(ok, CR._column(cr.signals, f), 0.0) for _, f in feats.get(e, ())]
        r0 = np.where(ok, r, 0.0)
        if e in sums.band_sum:
            band = np.searchsorted(sums.band_edges, cr.signals["x"] - xs)
            rs = r0 * np.sign(cr.signals["v"])
            for k in range(STROKE_BANDS):
                inb = ok & (band == k)
                sums.band_sum[e][blocks, k] = np.add.reduceat(np.where(inb, rs, 0.0), at)
                sums.band_count[e][blocks, k] = np.add.reduceat(inb.astype(float), at)
        for i, xi in enumerate(X):
            sums.xtr[e][blocks, i] = np.add.reduceat(xi * r0, at)
            for k in range(i + 1):
                sums.xtx[e][blocks, i, k] = sums.xtx[e][blocks, k, i] = np.add.reduceat(xi * X[k], at)
        for c in COMPONENTS:
            part = cr.parts.get(c, {}).get(e)
            if part is not None:
                sums.parts.setdefault((c, e), np.zeros(sums.eq[e].size))[blocks] = \
                    np.add.reduceat(np.where(ok, part * part, 0.0), at)
            fpart = cr.floor_parts.get(c, {}).get(e)
            if fpart is not None:
                sums.floor.setdefault((c, e), np.zeros(sums.eq[e].size))[blocks] = \
                    np.add.reduceat(np.where(ok & np.isfinite(fpart), fpart * fpart, 0.0), at)


#: the nominal replay's floor (:func:`nominal_replay`) is replayed on an operating segment's first chunk and every
#: FLOOR_EVERY-th after it; the chunks between take the last replayed chunk's floor per sample (it is set by the
#: sea state, which the 30-min reference follows too).  Every chunk: 2 h at 10 Hz monitored in 7.4 s, 24 h ~90 s
#: against the benchmark's 60 s; every third: ~1/3 of the replays' cost, the same gap/noise at 5 and 10 Hz [-]
FLOOR_EVERY = 3
#: above this rate every chunk is replayed: the floor's share of the noise grows with the rate (the noise is
#: filtered to the same band, the filters' smear of stick events is not), and so does the error of taking another
#: chunk's: 2 h no-effect logs read friction 1.26 (25 Hz) and 1.44 (50 Hz) with every third, 1.09 and 1.15 with
#: every chunk; the replay's cost does not grow with the rate (its own step), the monitor's other passes do [Hz]
FLOOR_RATE = 15.0


def nominal_replay(sub, params, heave_reference) -> dict:
    """The nominal model's replay of one chunk ``sub`` as the diagnosis replays a log
    (:func:`heavecomp.diagnosis.replay.build`: its heave pre-processing, its start-state estimate from the
    chunk's first seconds, the file's own plant effects), its plant driven by the measured heave about
    ``heave_reference`` [m], the reference the chunk's equation residuals use (a replay about another
    reference would read the difference as a string deflection).  Returns {stroke, pressure, wob: array}
    at the chunk's samples [SI]: the floor of the chunk's component residuals (``floor_channels`` of
    :func:`heavecomp.diagnosis.components.residuals`).  The replay satisfies the model's equations
    exactly, whatever its start, so what its equation residuals show is the filters' smear of its stick
    events and the heave pre-processing: what a log of the nominal model shows too, in a share of the
    noise that grows with the rate (the noise is filtered to the same band, the artefacts are not).

    Parameters
    ----------
    sub : MeasuredRun
        The chunk (any clock; the columns the log has).
    params : CMCParams
        The segment's nominal parameters.
    heave_reference : float [m]
        The heave of the segment's operating point.
    """
    r0 = MeasuredRun(sub.t - sub.t[0], dict(sub.columns), source=sub.source)
    rp = R.build(r0, params)
    rp = dataclasses.replace(rp, hs=heave_samples(r0, rp.h, rp.n_steps, reference=heave_reference, spline=rp.spline))
    nom = rp.simulate([])
    return {k: np.asarray(nom[k], float) for k in ("stroke", "pressure", "wob")}


def segment_point(params, w_segment, w_first):
    """The nominal parameters of an operating segment: the file's own operating point for the first
    (as the diagnosis takes it), a later one's WOB set-point moved by its block-median WOB's step from
    the first segment's.  The mean WOB of a compensated string is not its set-point (the seal friction
    holds it off by ~0.4 kN on paper A under JONSWAP), so taking a segment's median WOB as its set-point
    moves the gas law's charge pressure and the string's static deflection by that offset: it read as a
    gap of 4-8 noise sigmas in the gas law and the lower-mass balance of a nominal log.

    Parameters
    ----------
    params : CMCParams
        The file's parameters.
    w_segment, w_first : float [N]
        The block-median WOB of the segment and of the first segment (NaN: no WOB channel).
    """
    if not (math.isfinite(w_segment) and math.isfinite(w_first)) or w_segment == w_first:
        return params
    w0 = params.operating_point.wob_setpoint + (w_segment - w_first)
    return params.replace(operating_point={"wob_setpoint": w0}) if w0 > 0 else params


def segment_heave_reference(op, a, b, params) -> float:
    """The heave reference of an operating segment (its reference stretch, blocks a..b) [m]: the median over
    those blocks of the
    heave the quasi-static string balance implies (:func:`heavecomp.diagnosis.start.string_balance_heave`,
    the diagnosis' own start estimate of it) from the block means of heave, stroke and WOB (a missing
    stroke: 0; a missing WOB: the set-point).  The segment's median heave is not it: the string is stiff
    (2 MN/m on paper A), so a 1 mm difference reads as 2 kN of string tension, a gap of several noise
    sigmas in the lower-mass balance of a nominal log at 5 Hz.

    Parameters
    ----------
    op : dict
        Block means per channel [SI].
    a, b : int
        First and past-the-last block of the segment.
    params : CMCParams
        The segment's nominal parameters (:func:`segment_point`).
    """
    z = op["heave"][a:b]
    s = np.nan_to_num(op["stroke"][a:b], nan=0.0)
    w = op["wob"][a:b]
    w = np.where(np.isfinite(w), w, params.operating_point.wob_setpoint)
    zr = string_balance_heave(z, s, w, params)
    return float(np.nanmedian(zr)) if np.isfinite(zr).any() else 0.0


def component_blocks(run, params, edges, op_bounds, op, noise, *, block=BLOCK, chunk=CHUNK, pad=PAD,
                     progress=None, equations=None, learn=LEARN) -> BlockSums:
    """Block sums of the equation residuals and their component parts (pass 2), chunk by chunk, each
    operating segment with its own operating point.

    Parameters
    ----------
    run : MeasuredRun
    params : CMCParams
        Nominal parameters.
    edges : array of int
        Sample index where each block starts, and the end.
    op_bounds : list of int
        Blocks where an operating change begins.
    op : dict
        Block means per channel [SI].
    noise : dict
        Channel -> noise sigma [SI].
    block : float [s]
    chunk : float [s]
        Component-residual window.
    pad : float [s]
        Extra samples on each side of a chunk.
    progress : callable (fraction, message), optional
    equations : sequence of str, optional
        The equations to follow (default: every one); a channel the log lacks is given a constant
        stand-in (:func:`_stand_in`) that only the equations left out read.
    learn : int
        Blocks of a segment's reference stretch: its heave reference is read over them
        (:func:`segment_heave_reference`), so a later change of the WOB's reading does not move it.
    """
    nb = edges.size - 1
    t = run.t
    sums = None
    seg_edges = [0] + sorted(op_bounds) + [nb]
    per = max(1, int(round(chunk / block)))
    done = 0
    feats = coefficient_features()
    every = 1 if (t.size - 1) / max(t[-1] - t[0], 1e-300) > FLOOR_RATE else FLOOR_EVERY

    def median_wob(a, b):
        return float(np.nanmedian(op["wob"][a:b])) if np.isfinite(op["wob"][a:b]).any() else math.nan

    w_first = median_wob(seg_edges[0], seg_edges[1])
    for s0, s1 in zip(seg_edges[:-1], seg_edges[1:]):
        if s1 <= s0:
            continue
        prm = segment_point(params, median_wob(s0, s1), w_first)
        zref = segment_heave_reference(op, s0, min(s1, s0 + learn), prm)
        xs = float(np.nanmedian(op["stroke"][s0:s1])) if np.isfinite(op["stroke"][s0:s1]).any() else 0.0
        floor_ms = None  # the segment's last replayed floor: mean square per analysed sample {(c, e): value}
        for n_chunk, (a, b) in enumerate(_chunks(s0, s1, per)):
            i0, i1 = edges[a], edges[b]
            j0 = int(np.searchsorted(t, t[i0] - pad))
            j1 = int(np.searchsorted(t, t[i1 - 1] + pad, side="right"))
            if j1 - j0 < 50:
                continue
            sub = MeasuredRun(t[j0:j1], {k: run[k][j0:j1] if k in run.columns else _stand_in(k, params, j1 - j0)
                                         for k in OP_CHANNELS}, source=run.source)
            own = MeasuredRun(t[j0:j1], {k: run[k][j0:j1] for k in OP_CHANNELS if k in run.columns},
                              source=run.source)
            replay = floor_ms is None or n_chunk % every == 0
            cr = CR.residuals(sub, prm, heave_reference=zref, noise=noise,
                              floor_channels=nominal_replay(own, prm, zref) if replay else None)
            if equations is not None:
                cr.equations = {e: r for e, r in cr.equations.items() if e in equations}
            if sums is None:
                sums = _new_sums(cr, nb, feats)
            if STROKE_BANDS > 1 and BAND_EQUATION in cr.equations and BAND_EQUATION not in sums.band_sum:
                _open_bands(sums, cr, nb, xs)
            _add_chunk(sums, cr, slice(a, b), edges[a:b + 1] - j0, feats, xs)
            if replay:
                floor_ms = {k: float(v[a:b].sum()) / max(float(sums.count[k[1]][a:b].sum()), 1.0)
                            for k, v in sums.floor.items()}
            else:  # between replays: the last replayed chunk's floor per sample, over this chunk's samples
                for k, ms in floor_ms.items():
                    sums.floor[k][a:b] = ms * sums.count[k[1]][a:b]
            done += b - a
            if progress:
                progress(done / max(nb, 1), f"component residuals to {t[i1 - 1]:.0f} s")
    for bnd in op_bounds:  # the filters straddle an operating change
        for e in sums.count:
            sums.count[e][max(bnd - BLANK, 0):bnd + BLANK] = 0.0
        for e in sums.band_count:
            sums.band_count[e][max(bnd - BLANK, 0):bnd + BLANK] = 0.0
    return sums


# ---------------------------------------------------------------------------- pass 3: changes
def _standardised(z):
    """log(1 + z) over its noise (:func:`null_sigma`, floored at :data:`SIGMA_MIN`)."""
    x = np.log1p(np.maximum(z, 0.0))
    return x / max(null_sigma(x), SIGMA_MIN)


def _name(sums, e, onset, alarm, start):
    """The component of equation ``e`` whose part grew most between the reference blocks (before the
    onset, at most :data:`REFERENCE` of them) and onset..alarm [noise variances]."""
    ref = slice(max(start, onset - REFERENCE), onset)
    new = slice(onset, alarm + 1)
    best, grow = None, -math.inf
    for (c, e2) in sums.parts:
        if e2 != e:
            continue
        z = sums.z_part(c, e)
        d = float(np.nanmean(z[new]) - np.nanmean(z[ref])) if np.isfinite(z[ref]).any() else float(np.nanmean(z[new]))
        if d > grow:
            best, grow = c, d
    return best


def _component(sums, moved, e, onset, alarm, start):
    """The component of a change from the equations that moved (the structure,
    :mod:`heavecomp.diagnosis.structure`): one equation -> the part of it that grew; the set of
    equations that read one channel (``components.READS``; the heave: ``structure.HEAVE_READS``) ->
    ``heave_input`` if its parts changed more than the equations' own rests, else ``sensors`` (a
    channel that misreads shows in every equation reading it; its rests may grow or shrink)."""
    if len(moved) > 1 and any(moved == set(eqs) for eqs in CR.READS.values()):
        own = sum(abs(_growth(sums, [(CR.OWN[x], x)], onset, alarm, start)) for x in moved)
        hv = sum(abs(_growth(sums, [("heave_input", x)], onset, alarm, start)) for x in moved)
        return "heave_input" if hv > own else "sensors"
    return _name(sums, e, onset, alarm, start)


def _growth(sums, keys, onset, alarm, start) -> float:
    ref = slice(max(start, onset - REFERENCE), onset)
    new = slice(onset, alarm + 1)
    g = 0.0
    for c, e in keys:
        if (c, e) in sums.parts:
            z = sums.z_part(c, e)
            g += float(np.nanmean(z[new]) - (np.nanmean(z[ref]) if np.isfinite(z[ref]).any() else 0.0))
    return g


def _standardised_coef(c, se=None):
    """A block coefficient over its noise (:func:`null_sigma`, floored at :data:`COEF_SIGMA_MIN` of its
    median magnitude): signed, so a change of the law's coefficient is seen with its sign.  With ``se``
    (each block's standard error), a block whose standard error exceeds :data:`SE_MAX` times the median
    block's is left out (NaN)."""
    c = np.asarray(c, float)
    if se is not None and np.isfinite(se).any():
        with np.errstate(invalid="ignore"):
            c = np.where(np.asarray(se, float) <= SE_MAX * float(np.nanmedian(se)), c, np.nan)
    sig = null_sigma(c)
    med = float(np.nanmedian(np.abs(c))) if np.isfinite(c).any() else 0.0
    floor = max(COEF_SIGMA_MIN * med, 1e-300)
    return c / max(sig if math.isfinite(sig) else floor, floor)


def columns(sums):
    """The monitored block series: (names, components, equations, standardised matrix).

    One column per equation (its mean square, :func:`_standardised`; component None: named from its
    parts) and one per (equation, feature) block coefficient (:func:`coefficient_features`; the
    component whose law the feature belongs to).

    Parameters
    ----------
    sums : BlockSums
    """
    names, comps, eqs, cols = [], [], [], []
    for e in sums.eq:
        names.append(e), comps.append(None), eqs.append(e), cols.append(_standardised(sums.z_eq(e)))
    for e, keys in coefficient_features().items():
        if e not in sums.xtr:
            continue
        beta, se = sums.coefficients(e, with_se=True)
        for k, (c, f) in enumerate(keys):
            names.append(f"{e}:{f}"), comps.append(c), eqs.append(e)
            cols.append(_standardised_coef(beta[:, k], se[:, k]))
    for e in sums.band_sum:  # the seal friction per stroke band: the equation's own component
        bm = sums.band_means(e)
        for k in range(bm.shape[1]):
            names.append(f"{e}:band{k}"), comps.append(CR.OWN[e]), eqs.append(e)
            cols.append(_standardised_coef(bm[:, k]))
    return names, comps, eqs, np.column_stack(cols)


def _shift(u, onset, alarm, start):
    """Per column: |mean over the last :data:`MOVED_BLOCKS` up to the alarm - mean over the reference
    blocks before the onset| [block sigmas] (0 where the reference has no finite block)."""
    ref = slice(max(start, onset - REFERENCE), onset)
    new = slice(max(onset, alarm + 1 - MOVED_BLOCKS), alarm + 1)
    with warnings.catch_warnings():  # an all-NaN column (nothing analysed): no move
        warnings.simplefilter("ignore", RuntimeWarning)
        d = np.abs(np.nanmean(u[new], axis=0) - np.nanmean(u[ref], axis=0))
    return np.nan_to_num(d)


def _attribute_change(sums, names, comps, eqs, u, j, onset, alarm, start):
    """(component, equations that moved) of an alarm in column ``j``, from the structure.

    The columns that moved with it (:data:`MOVED` sigmas and :data:`MOVED_SHARE` of the alarming
    column's move) give the equations that moved.  Exactly the equations that read one channel
    (``components.READS``), more than one -> ``sensors`` (or ``heave_input``: :func:`_component`).
    Otherwise the component of the feature coefficient that moved most among the moved equations'
    features (the law's own shape: a softer formation moves the lower-mass coefficient of the
    relative displacement, a leak the gas law's constant, a seal friction the top-mass coefficients
    of sign(v)); if no coefficient moved, the part of the alarming equation that grew."""
    d = _shift(u, onset, alarm, start)
    move = {}
    for k, e in enumerate(eqs):
        move[e] = max(move.get(e, 0.0), d[k])
    moved = {e for e, x in move.items() if x >= MOVED and x >= MOVED_SHARE * d[j]} | {eqs[j]}
    if len(moved) > 1 and any(moved == set(r) for r in CR.READS.values()):
        return _component(sums, moved, eqs[j], onset, alarm, start), moved
    coef = [k for k in range(len(names)) if comps[k] is not None and eqs[k] in moved and d[k] >= COEF_MOVED]
    if coef:
        return comps[max(coef, key=lambda k: d[k])], moved
    return _name(sums, eqs[j], onset, alarm, start), moved


def component_changes(sums, block_t, block, op_bounds, *, threshold=THRESHOLD, learn=LEARN, jump_eq=JUMP_EQ):
    """CUSUM changes of the equation statistics and block coefficients (pass 3), named by
    :func:`_attribute_change`, restarting at every operating boundary and after every alarm.

    Parameters
    ----------
    sums : BlockSums
    block_t : array [s]
        Start of every block.
    block : float [s]
    op_bounds : list of int
        Blocks where an operating change begins.
    threshold : float [sigmas]
        CUSUM threshold.
    learn : int
        Blocks learnt at a stretch's start.
    jump_eq : float [sigmas]
        The Shewhart rule's deviation on the equations' mean squares (:data:`JUMP_EQ`; a short log:
        :data:`JUMP_EQ_SHORT`).
    """
    names, comps, eqs, u = columns(sums)
    band = [":band" in n for n in names]
    jumps = np.array([jump_eq if c is None else JUMP_BAND if b else JUMP for c, b in zip(comps, band)])
    thresholds = np.array([THRESHOLD_EQ if c is None else THRESHOLD_BAND if b else threshold
                           for c, b in zip(comps, band)])
    out = []
    nb = u.shape[0]
    restarts = sorted(set(op_bounds) | {0})
    start = 0
    while start < nb:
        stop = next((r for r in restarts if r > start), nb)
        hit = cusum(u[:stop], learn=learn if start in restarts else min(RELEARN, learn), start=start,
                    jump=jumps, threshold=thresholds)
        if hit is None:
            start = stop
            continue
        b, j, onset, size = hit
        comp, moved = _attribute_change(sums, names, comps, eqs, u, j, onset, b, start)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            sign = np.nanmean(u[onset:b + 1, j]) - np.nanmean(u[max(start, onset - REFERENCE):onset, j])
        out.append({"t": float(block_t[b] + block), "component": comp, "size_to_noise": size, "kind": "effect",
                    "onset": float(block_t[onset]), "equations": sorted(moved), "column": names[j],
                    "direction": 1 if not sign < 0 else -1})
        start = b + 1
    return merge_drifts(out, u, names, block_t, block)


def merge_drifts(changes, u, names, block_t, block) -> list:
    """Effect alarms that follow one drift, as one change.  A slowly growing effect (a gas leak) is alarmed,
    the CUSUM restarts, relearns for :data:`RELEARN` blocks and alarms again, on the same series in the same
    direction, as long as the drift goes on: a chain of :data:`DRIFT_ALARMS` or more such alarms, each
    starting within :data:`DRIFT_LINK` blocks of the previous alarm, is one change (``kind`` ``effect``, at
    the first alarm and onset) with ``drift`` true, ``until`` [s] (the last alarm), ``alarms`` (how many it
    merges), ``rate`` [noise sigmas per hour] (the least-squares slope of the standardised series from the
    onset to the last alarm; the sign of its direction) and ``rate_unit``; the component is the one most of
    its alarms named.

    Parameters
    ----------
    changes : list of dict
        The effect alarms in time order (:func:`component_changes`).
    u : array (blocks, series)
        The standardised series (:func:`columns`).
    names : list of str
        Their names.
    block_t : array [s]
    block : float [s]
    """
    out, i = [], 0
    while i < len(changes):
        k = i + 1
        while (k < len(changes) and changes[k]["column"] == changes[i]["column"]
               and changes[k]["direction"] == changes[i]["direction"]
               and changes[k]["onset"] - changes[k - 1]["t"] <= DRIFT_LINK * block):
            k += 1
        chain = changes[i:k]
        if len(chain) < DRIFT_ALARMS:
            out.extend(chain)
            i = k
            continue
        first, last = chain[0], chain[-1]
        j = names.index(first["column"])
        a, b = int(np.searchsorted(block_t, first["onset"])), int(np.searchsorted(block_t, last["t"] - block)) + 1
        y, x = u[a:b, j], (block_t[a:b] + 0.5 * block) / 3600.0
        ok = np.isfinite(y)
        rate = float(np.polyfit(x[ok], y[ok], 1)[0]) if ok.sum() >= 3 else math.nan
        comps = [c["component"] for c in chain]
        merged = dict(first, component=max(set(comps), key=lambda c: (comps.count(c), -comps.index(c))),
                      equations=sorted({e for c in chain for e in c["equations"]}), drift=True, until=last["t"],
                      alarms=len(chain), rate=rate, rate_unit="noise sigma/h")
        out.append(merged)
        i = k
    return out


def one_per_misreading(op_changes, effects) -> list:
    """The operating changes and the effect changes, a WOB that moved alone counted once: the operating
    point's detector names it ``sensors`` (the load balance does not carry it) and the component
    residuals alarm on it too (both balances read the WOB).  An effect alarm of the same component whose
    onset is within :data:`OP_SLACK` of such a change's is the same change: the earlier detection is kept,
    with the other's keys it lacks (``wob_step``, ``pressure_step``, ``equations``).

    Parameters
    ----------
    op_changes : list of dict
        :func:`operating_changes`' changes.
    effects : list of dict
        The component residuals' effect changes.
    """
    out = [dict(e) for e in effects]
    for o in op_changes:
        twin = next((e for e in out if o["kind"] == "effect" and e["component"] == o["component"]
                     and abs(e["onset"] - o["onset"]) <= OP_SLACK), None)
        if twin is None:
            out.append(o)
            continue
        first, other = (twin, o) if twin["t"] <= o["t"] else (dict(o), twin)
        merged = {**{k: v for k, v in other.items() if k not in first}, **first}
        out[out.index(twin)] = merged
    return out


def absorbed(effect, op_changes) -> bool:
    """An effect alarm that an operating change explains: it falls between :data:`OP_SLACK` before the
    operating change's onset and its alarm (the new set-point reached the residuals before the
    block-mean WOB had moved enough).

    Parameters
    ----------
    effect : dict
        An effect change.
    op_changes : list of dict
        The operating changes.
    """
    return any(o["kind"] == "operating" and o["onset"] - OP_SLACK <= effect["t"] <= o["t"] + OP_SLACK
               and effect["onset"] <= o["t"] for o in op_changes)


def segment_gap(sums, a, b) -> dict:
    """gap_to_noise per component over blocks a..b: sqrt(1 + gap), the gap computed as the diagnosis
    computes it (:func:`heavecomp.diagnosis.components.gap_of`: its parts' mean squares over their
    equations' noise variances, less the noise's expected 1 for an equation's own rest and less the
    nominal replay's floor, :attr:`BlockSums.floor`, over the same blocks).

    Parameters
    ----------
    sums : BlockSums
    a, b : int
        First and past-the-last block.
    """
    z = {c: {} for c in COMPONENTS}
    floor = {c: {} for c in COMPONENTS}
    for (c, e), sq in sums.parts.items():
        k = sums.count[e][a:b] > 0
        n = float(sums.count[e][a:b].sum())
        if n > 0:
            z[c][e] = float(sq[a:b][k].sum()) / n / sums.noise[e] ** 2
            if (c, e) in sums.floor:
                floor[c][e] = float(sums.floor[(c, e)][a:b][k].sum()) / n / sums.noise[e] ** 2
    return {c: math.sqrt(1.0 + g) for c, g in CR.gap_of(z, floor).items()}


def block_gap(sums) -> dict:
    """{component: array over blocks}: each block's gap/noise, computed as :func:`segment_gap` computes a
    segment's (the nominal replay's floor subtracted), NaN where a block analysed nothing: the timeline's
    rows.

    Parameters
    ----------
    sums : BlockSums
    """
    nb = next(iter(sums.count.values())).size
    gap = {c: np.zeros(nb) for c in COMPONENTS}
    seen = np.zeros(nb, bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        for (c, e), sq in sums.parts.items():
            n = sums.count[e]
            ok = n > 0
            seen |= ok
            z = np.where(ok, sq / np.maximum(n, 1), 0.0) / sums.noise[e] ** 2
            f = np.where(ok, sums.floor[(c, e)] / np.maximum(n, 1), 0.0) / sums.noise[e] ** 2 \
                if (c, e) in sums.floor else 0.0
            gap[c] += np.maximum(z - (1.0 if CR.OWN[e] == c else 0.0) - f, 0.0)
    return {c: np.where(seen, np.sqrt(1.0 + g), np.nan) for c, g in gap.items()}


def gap_level(gap) -> dict:
    """``{"gap_to_noise": largest component gap/noise, "component": its component}`` of a log's (or a
    segment's) ``gap_to_noise`` (None values when there is none): how far the log is from the model, the
    fleet's ranking key.

    Parameters
    ----------
    gap : {component: float}
        gap/noise per component [-].
    """
    if not gap:
        return {"gap_to_noise": None, "component": None}
    c = max(gap, key=lambda k: gap[k])
    return {"gap_to_noise": float(gap[c]), "component": c}


def segments(changes, block_t, block, op, sums, duration) -> list:
    """The stationary stretches between changes (boundaries at the changes' onsets), each with its
    operating point (medians of the block means) and gap_to_noise.

    Parameters
    ----------
    changes : list of dict
        Every change.
    block_t : array [s]
    block : float [s]
    op : dict
        Block means per channel [SI].
    sums : BlockSums
    duration : float [s]
        Length of the log.
    """
    cuts = sorted({c["onset"] for c in changes})
    bounds = [0.0] + [c for c in cuts if 0.0 < c < duration] + [duration]
    out = []
    for s, e in zip(bounds[:-1], bounds[1:]):
        a = int(np.searchsorted(block_t, s))
        b = max(int(np.searchsorted(block_t, e)), a + 1)
        sl = slice(a, b)
        opp = {k: (float(np.nanmedian(op[c][sl])) if np.isfinite(op[c][sl]).any() else None)
               for k, c in (("wob_setpoint", "wob"), ("static_stroke", "stroke"), ("static_pressure", "pressure"))}
        out.append({"start": float(s), "end": float(e), "operating_point": opp,
                    "gap_to_noise": segment_gap(sums, a, b)})
    return out


def learning_window(n_blocks, learn=LEARN) -> tuple:
    """(blocks the reference is learnt from, note or None) for a log of ``n_blocks`` blocks: ``learn`` when
    the log holds twice as many; else :data:`SHORT_LEARN_SHARE` of its blocks (at least 2), with a note
    saying so (the rest is compared with a shorter reference: alarms are less certain).

    Parameters
    ----------
    n_blocks : int
        Blocks in the log.
    learn : int
        The reference's blocks of a long log.
    """
    if n_blocks >= 2 * learn:
        return learn, None
    k = max(2, int(SHORT_LEARN_SHARE * n_blocks))
    return k, (f"the log holds {n_blocks} blocks, fewer than the {2 * learn} a reference of {learn} blocks needs: "
               f"the reference is learnt over its first {k} blocks and the rest compared with it (a short "
               "reference: an alarm is less certain, a slow change may be missed)")


def mean_wave_period(run, span=CHUNK) -> float:
    """The log's mean wave period [s]: 2 pi sqrt(m0 / m2) of its low-passed heave over its first ``span``
    seconds (the spectral moments from the heave's and its velocity's variances); NaN when the heave
    hardly moves (below 3 x its noise: no wave to average over).

    Parameters
    ----------
    run : MeasuredRun
    span : float [s]
    """
    k = run.t <= run.t[0] + span
    z = run["heave"][k]
    ok = np.isfinite(z)
    if ok.sum() < 20:
        return math.nan
    zf, dz, _ = lowpass_zero_phase(run.t[k][ok], z[ok], HEAVE_CUTOFF)
    m0, m2 = float(np.var(zf)), float(np.var(dz))
    if not (m2 > 0) or math.sqrt(m0) < 3.0 * noise_floor(z[ok]):
        return math.nan
    return 2.0 * math.pi * math.sqrt(m0 / m2)


def block_bounds(run) -> tuple:
    """(shortest, longest) statistic block for ``run`` [s], from physics: a block holds
    :data:`BLOCK_MIN_PERIODS` of the log's mean wave period (:func:`mean_wave_period`) and
    :data:`MIN_BLOCK_SAMPLES` samples at its rate; the log holds :data:`MIN_BLOCKS` blocks, and a block
    is at most one :data:`CHUNK`.

    Parameters
    ----------
    run : MeasuredRun
    """
    rate = (run.t.size - 1) / max(run.duration, 1e-300)
    lo = MIN_BLOCK_SAMPLES / rate
    tw = mean_wave_period(run)
    if math.isfinite(tw):
        lo = max(lo, BLOCK_MIN_PERIODS * tw)
    return lo, min(CHUNK, run.duration / MIN_BLOCKS)


def check_block(run, block) -> float:
    """``block`` [s] checked against :func:`block_bounds` (before any work); returns it.

    Parameters
    ----------
    run : MeasuredRun
    block : float [s]

    Raises
    ------
    heavecomp.errors.InputError
        One line naming ``--block``, the bounds and why.
    """
    lo, hi = block_bounds(run)
    if not (math.isfinite(block) and lo <= block <= hi):
        tw = mean_wave_period(run)
        wave = f"half the mean wave period {tw:.3g} s, " if math.isfinite(tw) else ""
        raise InputError(f"block {block:g} s is outside {lo:.3g}..{hi:.3g} s for {run.source}: a block holds at "
                         f"least {wave}{MIN_BLOCK_SAMPLES} samples, the log at least {MIN_BLOCKS} blocks "
                         f"(it spans {run.duration:.4g} s), a block at most {CHUNK:g} s", option="block")
    return block


def monitor(run, params, *, block=BLOCK, chunk=CHUNK, threshold=THRESHOLD, threshold_op=THRESHOLD_OP,
            learn=LEARN, noise=None, progress=None) -> MonitorResult:
    """Monitor a measured run (:class:`heavecomp.diagnosis.data.MeasuredRun`) against the nominal ``params``.

    Parameters
    ----------
    run : MeasuredRun
        The log.
    params : CMCParams
        The nominal parameters.
    learn : int
        Blocks learnt before any alarm (:data:`LEARN`).
    block : float [s]
        Statistic block (:data:`BLOCK`).
    chunk : float [s]
        Window of the component residuals (:data:`CHUNK`): memory is set by it.
    threshold, threshold_op : float [block sigmas]
        CUSUM thresholds of the component statistics and of the block-mean WOB.
    noise : {channel: sigma [SI]}, optional
        Channel noise (default: :func:`heavecomp.diagnosis.data.noise_floor` of the first chunk).
    progress : callable (fraction, message), optional

    Returns
    -------
    MonitorResult
    """
    sensors = list(run.sensors)
    use, skip = usable_equations(sensors)
    missing = [c for c in OP_CHANNELS if c not in sensors]
    if not use:
        raise DataError(f"{run.source}: column(s) {', '.join(repr(c) for c in missing)} missing: no equation residual "
                        f"can be computed from {', '.join(sensors)} (the gas law needs stroke and pressure, the "
                        "lower-mass balance heave, stroke and WOB)")
    skipped = {}
    if skip:
        skipped["equations"] = skip
        log.warning("%s: without %s the monitor leaves out %s", run.source, ", ".join(missing),
                    "; ".join(f"the {e} residual (reads {', '.join(c)})" for e, c in skip.items()))
    if "wob" not in sensors:
        skipped["operating_point"] = "no WOB channel: set-point changes are not detected"
    elif "pressure" not in sensors:
        skipped["operating_point"] = ("no pressure channel: a WOB step is reported as an operating change, "
                                      "unchecked by the load balance (a WOB misreading reads the same)")
    check_block(run, block)
    t = run.t
    edges = _block_edges(t, block)
    block_t = t[edges[:-1]]
    learn, note = learning_window(edges.size - 1, learn)
    notes = [note] if note else []
    if note:
        log.warning("%s: %s", run.source, note)
    nan = np.full(edges.size - 1, np.nan)
    op = {k: _block_means(run[k], edges) if k in sensors else nan.copy() for k in OP_CHANNELS}
    if noise is None:
        first = t <= t[0] + chunk
        noise = {k: noise_floor(run[k][first]) if k in sensors else 1.0 for k in OP_CHANNELS}
    if progress:
        progress(0.0, f"{edges.size - 1} blocks of {block:g} s; operating point")
    if "wob" in sensors:
        op_changes, op_bounds = operating_changes(op, block_t, block, params, threshold=threshold_op, learn=learn)
    else:
        op_changes, op_bounds = [], []
    sums = component_blocks(run, params, edges, op_bounds, op, noise, block=block, chunk=chunk, progress=progress,
                            equations=use, learn=learn)
    eff = [e for e in component_changes(sums, block_t, block, op_bounds, threshold=threshold, learn=learn,
                                        jump_eq=JUMP_EQ_SHORT if note else JUMP_EQ)
           if not absorbed(e, op_changes)]
    changes = sorted(one_per_misreading(op_changes, eff), key=lambda c: c["t"])
    segs = segments(changes, block_t, block, op, sums, run.duration)
    return MonitorResult(block_t, block, sums.stats(), op, sums, changes, segs,
                         {k: float(v) for k, v in noise.items() if k in sensors}, sensors, run.duration, skipped,
                         learn, notes, segment_gap(sums, 0, block_t.size))


# ---------------------------------------------------------------------------- --diagnose: one verdict per segment
DIAGNOSE_SPAN = 600.0  #: a segment is diagnosed on at most its first this many seconds (the diagnosis' benchmarked length) [s]
DIAGNOSE_MIN = 120.0  #: a segment shorter than this is not diagnosed (a fitted and a held-out part of several wave periods) [s]


def carries_gap(segment, changes) -> bool:
    """A segment carries a gap when it starts at an effect change (the monitor saw the gap appear or
    change there).  The first segment is the log's reference stretch: its gap, if any, is the one
    ``heavecomp diagnose`` of the log's start finds.

    Parameters
    ----------
    segment : dict
        A segment of :func:`segments`.
    changes : list of dict
        Every change.
    """
    return any(c["kind"] == "effect" and math.isclose(c["onset"], segment["start"], abs_tol=1e-6) for c in changes)


def segment_run(run, start, end) -> MeasuredRun:
    """The part of ``run`` from ``start`` to ``end`` [s, log time] as a run of its own, its clock restarted
    at 0 (the diagnosis estimates the state it starts from, as for any log that starts mid-operation).

    Parameters
    ----------
    run : MeasuredRun
    start, end : float [s]
        The part to slice, in log time.
    """
    k = (run.t >= start) & (run.t <= end)
    t = run.t[k]
    return MeasuredRun(t - t[0], {c: y[k] for c, y in run.columns.items()},
                       source=f"{run.source} [{start:.0f}-{end:.0f} s]", measurement=dict(run.measurement))


def diagnose_segments(result, run, params, *, candidates=None, n_jobs=1, span=DIAGNOSE_SPAN, progress=None,
                      each=None) -> dict:
    """Diagnose every segment of ``result`` (:func:`monitor`) that carries a gap (:func:`carries_gap`) with
    :class:`heavecomp.diagnosis.estimator.GapDiagnoser` on that segment (at most its first ``span`` s).

    Adds ``verdict`` (``effect``, ``confidence``, ``component``, ``shrink``, ``span`` [s, log time]) to
    each diagnosed segment of ``result.segments``, and ``verdict = {"effect": "not_diagnosed",
    "reason": ...}`` to a segment that carries a gap but is shorter than :data:`DIAGNOSE_MIN`.

    Parameters
    ----------
    result : MonitorResult
        What :func:`monitor` found; its segments gain ``verdict``.
    run : MeasuredRun
        The log it ran on.
    params : CMCParams
        The nominal parameters.
    candidates : sequence of str, optional
        Effect names (default: every candidate).
    n_jobs : int
        Candidates fitted concurrently.
    span : float [s]
        Longest part of a segment diagnosed.
    progress : callable (fraction, message), optional
        Called as each segment starts and as its diagnosis goes (the candidates' fits, named by segment).
    each : callable (index, GapDiagnoser, MeasuredRun, (start, end)), optional
        Called with each fitted diagnosis, the segment's run and its span [s, log time], as it is done
        (``heavecomp monitor --diagnose`` writes the segment's folder with it, as ``diagnose --span`` does).

    Returns
    -------
    dict
        Segment index -> the segment's full ``diagnosis.json`` content (``GapDiagnoser.to_json``).
    """
    out = {}
    todo = [i for i, s in enumerate(result.segments) if carries_gap(s, result.changes)]
    for n, i in enumerate(todo):
        seg = result.segments[i]
        a, b = seg["start"], min(seg["end"], seg["start"] + span)
        if b - a < DIAGNOSE_MIN:
            seg["verdict"] = {"effect": "not_diagnosed",
                              "reason": f"segment of {b - a:.0f} s, shorter than {DIAGNOSE_MIN:g} s"}
            continue
        if progress:
            progress(n / len(todo), f"diagnosing segment {i} ({a:.0f}-{b:.0f} s)")
        inner = None
        if progress:
            def inner(frac, msg, n=n, i=i):
                progress((n + frac) / len(todo), f"segment {i}: {msg}")
        d = GapDiagnoser(params, candidates, n_jobs=n_jobs, progress=inner)
        sub = segment_run(run, a, b)
        d.fit(sub)
        v = d.verdict_
        seg["verdict"] = {"effect": v["effect"], "confidence": v.get("confidence"), "component": v.get("component"),
                          "shrink": v.get("shrink"), "span": [float(a), float(b)]}
        seg["verdict"].update({k: v[k] for k in ("law", "member") if k in v})  # a family's law and its fitted member
        out[i] = d.to_json()
        if each is not None:
            each(i, d, sub, (float(a), float(b)))
        log.info("segment %d (%.0f-%.0f s): %s (%s)", i, a, b, v["effect"], v.get("confidence"))
    return out
