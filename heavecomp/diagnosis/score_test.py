"""A score test on the replay before a full fit, for the candidates the equation error cannot screen.

The equation error (:func:`heavecomp.diagnosis.screen.prescreen`) leaves out a candidate whose component
shows no gap, but only where its residual sees the effect (``FitSpec.screened``).  Where it is blind (a
friction memory acts at reversals, a dwell-grown static force at breakaway, a string damping under the
lower-mass balance's noise) the candidate used to be fitted in full (~40 replays) whatever the log.

The score (Lagrange-multiplier) test asks the replay itself, at the null, whether the effect can explain
anything: each of the effect's probes (``FitSpec.probes``: a moderate amplitude at two or three values
of its shape parameter, e.g. a lag time or a relaxation length) is replayed once, whole; its difference
from the nominal replay is a column of the secant Jacobian of every channel w.r.t. the effect's
amplitude at that shape.  The Gauss-Newton step from the null, fitted on the fit part (weighted,
decimated: the full fit's own objective) with non-negative amplitudes (an effect's amplitude is >= 0;
a mixture of shapes stands for any shape between them), predicts the candidate's held-out channels;
their explained share of the held-out gap above the noise floor is the verdict's own measure
(:meth:`heavecomp.diagnosis.replay.ReplayContext.explained`); so are the fit part's and the best probe's
own, and the largest of the three is tested (:func:`predicted`).  A candidate whose predicted share is
under ``VerdictPolicy.score_test_explained`` is not replayed in full; its prescreen entry keeps the
evidence (``score_test``).  The probes are secants from the null to a physical configuration, so the
linear model includes each probe's own replay (amplitude 1, and its fit-part cost is never above the
best probe's).  Three probes cost about three replays, against ~40 for a full fit.

The same Gauss-Newton step asks a joint second-effect fit before it is run (:func:`joint_prediction`,
from the partner's own fit instead of the null), and a smooth candidate's fit starts at the test's step
(:func:`start`).
"""

from __future__ import annotations

import math
import time

import numpy as np

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis import fitting as F
from heavecomp.effects.candidates import get


def needs_test(cls, comp, gap, shares, seen, ee, policy) -> bool:
    """Whether a replayed candidate is one the equation error would have left out were it not blind to
    it: a plant candidate with probes, not ``screened``, whose screened, observable component shows no gap
    (<= ``prescreen_gap`` noise variances or under ``prescreen_share`` of the whole) and whose
    equation-error fit shrinks nothing held out (< :data:`heavecomp.diagnosis.equation_error.MIN_SHRINK`).

    Parameters
    ----------
    cls : type
        The candidate's effect class.
    comp : str
        Its component.
    gap, shares, seen : dict
        Per component: gap [noise variances], share of the gap [-], observable.
    ee : dict or None
        Its equation-error fit (:func:`heavecomp.diagnosis.equation_error.rank_effects` row).
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        ``prescreen_gap``, ``prescreen_share``, ``score_test_explained`` (<= 0: no test).
    """
    small = gap.get(comp, 0.0) <= policy.prescreen_gap or shares.get(comp, 0.0) < policy.prescreen_share
    return bool(policy.score_test_explained > 0 and cls.kind == "plant" and not cls.fit.screened
                and cls.fit.probes and comp in CR.SCREENED and seen.get(comp, True) and small
                and (ee is None or ee["shrink"] < EE.MIN_SHRINK))


def _channels(ctx, pred, mask) -> dict:
    """Per channel the residual (prediction minus measurement) on ``mask``'s finite samples."""
    out = {}
    for c in ctx.channels:
        y = ctx.y[c][: pred[c].size]
        ok = mask[: pred[c].size] & np.isfinite(y)
        out[c] = pred[c][ok] - y[ok]
    return out


