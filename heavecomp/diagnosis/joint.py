"""A second effect: joint fits of the best candidate with runners-up (:func:`search`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from heavecomp.diagnosis import fitting as F
from heavecomp.diagnosis import score_test as T
from heavecomp.diagnosis.replay import sorted_config
from heavecomp.diagnosis.screen import candidate_component
from heavecomp.effects.candidates import get, same_family


@dataclasses.dataclass(frozen=True)
class SecondSearch:
    """The result of :func:`search`: the ``second_effect`` (None: no partner added enough) and every
    partner ``tried`` ({effect, explained_joint, added_explained}, in the order tried)."""

    best: dict | None
    tried: tuple = ()

    def candidates(self, n: int = 3) -> list:
        """The ``n`` joint partners that added most, best first (a user sees the likeliest second
        effect even when it falls short of the bar for naming it)."""
        return sorted(self.tried, key=lambda r: -r["added_explained"])[:n]


def partners(fits, shares, prescreened, n_second, policy) -> list:
    """The runners-up fitted jointly with the best: the ``n_second`` best-ranked, plus the best candidate
    of each other component holding ``second_share`` of the equation-error gap (``shares``).  Any pair
    works except two output candidates (one transport delay per configuration) and two laws of one
    family (``friction_lag`` in time and in distance: one answer, :func:`heavecomp.effects.candidates.family_of`).

    Parameters
    ----------
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best first.
    shares : dict
        Equation-error share of the gap [-] per component (``where.components``).
    prescreened : dict
        :func:`heavecomp.diagnosis.screen.prescreen` result (each candidate's component).
    n_second : int
        Best-ranked runners-up tried jointly.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds (``second_share``).
    """
    best = fits[0]
    best_output = get(best.effect).kind == "output"
    # a second law of the best's own family is the same answer, not a second effect
    allowed = [r for r in fits[1:] if not (best_output and get(r.effect).kind == "output")
               and not same_family(r.effect, best.effect)]
    chosen = allowed[:n_second]
    # a second gap in another component: its best candidate, however it ranked alone
    have = {candidate_component(r.effect, r.values, prescreened) for r in [best] + chosen}
    for r in allowed[n_second:]:
        comp = candidate_component(r.effect, r.values, prescreened)
        if comp not in have and shares.get(comp, 0.0) >= policy.second_share:
            chosen.append(r)
            have.add(comp)
    return chosen


def search(ctx, fits, shares, prescreened, n_second, search=F.Search()) -> SecondSearch:
    """Joint fit of the best candidate (held at its fitted values) with each partner
    (:func:`partners`, fitted concurrently, costliest first); the one whose joint held-out explained
    share exceeds the best's by more than ``second_gain`` after the parsimony penalty is the
    ``second_effect``.  The ranking alone is a poor guide to the partner (alone, a candidate may mimic
    the dominant effect's remainder or distort to absorb it), so the components' shares add the
    partners they see without replaying them.  Default 4 + those: the joint fits were half of the
    diagnosis' time with every runner-up tried (bench_600s).

    A partner fitted through the replay (not a channel reading) is asked first, as the score test asks a
    blind candidate (:func:`heavecomp.diagnosis.score_test.joint_prediction`): the joint start (the
    partner at its own fit) and one secant per parameter the joint fit moves are replayed whole, and the
    Gauss-Newton step from the start predicts the joint explained share (the largest of held out, fit
    part and the replays' own).  Where it adds no more than ``second_gain`` after the penalty by any of
    the three (each against the best's own share by the same measure: the fit part's is in-sample), the
    bar the fit itself must pass to be named, the partner is not fitted: its ``tried`` row carries the
    prediction (``score_test``; ``explained_joint`` the best's explained share plus what it adds).  On bench_600s the prediction was within 0.002 of the fit
    (string_damping 0.861 against 0.859, parameter_mismatch 0.850 against 0.849; both add under 0):
    3 and 2 replays against 23 and 18.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best first.
    shares : dict
        Equation-error share of the gap [-] per component (``where.components``).
    prescreened : dict
        :func:`heavecomp.diagnosis.screen.prescreen` result (each candidate's component).
    n_second : int
        Best-ranked runners-up tried jointly (:func:`partners`).
    search : heavecomp.diagnosis.fitting.Search
        Search effort of each joint fit.
    """
    P = ctx.policy
    best = fits[0]
    fixed = [(best.effect, best.values)]
    chosen = partners(fits, shares, prescreened, n_second, P)
    tested = {}  # partner -> its joint score test (a partner fitted through the replay)
    best_fit = ctx.explained(ctx.mse(ctx.nominal_pred, ctx.fitmask), ctx.mse(best.pred, ctx.fitmask))

    def joint(r):
        cls = F.candidate_class(ctx, r.effect)
        start = r.values if cls.kind != "output" else None
        start_pred = None
        if start is not None:
            # the score test of the joint fit: its Gauss-Newton step from the start predicts what the fit can
            # add; under the naming bar (second_gain, after the penalty) the partner is not fitted
            lo, hi = cls.search_box(ctx.replay.nominal)
            x = cls.to_x(start)
            free = np.flatnonzero(x != cls.x0()) if cls.kind == "nominal" else np.arange(x.size)
            got, start_pred = T.joint_prediction(ctx, fixed, cls, start, free, lo, hi)
            # what the joint adds by each of the prediction's measures, against the best's own by the same
            # measure (the fit part's share is in-sample: against the best's fit-part share)
            added = max(got["held_out"] - best.explained, got["probe"] - best.explained, got["fit_part"] - best_fit)
            gain = added - P.penalty * F.n_params(ctx, r.effect, r_fit(r))
            tested[r.effect] = dict(got, free=int(free.size), added=float(added))
            if math.isfinite(gain) and gain <= P.second_gain:  # a diverged prediction (nan, inf) is fitted
                return None, start_pred, best.explained + added
        fitted = F.fit(ctx, r.effect, start=start, fixed=fixed, search=search)
        same = start_pred is not None and sorted_config([(r.effect, fitted.values)]) == \
            sorted_config([(r.effect, dict(start))])
        pred = start_pred if same else ctx.simulate(fixed + [(r.effect, fitted.values)])
        return fitted, pred, ctx.explained(ctx.mse_before, ctx.mse(pred, ctx.valmask))

    def r_fit(r):  # the partner's own fit as a Fit (its parameters counted as its own fit counted them)
        return F.Fit(r.values, {}, 0, math.nan, n_params=r.n_params)

    order = sorted(range(len(chosen)), key=lambda i: -F.fit_cost(ctx, chosen[i].effect))  # costliest first
    results = [None] * len(chosen)
    for i, got in zip(order, ctx.map(joint, [chosen[i] for i in order])):
        results[i] = got
    # the heave-noise draws only lower a joint fit's explained share: drawn only where the replay's own
    # share adds more than second_gain (a partner that may be named); the others are recorded on the replay
    drawn = []
    for k, (r, (fitted, pred, expl)) in enumerate(zip(chosen, results)):
        if fitted is None:  # not fitted: its joint score test left no room for it
            continue
        gain = expl - best.explained - P.penalty * F.n_params(ctx, r.effect, fitted)
        if math.isfinite(expl) and gain > P.second_gain:
            drawn.append(k)
    for k in drawn:
        fitted, pred, expl = results[k]
        cfg = fixed + [(chosen[k].effect, fitted.values)]
        pert = ctx.map(lambda hs, cfg=cfg: ctx.simulate(cfg, hs=hs), ctx.hs_pert)
        results[k] = (fitted, pred, min(expl, ctx.explained_perturbed(pert)))
    out, tried = None, []
    for k, (r, (fitted, pred, expl)) in enumerate(zip(chosen, results)):
        if not math.isfinite(expl):
            continue
        gain = expl - best.explained - P.penalty * F.n_params(ctx, r.effect, fitted or r_fit(r))
        row = {"effect": r.effect, "explained_joint": float(expl), "added_explained": float(gain),
               "perturbed_heave": k in drawn}
        if fitted is None:  # the score test's prediction, not a fit
            row["score_test"] = tested[r.effect]
        tried.append(row)
        if fitted is not None and gain > P.second_gain and (out is None or gain > out["added_explained"]):
            mse_a = ctx.mse(pred, ctx.valmask)
            out = {"effect": r.effect, "parameters": F.public(ctx.replay.nominal, r.effect, fitted.values),
                   "added_explained": float(gain), "explained_joint": float(expl),
                   "shrink_joint": 1.0 - math.sqrt(mse_a[ctx.primary] / max(ctx.mse_before[ctx.primary], 1e-30))}
    return SecondSearch(out, tuple(tried))
