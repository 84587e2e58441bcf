"""Can the log tell the leading explanations apart?  The data-side twin of the structural isolability table.

>>> d = distinguish(ctx, fits, perturbed, policy)            # doctest: +SKIP
>>> d.group, d.to_json()["pairs"][0]["apart"]                # doctest: +SKIP

:mod:`heavecomp.diagnosis.structure` says which candidates a sensor set can tell apart *in principle*
(from the model's structure).  Two explanations can be separable in principle and not on this log: a
seal friction that grows with pressure and a Coulomb force 30 % high are the same force at a nearly
constant pressure.  This module tests it on the log itself, and computes what would separate them.

**The test** (a block-based Vuong test, non-nested model comparison).  For two fitted explanations A and
B, the per-sample log-likelihood difference on the held-out part, with Gaussian noise of each channel's
noise floor sigma_c (output noise and the replay's sensitivity to the heave noise),

    d_t = 1/2 sum_c [(y_c - B_c)^2 - (y_c - A_c)^2] / sigma_c^2,

is summed over blocks of one longest wave period (``VerdictPolicy.distinguish_block_periods``): the
replay's errors are correlated within a wave (one flipped stick event shifts a stretch), hardly across
waves.  The statistic is Student's t of the block sums, z = mean(D_b) / (sd(D_b) / sqrt(n_b)), against
t(1 - alpha/2, n_b - 1), alpha = ``distinguish_alpha``.  It is computed on the replays driven by the
logged heave and on each heave-noise draw the diagnosis already makes (``ReplayContext.hs_pert``, both
explanations on the same draw); the pair is **apart** only when both the replay's statistic and the
median of the draws' exceed the threshold with the same sign (a preference that a heave-noise redraw
reverses is not the log's).  The statistic reported is the smaller of the two in magnitude.

**Its false-alarm rate, measured on every log.**  A model replayed on two heave-noise draws is two
explanations that fit equally well by construction: the test calling such a pair apart is a false
alarm.  Every diagnosis tests the pairs of its draws for the nominal model and the best candidate
(``false_alarm_measured``); the stated rate is ``distinguish_alpha``.  The verdict's rule (the replay
and the draws' median both apart) is stricter than one such pair, so the measured rate bounds it.

**What would separate them** (Box and Hill's model discrimination): the group's members (their fitted
configurations) are simulated from rest under experiments a rig can run -- another WOB set-point, a
calmer and a rougher sea (JONSWAP at the log's peak period), a longer log -- and, for a channel the log
lacks, on this log's heave.  Each experiment's divergence is 1/2 sum_t sum_c (A_c - B_c)^2 / sigma_c^2 at
one sample a second, the expected log-likelihood ratio between the two if one is right; experiments are
ranked by it against this log's own (the members' replays of it, ``ratio``), and those that beat it
are written in words; a log that does not start at rest adds the experiment of a log that does.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from heavecomp.diagnosis.data import MeasuredRun, uniform
from heavecomp.diagnosis.replay import CH
from heavecomp.diagnosis.stepper import replay_dt
from heavecomp.diagnosis.where import wave_band
from heavecomp.effects.candidates import by_family, family_of
from heavecomp.plants.cmc import plant_vectors
from heavecomp.simulate.excitation import jonswap, spectral_hs_tp

#: the description of the test in ``verdict.distinguishable.test``
TEST = ("block Vuong test: per-block held-out log-likelihood difference (squared errors over each channel's "
        "noise floor), blocks of one longest wave period, Student's t; apart only when the replay and the "
        "median of the heave-noise draws both pass, with the same sign")


@dataclasses.dataclass(frozen=True)
class Pair:
    """One pair's test: ``a`` (the better by score) against ``b``; ``statistic`` the signed t (positive: a
    fits the held-out log better), ``threshold`` the two-sided critical value, ``apart``."""

    a: str
    b: str
    statistic: float
    threshold: float
    apart: bool
    blocks: int
    replay: float
    draws: float

    def to_json(self) -> dict:
        return {"a": self.a, "b": self.b, "statistic": self.statistic, "threshold": self.threshold,
                "apart": self.apart, "blocks": self.blocks, "statistic_replay": self.replay,
                "statistic_draws_median": self.draws}


@dataclasses.dataclass(frozen=True)
class Distinguishability:
    """The test on the leading candidates: ``pairs`` (the best against each), ``group`` (the best and
    those it cannot be told from, score order, at most ``group_max``), ``left_out`` (members beyond it),
    the stated ``alpha`` and the null pairs' counts, ``block_s`` [s]."""

    pairs: tuple
    group: tuple
    alpha: float
    null_pairs: int
    null_apart: int
    block_s: float
    left_out: tuple = ()

    def to_json(self) -> dict:
        out = {"test": TEST, "false_alarm_rate": self.alpha,
               "false_alarm_measured": {"null_pairs": self.null_pairs, "apart": self.null_apart,
                                        "rate": self.null_apart / self.null_pairs if self.null_pairs else None,
                                        "how": "one model replayed on two heave-noise draws (equal by "
                                               "construction), for the nominal model and the best candidate"},
               "block_s": self.block_s, "pairs": [p.to_json() for p in self.pairs]}
        if self.left_out:
            out["left_out_of_group"] = list(self.left_out)
        return out