def predicted(ctx, preds, null=None) -> dict:
    """The Gauss-Newton prediction from the nominal of the probes' replays ``preds`` (whole, one per probe):
    the amplitudes (>= 0) fitted on the fit part's weighted, decimated residual
    (:meth:`~heavecomp.diagnosis.replay.ReplayContext.resid_vec`), and the explained share of the gap
    above noise (:meth:`~heavecomp.diagnosis.replay.ReplayContext.explained`) of the predicted channels
    held out (``held_out``) and on the fit part itself (``fit_part``), and the best probe's own held out
    (``probe``) [-].  ``explained``, the figure tested, is the largest of the three: where the replay
    responds far from linearly (a dwell-grown static force flips stick events) the linear prediction
    held out can be worse than the nominal even for the effect that is there (the tuning set's planted
    dwell stiction: -1.29 held out, while its fit explains 0.96), but its fit part then says how much
    the probes' directions can take out.

    With ``null`` (a replay other than the nominal's: a joint fit's start, :func:`joint_prediction`) the
    columns are secants from it, their steps signed (unbounded least squares), the shares still of the
    nominal's gap, and ``null``'s own held-out share counts among the probes'.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    preds : list of dict
        The probes' whole replays (:meth:`ReplayContext.simulate`).
    null : dict, optional
        The whole replay the columns are secants from (None: the nominal's, amplitudes >= 0).
    """
    from scipy.optimize import nnls

    base = ctx.nominal_pred if null is None else null
    r0 = ctx.resid_vec(base)
    J = np.column_stack([ctx.resid_vec(p) - r0 for p in preds]) if preds else np.zeros((r0.size, 0))
    ok = np.all(np.isfinite(J), axis=1) & np.isfinite(r0)
    if not (ok.any() and np.any(J[ok])):
        a = np.zeros(len(preds))
    elif null is None:
        a, _ = nnls(J[ok], -r0[ok])
    else:
        a = np.linalg.lstsq(J[ok], -r0[ok], rcond=None)[0]

    def share(mask):
        v0 = _channels(ctx, base, mask)
        cols = [_channels(ctx, p, mask) for p in preds]
        # a probe the fit gave no amplitude adds nothing (its replay may have diverged: not finite)
        lin = {c: float(np.mean((v0[c] + sum(ak * (col[c] - v0[c]) for ak, col in zip(a, cols) if ak != 0)) ** 2))
               for c in ctx.channels}
        e = ctx.explained(ctx.mse(ctx.nominal_pred, mask), lin)
        return float(e) if math.isfinite(e) else math.inf

    e_probe = max((e for e in (ctx.explained(ctx.mse_before, ctx.mse(p, ctx.valmask))
                               for p in list(preds) + ([] if null is None else [null]))
                   if math.isfinite(e)), default=-math.inf)
    got = {"held_out": share(ctx.valmask), "fit_part": share(ctx.fitmask), "probe": float(e_probe)}
    return dict(got, explained=max(got.values()), amplitudes=[float(x) for x in a])


def joint_prediction(ctx, fixed, cls, values, free, lo, hi):
    """The score test of a joint fit before it is run: the configuration ``fixed`` plus candidate ``name``
    at its own fit ``values`` replayed whole, and once more with each of its ``free`` fit-vector entries
    moved by a secant of 10 % of its search range (inwards, as the stepwise refit's Jacobian,
    :func:`heavecomp.diagnosis.fitting.stepwise`); the Gauss-Newton step from the start predicts the
    joint explained share (:func:`predicted`: the largest of held out, fit part and the replays' own).
    Returns (that prediction, the start's whole replay).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    fixed : list of (str, dict)
        The configuration held (the best candidate at its fit).
    cls : type
        The partner's effect class as fitted on this run (:func:`heavecomp.diagnosis.fitting.candidate_class`).
    values : dict
        Its own fit's parameter values [SI] (the joint fit's start).
    free : sequence of int
        The fit-vector entries the joint fit moves.
    lo, hi : numpy.ndarray
        Its search box (fit vector).
    """
    name = cls.name
    x = np.clip(cls.to_x(values), lo, hi)
    configs = [fixed + [(name, dict(values))]]
    for j in free:
        h = F.secant_step(x, lo, hi, j, 0.1)
        xx = x.copy()
        xx[j] += h
        configs.append(fixed + [(name, {**values, **cls.from_x(xx)})])
    preds = ctx.map(ctx.simulate, configs)
    return predicted(ctx, preds[1:], null=preds[0]), preds[0]