# ------------------------------------------------------------------ the test
def block_length(run, policy) -> float:
    """Block length [s]: ``distinguish_block_periods`` longest wave periods (1 / the wave band's low
    edge, :func:`heavecomp.diagnosis.where.wave_band`).

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run (its heave).
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds.
    """
    lo, _hi = wave_band(run.t, run["heave"])
    return policy.distinguish_block_periods / max(lo, 1e-3)


def losses(ctx, pred) -> np.ndarray:
    """Per-sample held-out loss 1/2 sum_c (pred_c - y_c)^2 / sigma_c^2 (sigma: the noise floor) on the
    held-out samples of ``ctx`` (NaN where no channel is finite).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (its held-out mask, measured channels and noise floor).
    pred : dict
        A replay, {channel: array} [SI].
    """
    m = ctx.valmask
    tot = np.zeros(int(m.sum()))
    seen = np.zeros(tot.size, bool)
    for c in ctx.channels:
        n = pred[c].size
        y = ctx.y[c][:n][m[:n]]
        p = pred[c][m[:n]]
        k = min(y.size, tot.size)
        r = (p[:k] - y[:k]) / max(ctx.noise_floor[c], 1e-30)
        ok = np.isfinite(r)
        tot[:k][ok] += 0.5 * r[ok] ** 2
        seen[:k] |= ok
    return np.where(seen, tot, np.nan)


def block_t(d, t, block) -> tuple:
    """Student's t of the block sums of ``d`` (samples at times ``t``, NaN left out; blocks of ``block``
    s, a block with under half its samples dropped) and the number of blocks.

    Parameters
    ----------
    d : numpy.ndarray
        Per-sample loss differences (NaN: left out).
    t : numpy.ndarray
        Their times [s].
    block : float
        Block length [s].
    """
    ok = np.isfinite(d)
    if ok.sum() < 4:
        return 0.0, 0
    idx = np.floor((t - t[0]) / block).astype(int)
    nb = int(idx[-1]) + 1
    sums = np.bincount(idx[ok], weights=d[ok], minlength=nb)
    cnt = np.bincount(idx[ok], minlength=nb)
    full = np.bincount(idx, minlength=nb)
    keep = cnt >= 0.5 * np.maximum(full, 1)
    D = sums[keep] / np.maximum(cnt[keep], 1) * np.mean(cnt[keep])  # per-block mean, on the typical block's count
    if D.size < 2:
        return 0.0, int(D.size)
    sd = float(np.std(D, ddof=1))
    if sd <= 0:
        return (0.0 if np.mean(D) == 0 else math.copysign(math.inf, float(np.mean(D)))), int(D.size)
    return float(np.mean(D) / (sd / math.sqrt(D.size))), int(D.size)


def threshold(alpha, blocks) -> float:
    """Two-sided critical value t(1 - alpha/2, blocks - 1) (infinite below two blocks).

    Parameters
    ----------
    alpha : float
        Two-sided false-alarm rate.
    blocks : int
        Number of blocks the statistic was formed from.
    """
    from scipy.stats import t as student

    return float(student.ppf(1.0 - 0.5 * alpha, blocks - 1)) if blocks >= 2 else math.inf


def _stat(ctx, pa, pb, block):
    tv = ctx.run.t[ctx.valmask]
    return block_t(losses(ctx, pb) - losses(ctx, pa), tv, block)


def pair_test(ctx, a, b, pred_a, pred_b, pert_a, pert_b, alpha, block) -> Pair:
    """The test of ``a`` against ``b`` from their replays (``pred_*``) and their replays on the same
    heave-noise draws (``pert_*``); see the module docstring.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (its held-out mask, measured channels and noise floor).
    a, b : str
        The two explanations' names.
    pred_a, pred_b : dict
        Their replays on the logged heave ({channel: array} [SI]).
    pert_a, pert_b : list of dict
        Their replays on the same heave-noise draws.
    alpha : float
        Two-sided false-alarm rate.
    block : float
        Block length [s].
    """
    z0, nb = _stat(ctx, pred_a, pred_b, block)
    zs = [_stat(ctx, x, y, block)[0] for x, y in zip(pert_a, pert_b)]
    zd = float(np.median(zs)) if zs else z0
    thr = threshold(alpha, nb)
    same = z0 * zd > 0
    stat = math.copysign(min(abs(z0), abs(zd)), z0) if same else 0.0
    return Pair(a, b, float(stat), thr, bool(same and abs(stat) > thr), nb, float(z0), zd)


def null_stats(ctx, perturbed, block) -> list:
    """[(t, blocks)] of every pair of heave-noise draws of each model in ``perturbed`` (a list of the model's
    replays on the draws), tested as if they were two explanations: equal by construction.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (its held-out mask, measured channels and noise floor).
    perturbed : list of list of dict
        Per model, its replays on the heave-noise draws.
    block : float
        Block length [s].
    """
    return [_stat(ctx, x, y, block) for preds in perturbed for x, y in itertools.combinations(preds, 2)]


def null_pairs(ctx, perturbed, alpha, block) -> tuple:
    """(pairs, apart): :func:`null_stats` against the test's threshold at ``alpha``.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (its held-out mask, measured channels and noise floor).
    perturbed : list of list of dict
        Per model, its replays on the heave-noise draws.
    alpha : float
        Two-sided false-alarm rate.
    block : float
        Block length [s].
    """
    st = null_stats(ctx, perturbed, block)
    return len(st), sum(abs(z) > threshold(alpha, nb) for z, nb in st)


def distinguish(ctx, fits, perturbed, policy, nominal_pert=None) -> Distinguishability:
    """Test the best of ``fits`` (best score first) against the leading others and the refit of the
    nominal's parameters.  When one of them fits the held-out log significantly better than the best by
    score (the parsimony penalty is a proxy; the held-out test is the evidence), it becomes the best and
    is tested against the others in turn.  The group is the best and those not apart from it, the
    closest first.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best score first (``pred``: the whole replay).
    perturbed : dict
        {effect: its replays on the heave-noise draws ``ctx.hs_pert``}.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds (``distinguish_*``, ``group_max``).
    nominal_pert : list of dict, optional
        The nominal model's replays on the same draws (null pairs); None: re-simulated.
    """
    P = policy
    block = block_length(ctx.run, P)
    # the leading families (two laws of one family count once: both are tested, neither crowds out a rival)
    top = within_families([f.effect for f in fits], P.distinguish_leading)
    lead = [f for f in fits if f.effect in top]
    lead += [f for f in fits if f.effect not in top and f.effect == "parameter_mismatch"]
    # an explanation explains: a candidate under min_explained is no named verdict's rival (a short held-out
    # part has few blocks, and the test alone would keep it in the group)
    lead = [f for f in lead if f.pred is not None and math.isfinite(f.explained) and f.effect in perturbed
            and (f is fits[0] or f.explained >= P.min_explained)]
    best = fits[0]
    seen = set()
    while True:  # the best is the one no other leading candidate beats on the held-out log
        seen.add(best.effect)
        pairs = tuple(pair_test(ctx, best.effect, f.effect, best.pred, f.pred, perturbed.get(best.effect, []),
                                perturbed[f.effect], P.distinguish_alpha, block) for f in lead if f is not best)
        beaten = [p for p in pairs if p.apart and p.statistic < 0 and p.b not in seen]
        if not beaten:
            break
        winner = min(beaten, key=lambda p: p.statistic).b
        best = next(f for f in lead if f.effect == winner)
    together = [best.effect] + [p.b for p in sorted(pairs, key=lambda p: abs(p.statistic)) if not p.apart]
    if nominal_pert is None:  # the nominal's draws the preparation replayed (not twice)
        nominal_pert = list(ctx.nominal_pert) or [ctx.simulate([], hs=hs) for hs in ctx.hs_pert]
    n, k = null_pairs(ctx, [nominal_pert, perturbed.get(best.effect, [])], P.distinguish_alpha, block)
    inside = within_families(together, P.group_max)
    return Distinguishability(pairs, inside, P.distinguish_alpha, n, k, block,
                              tuple(m for m in together if m not in inside))