def start(cls, entry):
    """The fit vector a smooth candidate's fit starts from after its score test (``FitSpec.smooth``:
    its replay responds smoothly, so the test's Gauss-Newton step from the null stands for a point near
    its optimum), or None (no test, not smooth, or a step of zero amplitude).  The probes are secant
    columns in the effect's amplitude (``FitSpec.probes``: a moderate amplitude at several values of its
    shape parameter): a parameter equal in every probe (the amplitude) is scaled by the sum of the fitted
    amplitudes, one that differs (the shape) is their amplitude-weighted mean.

    Parameters
    ----------
    cls : type
        The candidate's effect class.
    entry : dict or None
        Its prescreen entry (``score_test``: the probes and their fitted amplitudes, :func:`run`).
    """
    test = (entry or {}).get("score_test")
    if not cls.fit.smooth or not isinstance(test, dict) or not test.get("amplitudes"):
        return None
    a = np.asarray(test["amplitudes"], dtype=float)
    if not np.all(np.isfinite(a)) or a.sum() <= 0:
        return None
    probes = [dict(p) for p in test["probes"]]
    values = cls.from_x(cls.x0())
    for name in probes[0]:
        v = np.array([p[name] for p in probes], dtype=float)
        values[name] = float(v[0] * a.sum() if np.all(v == v[0]) else a @ v / a.sum())
    lo, hi = cls.bounds_x()
    return np.clip(cls.to_x(values), lo, hi)


def run(ctx, prescreened, names, policy, progress=None) -> dict:
    """The score test of the candidates ``names`` (their :func:`needs_test` holds), their probes replayed
    on ``ctx.n_jobs`` threads; each prescreen entry gets ``score_test`` (the probes, the prediction, the
    threshold) and ``replay`` False when its predicted explained share (the largest of held out, fit part
    and best probe) is under ``policy.score_test_explained``, unless no candidate at all would then be fitted
    (then every one tested is, as the pre-screen does).  Returns ``prescreened`` (updated in place).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    prescreened : dict
        :func:`heavecomp.diagnosis.screen.prescreen` result.
    names : sequence of str
        The candidates tested.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        ``score_test_explained``.
    progress : callable(str), optional
        One line per candidate tested.
    """
    jobs = [(n, dict(p)) for n in names for p in get(n).fit.probes]
    t0 = time.perf_counter()
    preds = ctx.map(lambda job: ctx.simulate([job]), jobs)
    wall = (time.perf_counter() - t0) / max(len(names), 1)
    for n in names:
        mine = [p for (m, _), p in zip(jobs, preds) if m == n]
        got = predicted(ctx, mine)
        keep = not got["explained"] < policy.score_test_explained  # a diverged probe (inf, nan): replayed
        entry = prescreened[n]
        entry["score_test"] = dict(got, probes=[p for m, p in jobs if m == n], threshold=policy.score_test_explained)
        entry["wall_time"] = entry.get("wall_time", 0.0) + wall
        if not keep:
            entry["replay"] = False
            entry["reason"] = (f"score test: its probes' Gauss-Newton step from the null explains at most "
                               f"{100 * got['explained']:.1f} % of the gap above noise (held out "
                               f"{100 * got['held_out']:.1f} %, fit part {100 * got['fit_part']:.1f} %, best probe "
                               f"{100 * got['probe']:.1f} %; under {100 * policy.score_test_explained:g} %; the "
                               f"equation error is blind to it and its component {entry['component']} shows no gap)")
        if progress is not None:
            progress(f"{n}: score test predicts {100 * got['explained']:.0f} % explained "
                     f"({'replayed' if keep else 'not replayed'})")
    if not any(o["replay"] for o in prescreened.values()):  # the verdict needs a fit: as the pre-screen, all
        for n in names:
            prescreened[n]["replay"] = True
            prescreened[n].pop("reason", None)
            prescreened[n]["score_test"]["overridden"] = "no candidate would be fitted: every one is"
    return prescreened