def within_families(names, n) -> tuple:
    """The first ``n`` families of ``names`` (best first), every member of each kept: two laws of one
    contract class (``friction_lag`` in time and in distance) count once towards a group's size.

    Parameters
    ----------
    names : sequence of str
        Effect names, best first.
    n : int
        Families kept.
    """
    keep = {family_of(m) for m in by_family(names)[:n]}
    return tuple(m for m in names if family_of(m) in keep)


# ------------------------------------------------------------------ what would separate them
def _sea(run):
    """H_s [m] and T_p [s] of the log's heave."""
    tu, zu = uniform(run.t, run["heave"])
    hs, tp = spectral_hs_tp(zu, tu[1] - tu[0])[:2]
    return float(hs), float(tp)


class _RestStarts(dict):
    """Every reading starts the experiment's replay from the true rest state (a synthetic experiment knows
    its start; the log's start estimate does not apply)."""

    def __init__(self, starts):
        super().__init__()
        self._v = (0.0, starts)

    def __contains__(self, key):
        return True

    def __getitem__(self, key):
        return self._v


def experiment_replay(ctx, *, hs_scale=1.0, duration=None, setpoint=0.0, seed=7):
    """A :class:`~heavecomp.diagnosis.replay.Replay` of an experiment: a JONSWAP sea at the log's peak
    period and ``hs_scale`` x its H_s, ``duration`` [s] (default the log's), the nominal WOB set-point
    moved by the share ``setpoint``, from rest, sampled as the log.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (its held-out mask, measured channels and noise floor).
    hs_scale : float
        Factor on the log's significant wave height.
    duration : float, optional
        Length of the experiment [s]; default the log's.
    setpoint : float
        Relative change of the WOB set-point.
    seed : int
        Seed of the JONSWAP sea.
    """
    rp = ctx.replay
    run = rp.run
    hs0, tp = _sea(run)
    T = float(run.t[-1] if duration is None else duration)
    nominal = rp.nominal
    if setpoint:
        w0 = nominal.operating_point.wob_setpoint
        nominal = nominal.replace(operating_point={"wob_setpoint": w0 * (1.0 + setpoint)})
    h = replay_dt(nominal)
    n_steps = int(math.ceil(T / h))
    heave = jonswap(hs_scale * hs0, tp, 3.3, seed, min(30.0, 0.1 * T), (n_steps + 1) * h, 0.5 * h)
    heave = dataclasses.replace(heave, info=dict(heave.info, reference_m=0.0))
    dt = float(np.median(np.diff(run.t)))
    t = np.arange(0.0, T, dt)
    starts = [(0.0, 0.0, 0.0, 0.0, True)]
    fake = MeasuredRun(t, {"heave": np.interp(t, heave.t, heave.z)}, run.source)
    return dataclasses.replace(rp, run=fake, nominal=nominal, h=h, n_steps=n_steps, hs=heave,
                               plant=plant_vectors(nominal), bounds=[(0, n_steps)], starts=starts,
                               reinit=np.zeros(t.size, bool), cache=_RestStarts(starts))


def divergence(preds, sigma, t, mask=None) -> float:
    """Box-Hill divergence of the members' predictions ``preds`` (dicts of channels): the smallest over
    the pairs of 1/2 sum_c mean_t (A_c - B_c)^2 / sigma_c^2 times the duration [s] (one sample a second).

    Parameters
    ----------
    preds : list of dict
        The members' predictions, {channel: array} [SI].
    sigma : dict
        Noise per channel [SI].
    t : numpy.ndarray
        Sample times [s].
    mask : numpy.ndarray, optional
        Samples to compare (default all).
    """
    out = math.inf
    T = float(t[-1] - t[0]) if t.size > 1 else 0.0
    for a, b in itertools.combinations(preds, 2):
        tot = 0.0
        for c, s in sigma.items():
            x = a[c] - b[c]
            if mask is not None:
                x = x[mask[: x.size]]
            x = x[np.isfinite(x)]
            if x.size:
                tot += 0.5 * float(np.mean(x * x)) / max(s, 1e-30) ** 2
        out = min(out, tot * T)
    return out if math.isfinite(out) else 0.0


def separate_by(ctx, fits, group, policy, top=3, pairs=()) -> list:
    """What would tell the ``group``'s members apart, ranked by Box-Hill divergence (see the module
    docstring): [{experiment, description, divergence, ratio}] (ratio: against this log, the members'
    replays of it), best first, the ``top`` that beat it.  Empty for a group of one.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The fitted candidates (their ``values``).
    group : sequence of str
        The group's members (effect names), best first.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        The experiments' sizes (``separate_*``, ``added_channel_noise``).
    top : int
        Experiments returned.
    pairs : sequence of Pair
        The block tests of the group (the longer log's length the test would need).
    """
    group = by_family(group)  # one member per family: two laws of one class are one answer, not to separate
    if len(group) < 2:
        return []
    P = policy
    conf = {f.effect: [(f.effect, f.values)] for f in fits if f.effect in group}
    members = [m for m in group if m in conf]
    sigma = {c: ctx.noise_floor[c] for c in ctx.channels}
    T = float(ctx.run.t[-1])
    hs0, tp = _sea(ctx.run)
    w0 = ctx.replay.nominal.operating_point.wob_setpoint
    names = ", ".join(f"`{family_of(m)}`" for m in members[:-1]) + f" and `{family_of(members[-1])}`"

    def run(label, text, **kw):
        rp = experiment_replay(ctx, **kw)
        preds = [rp.simulate(conf[m]) for m in members]
        settle = rp.run.t >= min(30.0, 0.1 * rp.run.t[-1])
        return {"experiment": label, "description": text, "divergence": divergence(preds, sigma, rp.run.t, settle)}

    # the reference: this very log (the members' replays of it), against which every experiment is ranked
    d0 = max(divergence([ctx.simulate(conf[m]) for m in members], sigma, ctx.run.t, ctx.allmask), 1e-12)
    rows = []
    if not ctx.replay.initial.at_rest:
        rows.append(run("from_rest", f"a {T:.0f} s log that starts from rest at the operating point, in a sea like "
                        f"this one (H_s {hs0:.1f} m, T_p {tp:.1f} s; this log starts mid-operation)"))
    for s in P.separate_sea:
        rows.append(run("calmer_sea" if s < 1 else "rougher_sea",
                        f"a {'calmer' if s < 1 else 'rougher'} sea (H_s {s * hs0:.1f} m instead of {hs0:.1f} m; "
                        f"{'longer stops' if s < 1 else 'longer strokes and faster reversals'}), {T:.0f} s",
                        hs_scale=s))
    for sgn in (1.0, -1.0):
        step = sgn * P.separate_setpoint
        rows.append(run("setpoint_step", f"a WOB set-point step to {w0 * (1 + step) / 1e3:.0f} kN "
                        f"({100 * step:+.0f} %, from {w0 / 1e3:.0f} kN), {T:.0f} s logged at the new set-point "
                        "(the gas pressure, the friction's load and the string's stretch move)", setpoint=step))
    longer = min(P.separate_longer * T, 3600.0)
    need = ""
    if pairs:  # the block test's t grows with the square root of the held-out length at a fixed difference
        p = max((p for p in pairs if p.b in members and p.a in members), key=lambda p: abs(p.statistic), default=None)
        held = float(ctx.split["validate"][1] - ctx.split["validate"][0])
        if p is not None and abs(p.statistic) > 0 and math.isfinite(p.threshold):
            t_need = held * (p.threshold / abs(p.statistic)) ** 2
            need = (f"; at the present difference the block test would tell `{p.a}` from `{p.b}` on about "
                    f"{t_need / 60:.0f} min of held-out log")
    rows.append(run("longer_log", f"a {longer / 60:.0f} min log in the same sea ({longer / T:.1f} x this one: "
                    f"a drift or a slow change shows over it{need})", duration=longer))
    noise = dict(P.added_channel_noise)
    missing = [c for c in CH if c not in ctx.channels and c in noise]
    for c in missing:  # a channel added, on this very log (its replays predict every channel)
        preds = [ctx.simulate(conf[m]) for m in members]
        d = divergence(preds, {c: noise[c]}, ctx.run.t, ctx.allmask)
        unit = {"stroke": "mm", "pressure": "kPa", "wob": "kN"}[c]
        scale = {"stroke": 1e3, "pressure": 1e-3, "wob": 1e-3}[c]
        rows.append({"experiment": "channel_added",
                     "description": f"a {c} sensor on this rig (noise {noise[c] * scale:g} {unit}), the same log",
                     "divergence": d})
    for r in rows:
        r["ratio"] = r["divergence"] / d0
        r["description"] = (f"{r['description']}: drives {names} {r['ratio']:.1f} x further apart than this log")
    rows.sort(key=lambda r: -r["divergence"])
    return [r for r in rows if r["ratio"] > 1.0][:top]
