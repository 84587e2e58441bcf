"""Fitting strategies: each ``(context, effect, start) -> Fit`` on the fit part of a prepared run.

A strategy reads the frozen :class:`~heavecomp.diagnosis.replay.ReplayContext` and fits one candidate
effect class (optionally jointly after ``fixed`` configurations already fitted):

- :func:`fit_replayed` -- a plant or nominal candidate through the replay: a coarse start grid
  (<= 2 parameters) or the equation-error start, then Nelder-Mead (<= 2 parameters: stick-slip costs are
  piecewise smooth) or bounded least squares with a rescan of the rugged parameters; a smooth law
  (``FitSpec.smooth``: a string damping) by least squares (Gauss-Newton) from its start, no grid;
- :func:`fit_linear_output` -- a channel reading affine in its parameters (sensor_gain, sensor_offset):
  linear least squares per channel, refined through the replay on stroke and WOB;
- :func:`fit_delay_output` -- a channel delay (sensor_delay): a scan refined by a bounded scalar search.

A nominal candidate (``parameter_mismatch``) goes through the replay too, by a forward stepwise
refit (:func:`stepwise`): only the parameters the fit part asks for are released.

:func:`fit` picks the strategy; :func:`score` turns a fit into a :class:`CandidateFit`, its held-out
record (the rows of ``diagnosis.json``'s ``candidates``).
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import functools
import logging
import math
import time
import types

import numpy as np

from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.diagnosis.replay import CH, sorted_config
from heavecomp.diagnosis.stepper import CHANNELS as SC
from heavecomp.effects.candidates import MISMATCH_KEYS, ParameterMismatch, get

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class Search:
    """How hard a strategy searches: ``max_nfev`` model evaluations per candidate, ``grid`` points per
    axis of the coarse start grid, ``scan`` points of the rescan of each rugged parameter, ``n_jobs``
    threads for the least-squares Jacobian."""

    max_nfev: int = 40
    grid: int = 7
    scan: int = 6
    n_jobs: int = 1


@dataclasses.dataclass(frozen=True)
class Fit:
    """One candidate fitted on the fit part: parameter ``values`` [SI], their 1-sigma ``sigma``,
    model evaluations ``nfev``, fit cost (weighted sum of squares), wall time [s] and, where optional
    parameters were held at null, the parameters used (``n_params``; None: all)."""

    values: dict
    sigma: dict
    nfev: int
    cost: float
    wall_time: float = 0.0
    n_params: int | None = None
    #: a stroke or WOB reading's refinement through the replay, per channel (:func:`_refine_reading`)
    refinement: dict | None = None


@dataclasses.dataclass(frozen=True)
class CandidateFit:
    """A fitted candidate scored on the held-out part (a row of ``candidates``).

    ``channels`` {channel: {rms_before, rms_after, shrink}} [SI, -]; ``explained`` the smaller of
    ``explained_replay`` and ``explained_perturbed`` (the heave-noise draws' median); ``score`` =
    explained - penalty x ``n_params``; ``values`` the fit's parameters, ``parameters`` as reported
    (parameter_mismatch: named nominal values); ``pred`` the held-out replay; ``at_bound`` the
    parameters at a search bound."""

    effect: str
    parameters: dict
    uncertainty: dict
    channels: dict
    explained: float
    explained_replay: float
    explained_perturbed: float
    n_params: int
    score: float
    fit_wall_time: float
    values: dict
    pred: dict = dataclasses.field(repr=False, compare=False, default=None)
    at_bound: tuple = ()
    #: a reading's refinement through the replay per channel (:attr:`Fit.refinement`; None: not a reading)
    refinement: dict | None = None
    #: heave-noise draws ``explained_perturbed`` is the median of (0: not drawn; more than
    #: ``perturbed_draws`` where the first ones disagreed, :func:`draws_disagree`)
    heave_draws: int = 0

    @property
    def primary(self) -> str:
        """The primary channel: WOB, else the first of the replay's channels the run has."""
        return next(c for c in CH if c in self.channels)

    @property
    def rms_before(self) -> float:
        return self.channels[self.primary]["rms_before"]

    @property
    def rms_after(self) -> float:
        return self.channels[self.primary]["rms_after"]

    @property
    def shrink(self) -> float:
        return self.channels[self.primary]["shrink"]

    def to_json(self) -> dict:
        """The ``candidates`` row (contract fields first)."""
        return {"effect": self.effect, "parameters": self.parameters, "uncertainty": self.uncertainty,
                "rms_before": self.rms_before, "rms_after": self.rms_after, "shrink": self.shrink,
                "channels": self.channels, "explained": self.explained, "explained_replay": self.explained_replay,
                "explained_perturbed_heave": self.explained_perturbed, "n_params": self.n_params,
                "heave_draws": self.heave_draws, "score": self.score, "fit_wall_time": self.fit_wall_time,
                "at_bound": list(self.at_bound), **({} if self.refinement is None else {"refinement": self.refinement})}


def public(nominal, name, values) -> dict:
    """A candidate's parameters as reported (parameter_mismatch: the nominal's values it stands for).

    Parameters
    ----------
    nominal : heavecomp.params.CMCParams
        Nominal parameters (the values a parameter_mismatch multiplies).
    name : str
        Candidate effect name (:func:`heavecomp.effects.candidates.get`).
    values : dict
        Fitted parameter values [SI] of the candidate.
    """
    if name == "parameter_mismatch":
        return ParameterMismatch.named_values(nominal, values)
    return dict(values)


def at_bounds(name, values, tol=VerdictPolicy.bound_tol, params=None) -> list:
    """Fitted parameters of candidate ``name`` that sit at a bound of their search range
    (within ``tol`` of the range, on the fit's own scale: log where the candidate fits in log);
    not those whose bounds are the ends of their physical range (``cls.fit.limits``: a share of 0 or 1).

    Returns a list of {parameter, value, side ("lower" | "upper"), bound}.

    Parameters
    ----------
    name : str
        Candidate effect name.
    values : dict
        Fitted parameter values [SI] of the candidate.
    tol : float [-]
        Share of the search range (on the fit's scale) counted as at a bound.
    params : CMCParams, optional
        The parameter set the fit ran against: its search box (:meth:`Effect.search_box`, a refit's box
        anchored to the file's ``[anchor]``); None: the fields' bounds.
    """
    cls = get(name)
    lo, hi = cls.search_box(params)
    out = []
    for f, a, b in zip(cls.fields(), lo, hi):
        v = values.get(f.name)
        if not isinstance(v, (int, float)) or not math.isfinite(v) or f.name in cls.fit.limits:
            continue
        x = math.log(v) if f.name in cls.fit.log and v > 0 else v
        span = tol * (b - a)
        side = "upper" if x >= b - span else "lower" if x <= a + span else None
        if side:
            bound = float(f.metadata["bounds"][1 if side == "upper" else 0])
            edge = b if side == "upper" else a
            if not math.isclose(edge, math.log(bound) if f.name in cls.fit.log and bound > 0 else bound):
                bound = math.exp(edge) if f.name in cls.fit.log else edge  # an anchored box
            out.append({"parameter": f.name, "value": float(v), "side": side, "bound": bound,
                        "unit": f.metadata["unit"]})
    if cls is ParameterMismatch:  # the names the verdict's parameters use ("table.key"), values as multipliers
        names = {f.name: key for f, (key, _, _) in zip(cls.fields(), MISMATCH_KEYS)}
        for o in out:
            o["parameter"] = names.get(o["parameter"], o["parameter"])
    return out


def channel_scores(mse_b, mse_a) -> dict:
    """Held-out rms before and after, and shrink, per channel.

    Parameters
    ----------
    mse_b, mse_a : dict
        Held-out mean squares per channel [SI^2] before (nominal) and after (candidate), on the channels
        the run has.
    """
    return {c: {"rms_before": math.sqrt(mse_b[c]), "rms_after": math.sqrt(mse_a[c]),
                "shrink": 1.0 - math.sqrt(mse_a[c] / mse_b[c]) if mse_b[c] > 0 else 0.0} for c in CH if c in mse_b}


def score(ctx, name, fitted: Fit, pred, pred_pert) -> CandidateFit:
    """The held-out record of candidate ``name`` fitted as ``fitted``, from its replay ``pred`` and its
    replays on the heave-noise draws ``pred_pert``.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    name : str
        Candidate effect name.
    fitted : Fit
        The candidate's fit on the fit part.
    pred : dict
        Its whole replay ({channel: array} [SI], :meth:`ReplayContext.simulate`).
    pred_pert : list of dict or None
        Its replays on the heave-noise draws (:attr:`ReplayContext.hs_pert`); None: not drawn (the
        explained share is the replay's, ``explained_perturbed`` None).
    """
    P = ctx.policy
    mse_a = ctx.mse(pred, ctx.valmask)
    expl_plain = ctx.explained(ctx.mse_before, mse_a)
    # robustness: the same comparison with the heave-perturbed replay; a gain that comes
    # from lucky stick-event timing does not survive it, a real effect does.  None: not drawn (out of
    # contention, its replay's own score below every candidate the verdict reads: the draws only lower it)
    expl_pert = None if pred_pert is None else ctx.explained_perturbed(pred_pert)
    expl = expl_plain if expl_pert is None else min(expl_plain, expl_pert)
    if not math.isfinite(expl):  # the fitted model diverged on held-out data
        log.warning("diagnose: %s diverged on the held-out data", name)
        expl = P.diverged_explained
    k = n_params(ctx, name, fitted)  # optional parameters held at null are not counted
    return CandidateFit(name, public(ctx.replay.nominal, name, fitted.values), fitted.sigma,
                        channel_scores(ctx.mse_before, mse_a), float(expl), float(expl_plain),
                        None if expl_pert is None else float(expl_pert), k,
                        float(expl - P.penalty * k), fitted.wall_time, fitted.values, pred,
                        tuple(at_bounds(name, fitted.values, tol=P.bound_tol, params=ctx.replay.nominal)),
                        fitted.refinement, 0 if pred_pert is None else len(pred_pert))


def draws_disagree(ctx, pred, preds) -> bool:
    """Whether the first heave-noise draws disagree on a candidate (``VerdictPolicy.draw_disagreement``):
    one keeps less than that share of its replay's explained share ``pred`` and another at least as much,
    and the input envelope has more draws to settle it (:attr:`ReplayContext.more_draws`).  A candidate
    whose replay explains less than ``none_explained`` (the least any verdict reads) is not settled
    further: its draws cannot change what the verdict reads.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    pred : dict
        The candidate's whole replay.
    preds : list of dict
        Its replays on the first draws (:attr:`ReplayContext.hs_pert`).
    """
    if not ctx.mse_before_more or ctx.more_draws is None:
        return False
    e_rep = ctx.explained(ctx.mse_before, ctx.mse(pred, ctx.valmask))
    if not (math.isfinite(e_rep) and e_rep >= ctx.policy.none_explained):
        return False
    e = ctx.explained_draws(preds)
    bar = ctx.policy.draw_disagreement * e_rep
    return min(e) < bar <= max(e)


def upper_score(ctx, name, fitted: Fit, pred) -> float:
    """The highest score candidate ``name`` can reach (:func:`score`) from its replay ``pred`` alone: its
    explained share on the replay less the parsimony penalty (the heave-noise draws can only lower it).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    name : str
        Candidate effect name.
    fitted : Fit
        The candidate's fit.
    pred : dict
        Its whole replay.
    """
    e = ctx.explained(ctx.mse_before, ctx.mse(pred, ctx.valmask))
    if not math.isfinite(e):
        e = ctx.policy.diverged_explained
    return float(e - ctx.policy.penalty * n_params(ctx, name, fitted))


def candidate_class(ctx, name) -> type:
    """The class fitted for candidate ``name`` on this run (``Effect.for_input``: heave_reference
    without a logged angle fits g and t_d only).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    name : str
        Candidate effect name.
    """
    return get(name).for_input(ctx.replay.hs)


def n_params(ctx, name, fitted: Fit) -> int:
    """Parameters a fit used (optional ones held at null are not counted).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    name : str
        Candidate effect name.
    fitted : Fit
        The candidate's fit (its ``n_params``, None: all the class's parameters).
    """
    return candidate_class(ctx, name).n_params() if fitted.n_params is None else fitted.n_params


def fit_cost(ctx, name) -> float:
    """Rough wall time of fitting candidate ``name`` alone (relative; bench_600s): the thread pool
    starts the costliest first so that no long fit is left running alone at the end.  A plant effect
    replays on the library stepper (~1.5x the plain one) ~40 times (grid + Nelder-Mead), weighted
    2.7 per replay (the order bench_600s was measured with; 1.5 measured the same under load); the
    six-parameter refit ~250 times on the plain stepper (the stepwise refit: a scan of each parameter
    on the grid span and two refits for the first release, then per step a Jacobian, two probes per
    parameter and two refits, and a swap's refit; 233-252 replays on the planted runs of
    tests/test_diagnosis_recovery.py and the loop scenario's mismatch logs); an output
    candidate a few times.  The order changes no result (every fit is independent).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    name : str
        Candidate effect name.
    """
    cls = candidate_class(ctx, name)
    if cls.kind == "output":
        return 1.0
    if cls.kind == "nominal":
        return 250.0
    per_replay = 2.7 if cls.kind == "plant" else 1.0
    return per_replay * (40.0 if cls.n_params() <= 2 else 100.0)


def fit(ctx, name, start=None, fixed=(), *, search=Search(), hint=None, room=None) -> Fit:
    """Fit candidate ``name`` (optionally jointly after the ``fixed`` configurations) on the fit part,
    from ``start`` (parameter values; None: the default start, the coarse grid and the equation-error
    start ``hint``, a fit vector) with the strategy its kind asks for.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    name : str
        Candidate effect name.
    start : dict, optional
        Start parameter values [SI]; None: the default start (coarse grid, equation-error ``hint``).
    fixed : sequence of (str, dict)
        Configurations ``(effect name, values)`` already fitted and held in the model (a joint fit).
    search : Search
        Search effort (evaluations, grid and scan points, threads).
    hint : numpy.ndarray, optional
        Equation-error start as a fit vector (``cls.to_x``; a smooth candidate the equation error is blind
        to: its score test's step, :func:`heavecomp.diagnosis.score_test.start`); None: none.
    room : sequence of int, optional
        A nominal candidate's parameters the equation error leaves room for (the stepwise refit releases
        only those, :func:`heavecomp.diagnosis.screen.mismatch_room`); None: every one.
    """
    cls = candidate_class(ctx, name)
    t0 = time.perf_counter()
    out = _fit_once(ctx, cls, start, fixed, search, hint, room=room)
    if cls.kind in READING_KINDS:
        for _ in range(ctx.policy.reading_reweight):
            out = _fit_once(reweighted(ctx, list(fixed) + [(cls.name, out.values)]), cls, out.values, fixed, search,
                            None, out.values.get("channel"))
    return dataclasses.replace(out, wall_time=time.perf_counter() - t0)


#: effect kinds that correct a reading (a measured channel, the heave input): fitted with re-weighting
READING_KINDS = ("output", "heave")

#: Nelder-Mead's first simplex step [share of each parameter's search range] from a start the grid or the
#: defaults picked (the optimum may be a fair part of the range away); a start next to the optimum takes
#: ``VerdictPolicy.start_step``
NM_STEP = 0.08


def _fit_once(ctx, cls, start, fixed, search, hint, channel=None, room=None) -> Fit:
    """One fit of ``cls`` with the strategy its kind asks for (``channel``: an output effect's channel
    held, else every channel tried)."""
    if cls.kind == "output" and cls.fit.linear:
        return fit_linear_output(ctx, cls, fixed, channel)
    if cls.kind == "output":
        return fit_delay_output(ctx, cls, fixed, channel)
    return fit_replayed(ctx, cls, start, fixed, search=search, hint=hint, room=room)


def reweighted(ctx, config):
    """``ctx`` with every channel's fit weight 1 / max(mse, noise floor^2) of the fit-part residual of
    the configuration ``config`` (a fitted reading candidate) instead of the nominal's.

    The nominal's weights (:func:`heavecomp.diagnosis.replay.prepare`) are smallest on the channel the
    nominal misses worst; for a reading candidate that is the misread channel itself, whose fit then
    stops short (``VerdictPolicy.reading_reweight``).  Weighted by the candidate's own residual, a
    channel it fits down to its noise counts as much as its noise says.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    config : sequence of (str, dict)
        The fitted configuration ``(effect name, values)`` whose residual sets the weights.
    """
    pred = ctx.simulate(list(config), ctx.split["fit"][1])
    mse_fit = ctx.mse(pred, ctx.fitmask)
    weights = {c: 1.0 / max(mse_fit[c] if math.isfinite(mse_fit[c]) else math.inf, ctx.noise_floor[c] ** 2, 1e-30)
               for c in ctx.channels}
    if any(not math.isfinite(w) or w <= 1e-30 for w in weights.values()):  # a diverged replay: keep the nominal's
        return ctx
    return dataclasses.replace(ctx, weights=weights)


# ------------------------------------------------------------------ through the replay
def fit_replayed(ctx, cls, start=None, fixed=(), *, search=Search(), hint=None, room=None) -> Fit:
    """A plant or nominal candidate fitted through the replay (see the module docstring).

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    cls : type
        The candidate's effect class (:func:`candidate_class`).
    start : dict, optional
        Start parameter values [SI]; None: the default start (coarse grid, equation-error ``hint``).
    fixed : sequence of (str, dict)
        Configurations ``(effect name, values)`` already fitted and held in the model (a joint fit).
    search : Search
        Search effort (evaluations, grid and scan points, threads).
    hint : numpy.ndarray, optional
        Equation-error start as a fit vector (``cls.to_x``; a smooth candidate the equation error is blind
        to: its score test's step, :func:`heavecomp.diagnosis.score_test.start`); None: none.
    room : sequence of int, optional
        A nominal candidate's parameters its stepwise refit may release (:func:`stepwise`'s ``eligible``).
    """
    P = ctx.policy
    t_end = ctx.split["fit"][1]
    noise = P.search_resolution * noise_cost(ctx)  # a search stops where the noise cannot tell its steps apart
    x0 = cls.to_x(start) if start else cls.x0()
    lo, hi = cls.search_box(ctx.replay.nominal)  # a refit of a calibrated file: about its [anchor]
    x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
    seen = {}  # residual by (span, parameter vector): e.g. Nelder-Mead's optimum is evaluated again for its Jacobian

    def fun(x, t_stop=t_end):
        config = list(fixed) + [(cls.name, cls.from_x(x))]
        key = (t_stop, sorted_config(config))  # the replay's input: two vectors may give the same parameters
        if key not in seen:
            seen[key] = ctx.resid_vec(ctx.simulate(config, t_stop))
        return seen[key].copy()

    # a joint fit starts from the candidate's own fit, next to its optimum: a share of the budget
    budget = max(1, int(P.joint_nfev * search.max_nfev)) if fixed else search.max_nfev
    t_grid = min(t_end, ctx.split["settle"] + P.grid_span)
    if cls.kind == "nominal":  # a nominal refit releases only the parameters the fit part asks for
        release = None if start is None else np.flatnonzero(x0 != cls.x0())
        r = stepwise(fun, x0 if start else cls.x0(), lo, hi, budget, t_grid, P.refit_release, search, release,
                     noise_cost(ctx), P.refit_f, room, noise)
        # parsimony counts what moved (issue 30 item 3): the parameters released, not all it could release
        moved = int(np.count_nonzero(np.abs(np.asarray(r.x) - cls.x0()) > 1e-12))
        return Fit(cls.from_x(r.x), sigma(cls, r), int(r.nfev), float(2 * r.cost), n_params=moved)
    later = np.array([f.name in cls.fit.released_last for f in cls.fields()])
    smooth = bool(cls.fit.smooth)
    if start is None and later.any():
        def release(by_least_squares):
            return _fit_then_release(fun, x0, lo, hi, ~later, budget, t_grid, search, hint, P.start_step,
                                     by_least_squares, noise)

        r = release(smooth)
        if smooth and _worse_than_null(ctx, fixed, t_end, r):  # a local search lost on a rugged cost: the grid's way
            r = _better(r, release(False))
        if cls.fit.rugged:  # the rugged parameters' second start (rescan), as on the grid's way below
            r = rescan(cls, fun, r, lo, hi, ctx.replay.nominal, search)
        return Fit(cls.from_x(r.x), sigma(cls, r), int(r.nfev), float(2 * r.cost))

    def searched():
        """The grid's start (or the equation error's, with a small first simplex, ``VerdictPolicy.start_step``),
        then Nelder-Mead for up to two parameters, else least squares and the rugged parameters' rescan."""
        x, near = (x0, False) if start is not None else _start(cls, fun, x0, lo, hi, t_grid, search.grid, hint)
        if x.size <= 2:
            return nelder_mead(fun, x, lo, hi, budget, P.start_step if near else NM_STEP, noise)
        r = least_squares(fun, x, lo, hi, budget, search.n_jobs)
        return rescan(cls, fun, r, lo, hi, ctx.replay.nominal, search) if start is None else r

    if smooth:  # a smooth law (FitSpec.smooth): Gauss-Newton from its start (the equation error's where it costs less)
        x1 = _start(cls, fun, x0, lo, hi, t_grid, 0, hint)[0] if start is None else x0
        r = least_squares(fun, x1, lo, hi, budget, search.n_jobs)
        if start is None and _worse_than_null(ctx, fixed, t_end, r):  # lost on a rugged cost: the grid's way too
            r = _better(r, searched())
    else:
        r = searched()
    return Fit(cls.from_x(r.x), sigma(cls, r), int(r.nfev), float(2 * r.cost))


def _worse_than_null(ctx, fixed, t_end, r) -> bool:
    """A fit that costs more on the fit part than its own null (the candidate off: the nominal, or the joint
    fit's partners alone) has not found its optimum: every candidate reaches its null within its bounds, or
    near it.  A smooth law's Gauss-Newton fit can end there when stick events make the cost rugged after all
    (scored 960024, a near-noise quadratic string damping: from the default 3e4 N s/m the linear dashpot
    stopped at 2.9e4, fit-part explained share -1.2, where the grid's start found 1.3e4 at +1.9, held-out WOB
    shrink 0.60 against 0.43).  One replay of the null (the nominal's is in the replay's ledger)."""
    base = ctx.resid_vec(ctx.simulate(list(fixed), t_end))
    return float(r.cost) > 0.5 * float(base @ base)


def _better(a, b):
    """The lower-cost of two optimizer results, with both searches' evaluations counted."""
    best = a if float(a.cost) <= float(b.cost) else b
    best.nfev = int(a.nfev) + int(b.nfev)
    return best


def _fit_then_release(fun, x0, lo, hi, keep, budget, t_grid, search, hint, start_step=None, smooth=False, noise=0.0):
    """The fit of the parameters ``keep`` with the others held at ``x0`` (as :func:`fit_replayed` fits
    that smaller candidate: coarse start grid, Nelder-Mead for up to two; a ``smooth`` law by least
    squares from its start, no grid), then every parameter released by least squares from that optimum
    (``cls.fit.released_last``).  Least squares only takes steps that lower the cost, so the result
    costs no more on the fit part than the smaller fit.

    Parameters
    ----------
    fun : callable
        Residual vector of a full fit vector (``fun(x)`` or ``fun(x, t_stop)``).
    x0 : numpy.ndarray
        Start; the held parameters stay at their values here in the first stage.
    lo, hi : numpy.ndarray
        Bounds of the full fit vector.
    keep : numpy.ndarray of bool
        The parameters fitted in the first stage.
    budget : int
        Function evaluations of each stage.
    t_grid : float [s]
        Span of the start grid's evaluations.
    search : Search
        Search effort (``grid``, ``n_jobs``).
    hint : numpy.ndarray or None
        Equation-error start as a full fit vector.
    start_step : float, optional
        First simplex step (share of the range) from the equation-error start (``VerdictPolicy.start_step``;
        None: :data:`NM_STEP`).
    smooth : bool
        The law is smooth (``FitSpec.smooth``): no grid, the first stage by least squares too.
    noise : float [-]
        The first stage's stop: the search's share of the output noise's cost (:func:`nelder_mead`).
    """
    def part(xs, *t_stop):
        x = x0.copy()
        x[keep] = xs
        return fun(x, *t_stop)

    x1 = x0.copy()
    x1[keep], near = _start(None, part, x0[keep], lo[keep], hi[keep], t_grid, 0 if smooth else search.grid,
                            None if hint is None else hint[keep])
    r1 = _refit_subset(fun, x1, np.flatnonzero(keep), lo, hi, budget, search.n_jobs,
                       start_step if near and start_step is not None else NM_STEP, smooth, noise)
    r = least_squares(fun, np.clip(r1.x, lo + 1e-9, hi - 1e-9), lo, hi, budget, search.n_jobs)
    r.nfev = int(r.nfev) + int(r1.nfev)
    return r


def effective_samples(r) -> float:
    """Independent samples [-] of a residual vector ``r`` whose samples are correlated: its length
    over the integrated autocorrelation time 1 + 2 sum rho_k, the sum over the initial positive
    sequence of the autocorrelation rho_k (Geyer's truncation); at least 1.

    Parameters
    ----------
    r : array_like [-]
        A residual vector (e.g. the weighted replay residual of a fit).
    """
    r = np.asarray(r, dtype=float)
    r = r - r.mean()
    m = r.size
    if m < 3 or not np.any(r):
        return float(max(m, 1))
    f = np.fft.rfft(r, 2 * m)
    ac = np.fft.irfft(f * np.conj(f))[:m]
    rho = ac / ac[0]
    stop = np.flatnonzero(rho[1:] <= 0.0)
    tau = 1.0 + 2.0 * float(np.sum(rho[1:1 + (stop[0] if stop.size else m - 1)]))
    return float(max(m / tau, 1.0))


def noise_cost(ctx) -> float:
    """Expected fit cost [-] of the output noise alone: what a right model's replay leaves of the
    weighted, decimated fit residual (:meth:`heavecomp.diagnosis.replay.ReplayContext.resid_vec`),
    each channel's samples times its weight times its noise floor squared.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run: its fit mask, decimation, channel weights and noise floors.
    """
    total = 0.0
    for c in ctx.channels:
        n = int(np.count_nonzero((ctx.fitmask & np.isfinite(ctx.y[c][: ctx.fitmask.size]))[:: ctx.decimate]))
        total += n * ctx.weights[c] * ctx.noise_floor[c] ** 2
    return float(total)


def cost_resolution(noise, r) -> float:
    """The fit-cost change [-] the output noise resolves at the residual ``r``: ``noise`` (a share of the
    noise-only cost, :func:`noise_cost`) times the chi-square's relative spread sqrt(2 / n_eff), n_eff the
    independent samples of ``r`` (:func:`effective_samples`).  A search step that changes the cost by less
    cannot change a verdict (``VerdictPolicy.search_resolution``).

    Parameters
    ----------
    noise : float [-]
        ``VerdictPolicy.search_resolution`` times the noise-only fit cost.
    r : array_like [-]
        The weighted fit residual the spread is taken at.
    """
    return float(noise * math.sqrt(2.0 / effective_samples(r)))


def stepwise(fun, x0, lo, hi, budget, t_grid, release_share, search=Search(), release=None, floor=0.0,
             f_crit=0.0, eligible=None, noise=0.0):
    """Forward stepwise refit of a nominal parameter set (``parameter_mismatch``): from the nominal
    ``x0``, the parameters are released one at a time.  The first step scans each parameter alone
    (the others held; ``search.grid`` points over 10-90 % of its range, the cost on the first
    ``t_grid`` s) and picks the two best scans (from the nominal the linearised fit is poorest).
    Each later step builds one forward-difference Jacobian at the current best (one evaluation per
    parameter not released, a secant over 10 % of its range; the released ones' columns are the last fit's),
    and for every parameter not released the linearised JOINT fit with the released ones
    (orthogonal matching pursuit) gives a step; the actual cost is probed along it (at the full step
    and at the minimum of the parabola through the cost, its slope and the full step's cost: two
    evaluations), and the two best probed are the picks.  Both picks are refitted jointly with the
    released ones from their best points, on the whole fit part (Nelder-Mead up to two
    parameters, else least squares); the lower fit cost is the step's candidate.  It is released only
    when it passes a partial F-test of stepwise regression: it removes at least the share
    max(``release_share``, ``f_crit`` / n_eff) of the fit cost still left (the current refit's cost,
    and never less than the noise floor's expected cost ``floor``), n_eff the independent samples of
    the current residual (:func:`effective_samples`: a replay residual is correlated over seconds,
    so a short log asks more of a release); and nothing is released once the cost left is within
    the noise's own spread of ``floor`` (under floor (1 + sqrt(2 ``f_crit`` / n_eff)), a chi-square's
    relative spread at the same significance): what is left is noise.  Else the search stops, and
    every parameter not released stays exactly nominal (its multiplier 1, its 1-sigma 0).  After each
    release (from the second on) a floating step predicts every swap of an earlier release (back at
    its start) for a parameter not released by the same linearised fit at a new Jacobian, probes
    each the same way, refits the best probed and keeps it only if its fit cost is lower, while that
    holds.  Where the search stops (a step's picks fail the test, or the noise test stops it) after a
    release and above the noise's expected cost, it restarts once (:meth:`_Stepwise.restart`): the
    releases with each of two picks refitted from the nominal ``x0``, the lower kept if it passes, and
    the search goes on from it.  A first release that stood in for two parameters digs a valley that a
    refit from its point cannot leave (the seal's static and Coulomb forces both x0.79: the static
    force alone at x0.45, then the viscous force, the Coulomb force's probe third; restarted, both at
    x0.78-0.79).  The decisions are taken on refitted costs; the predictions, probes and scans only
    choose what to refit.

    Releasing all parameters at once lets near-collinear ones (a stiffer string against a softer gas
    spring, a viscous against a Coulomb force) trade off along a valley, and the local fit from the
    nominal stalls in it (a planted gas-spring and Coulomb mismatch refitted with every parameter
    moved, at eight times the truth's fit cost; the forward search reaches the truth's).  A bar on
    the nominal cost instead of on what is left misses a second parameter near-collinear with the
    first (the string stiffness once the formation's is released: 30 % of the cost left, 0.7 % of
    the nominal's); trying only the best single-parameter scans misses it too (alone it shows little).
    Forward selection alone keeps a first pick that only stood in for a near-collinear parameter
    (loop seed 571008: a softer string and a lower Coulomb force refitted as a softer formation,
    then the Coulomb, static, string and gas parameters to make up for it, at 1.3 times the truth's
    cost); hence the floating step.  Ranking by the linearised cost alone misranks far from the
    nominal (a 90 s planted gas-spring and string mismatch: with the gas spring released it ranks the
    Coulomb force first, 1026 against the string's 1255, whose refit reaches 0.43 against the
    Coulomb's 709); the probed cost ranks the string first (592 against 792 and 929), and the
    parabola's point catches a parameter whose response bends (the full step overshoots it).  From
    the nominal the probes misrank a stiffness 40 % off (loop seed 570008, string and formation:
    the viscous and gas probes first), hence the scans there.  Refitting every parameter each step
    (scanned for its start) found the same releases on six planted runs at 3.5 times the replays.

    Parameters
    ----------
    fun : callable
        Residual vector of a fit vector ``x``.
    x0 : numpy.ndarray
        The start: the nominal fit vector (forward search), or an earlier refit's (``release``); the
        parameters not released stay at it.
    lo, hi : numpy.ndarray
        Bounds of the fit vector.
    budget : int
        Evaluations of each joint refit.
    t_grid : float [s]
        End of the span the first step's single-parameter scans are scored on.
    release_share : float [-]
        Least share of the fit cost left that a release must remove (``VerdictPolicy.refit_release``).
    search : Search
        Threads of the least-squares Jacobian (``n_jobs``).
    release : sequence of int, optional
        Parameters released from the start (a joint fit from an earlier refit: its released set,
        refitted from ``x0``); None: the forward search.
    floor : float [-]
        Expected fit cost of the output noise alone (a model that is right leaves it); the cost the
        share is taken of never drops under it.
    f_crit : float [-]
        Critical value of the partial F-test (``VerdictPolicy.refit_f``); 0: the share alone.
    eligible : sequence of int, optional
        The parameters the search may release (the others stay at ``x0``: the equation error leaves no
        room for them, :func:`heavecomp.diagnosis.screen.mismatch_room`); None: every one.
    noise : float [-]
        The joint refits' stop: the search's share of the output noise's cost (:func:`nelder_mead`); 0:
        the absolute stop.
    """
    S = _Stepwise(fun, np.asarray(x0, dtype=float).copy(), lo, hi, budget, search.n_jobs, release_share, floor,
                  f_crit, noise)
    x, best = S.x0, S.nominal()
    if release is not None:
        if len(release):
            best = S.refit(x, release)
        best.nfev = S.nfev
        return best
    active: list = []
    pool = list(range(x.size)) if eligible is None else [int(j) for j in eligible]
    S.pool = pool
    floating = 0  # swaps left to try after the last release (the floating step)
    restarted = False  # the restart (below) is tried once
    for _ in range(4 * x.size + 2):  # releases, drops and swaps (each lowers a count or the cost), the restart
        stop = len(active) == len(pool) or not floating and S.noise_left(best)
        rest = [j for j in pool if j not in active]
        picks = None
        if not stop:
            J = S.jacobian(best, rest) if active else None  # one Jacobian at the current best, for the predictions
            if floating and len(active) > 1:
                floating -= 1
                moved = S.floating(best, active, rest, J)
                if moved is not None:
                    active, best = moved
                    continue
                floating = 0
                stop = S.noise_left(best)
        if not stop:
            # the next release: two picks (the best scans from the nominal, else the best probed joint
            # predictions), each refitted jointly with the released ones; the lower kept if it passes
            share = S.share_of(best.fun)
            picks = S.probed_picks(best, active, rest, J) if active else S.scanned_picks(t_grid, search.grid)
            c, j, got = S.best_release(best, active, picks)
            if S.passes(best.cost, c, share):
                active.append(j)
                best = got
                floating = len(pool) if len(active) > 1 else 0
                continue
            log.debug("diagnose: stepwise refit stops: releasing parameter %d lowers the fit cost %.4g -> %.4g", j,
                      2 * best.cost, 2 * c)
        # the search stops: once, the restart (its releases and one more refitted from the nominal)
        log.debug("diagnose: stepwise refit: stopped at fit cost %.4g, the noise's %.4g", 2 * best.cost, S.floor)
        if restarted or not active or len(active) == len(pool):
            break
        restarted = True
        if 2 * best.cost <= S.floor:  # it leaves no more than the noise's expected cost: no valley to leave
            break
        moved = S.restart(best, active, rest, picks)
        if moved is None:
            break
        active, best = moved
        floating = len(pool)
    best.nfev = S.nfev
    return best


class _Stepwise:
    """The evaluations of :func:`stepwise`: the residual ``fun`` of a fit vector, its bounds, the
    joint refit's ``budget``, threads and stop (``noise``), the partial F-test's ``release_share``, ``floor``
    and ``f_crit``, and the count of evaluations ``nfev`` (a refit's own count included)."""

    def __init__(self, fun, x0, lo, hi, budget, n_jobs, release_share, floor, f_crit, noise=0.0):
        self.fun, self.x0, self.lo, self.hi, self.budget, self.n_jobs = fun, x0, lo, hi, budget, n_jobs
        self.release_share, self.floor, self.f_crit, self.noise = release_share, floor, f_crit, noise
        self.nfev = 0
        self.pool = list(range(x0.size))  # the parameters the search may release

    def cost(self, x) -> float:
        """Fit cost (sum of squares) at ``x``."""
        r = self.fun(x)
        self.nfev += 1
        return float(r @ r)

    def nominal(self):
        """The start ``x0`` as a fit result (``x``, ``fun``, ``jac`` zero, ``cost`` half the sum of squares)."""
        f0 = self.fun(self.x0)
        self.nfev += 1
        return types.SimpleNamespace(x=self.x0, fun=f0, jac=np.zeros((f0.size, self.x0.size)), nfev=1,
                                     cost=0.5 * float(f0 @ f0))

    def refit(self, x, act):
        """``x`` with its entries ``act`` refitted (:func:`_refit_subset`)."""
        got = _refit_subset(self.fun, x, act, self.lo, self.hi, self.budget, self.n_jobs, noise=self.noise)
        self.nfev += got.nfev
        return got

    def jacobian(self, best, rest):
        """:func:`_jacobian` at ``best`` for the parameters ``rest``."""
        self.nfev += len(rest)
        return _jacobian(self.fun, best, rest, self.lo, self.hi)

    def probe(self, origin, r0, J, dx):
        """The actual fit cost along the linearised fit's step ``dx`` from ``origin`` (its residual
        ``r0``, or its prediction): at the full step, then at the minimum of the parabola through the
        cost at the origin, its slope there (from ``J``) and the full step's cost (far from the
        nominal the cost is far from quadratic, so the full step can overshoot a parameter whose
        response bends).  Returns the lower cost and its point (clipped to the bounds)."""
        lo, hi = self.lo, self.hi
        c0, g = float(r0 @ r0), 2.0 * float(r0 @ (J @ dx))
        x1 = np.clip(origin + dx, lo + 1e-9, hi - 1e-9)
        c1 = self.cost(x1)
        a = c1 - c0 - g
        t = float(np.clip(-g / (2 * a), 0.2, 2.0)) if a > 0 else 2.0
        xt = np.clip(origin + t * dx, lo + 1e-9, hi - 1e-9)
        ct = self.cost(xt)
        return (ct, xt) if ct < c1 else (c1, x1)

    def share_of(self, r) -> float:
        """The partial F-test's least share of the cost left, at the residual ``r`` (its n_eff)."""
        return max(self.release_share, self.f_crit / effective_samples(r)) if self.f_crit > 0 else self.release_share

    def passes(self, c, c_after, share) -> bool:
        """Whether a release that lowers the half cost ``c`` to ``c_after`` passes the partial F-test
        at ``share`` (of the cost left before it, never counted under the noise's ``floor``)."""
        return 2 * (c - c_after) >= share * max(2 * c, self.floor)

    def noise_left(self, best) -> bool:
        """Whether the cost left is the output noise's (within its own spread at ``f_crit``)."""
        return 2 * best.cost <= self.floor * (1.0 + math.sqrt(2.0 * self.f_crit / effective_samples(best.fun)))

    def scanned_picks(self, t_grid, n):
        """The first release's two picks: the best single-parameter scans (:func:`_best_scans`; from the
        nominal the linearised fit is poorest, e.g. a stiffness 40 % off)."""
        self.nfev += len(self.pool) * n
        return _best_scans(self.fun, self.x0, self.lo, self.hi, t_grid, n, self.pool)[:2]

    def probed_picks(self, best, active, rest, J):
        """A later release's two picks: each parameter of ``rest`` at the point the linearised JOINT
        fit with the ``active`` ones predicts (orthogonal matching pursuit: a parameter near-collinear
        with a released one, e.g. the string against the formation stiffness, shows little alone but
        much jointly), its actual cost probed along it (far from the nominal the linearised cost
        misranks); the two best probed, each from its probe (or ``best`` if the probe costs more)."""
        probes = sorted((self.probe(best.x, best.fun, J, _lin_fit(J, best.fun, active + [j])[1]) + (j,)
                         for j in rest), key=lambda t: t[0])
        log.debug("diagnose: stepwise refit: probed costs %s", [(p[2], round(p[0], 4)) for p in probes])
        return [(j, start if c_p < 2 * best.cost else best.x) for c_p, start, j in probes[:2]]

    def restart(self, best, active, rest, picks=None):
        """The restart, where the search stops: the releases ``active`` with each of two picks refitted
        from the nominal ``x0``, not from ``best`` (the picks of the step that failed, else the two best
        probed at ``best``).  A first release that stood in for two parameters digs a valley a refit from
        its point cannot leave (the seal's static and Coulomb forces both x0.79, independent truth 980000:
        the static force alone at x0.45, then the viscous force; the Coulomb force's probe ranked third),
        and the noise test may stop the search in it (990000, both x0.76: the cost left within the
        noise's spread of its floor on the fit part, held out 0.56 of the gap explained against a
        frictional memory's 0.74).  Kept when it passes the release's test against ``best``: then the
        floating step drops what it no longer needs.  Tried only where the search left more than the
        noise's expected cost (``floor``): below it there is no valley to leave (three planted 90 s
        friction mismatches: 0.95-0.96 of the gap explained without it, at 0.9 of the floor).  Returns
        the new (active, best), or None."""
        if picks is None:
            picks = self.probed_picks(best, active, rest, self.jacobian(best, rest))
        c, j, got = self.best_release(best, active, picks, origin=self.x0)
        return (active + [j], got) if self.passes(best.cost, c, self.share_of(best.fun)) else None

    def best_release(self, best, active, picks, origin=None):
        """Each pick ``(j, start)`` released with ``active`` and refitted jointly, from its ``start`` (or from
        ``origin`` for every pick: the restart's nominal): (fit half-cost, j, result) of the lowest."""
        trials = []
        for j, start in picks:
            got = self.refit(start if origin is None else origin, active + [j])
            trials.append((got.cost, j, got))
            log.debug("diagnose: stepwise refit: releasing %s with %d%s: fit cost %.4g -> %.4g", active, j,
                      "" if origin is None else " from the nominal", 2 * best.cost, 2 * got.cost)
        return min(trials, key=lambda t: t[0])

    def floating(self, best, active, rest, J):
        """The floating step: an earlier release may only have stood in for a parameter near-collinear
        with it (the formation stiffness for the string's in k_eff).  A release that no longer passes
        the test against the others is dropped: the one whose drop the linearised fit predicts to
        cost least, refitted when that prediction fails the test.  Else each swap of an earlier
        release (back at its start) for a parameter of ``rest`` is predicted and probed, the best
        probed refitted and kept only if its fit cost is lower.  Returns the new (active, best), or
        None."""
        x = self.x0
        held = {i: best.fun + J[:, i] * (x[i] - best.x[i]) for i in active}  # i back at its start
        moves = [(i, None) for i in active] + [(i, k) for i in active[:-1] for k in rest]  # drops, swaps
        moves = [(i, [a for a in active if a != i], k) for i, k in moves]
        lin = [(_lin_fit(J, held[i], act + ([] if k is None else [k])), i, k, act) for i, act, k in moves]

        def origin(i):
            o = best.x.copy()
            o[i] = x[i]
            return o

        (c_l, dx), i, _, act = min((m for m in lin if m[2] is None), key=lambda m: m[0][0])
        if not self.passes(0.5 * c_l, best.cost, self.share_of(held[i])):
            c_p, start = self.probe(origin(i), held[i], J, dx)
            got = self.refit(start, act)
            log.debug("diagnose: stepwise refit: dropping %d (probed %.4g): fit cost %.4g -> %.4g", i, c_p,
                      2 * best.cost, 2 * got.cost)
            if not self.passes(got.cost, best.cost, self.share_of(got.fun)):
                return act, got
        probes = [self.probe(origin(i), held[i], J, dx) + (i, k, act + [k]) for (c_l, dx), i, k, act in lin
                  if k is not None]
        c_p, start, i, k, act = min(probes, key=lambda t: t[0])
        got = self.refit(start, act)
        log.debug("diagnose: stepwise refit: swapping %d for %d (probed %.4g): fit cost %.4g -> %.4g", i, k, c_p,
                  2 * best.cost, 2 * got.cost)
        return (act, got) if got.cost < best.cost else None


def _best_scans(fun, x, lo, hi, t_grid, n, pool=None):
    """Each parameter of ``x`` (of ``pool``; None: all) scanned alone (``n`` points over 10-90 % of its
    range, the others held, the cost on the first ``t_grid`` s), lowest cost first: (its index, ``x``
    with it at its best point)."""
    out = []
    for j in (range(x.size) if pool is None else pool):
        for v in _grid_axis(lo[j], hi[j], n):
            xx = x.copy()
            xx[j] = v
            r = fun(xx, t_grid)
            out.append((float(r @ r), j, xx))
    out.sort(key=lambda t: t[0])
    picks = {}
    for _, j, xx in out:
        picks.setdefault(j, xx)
    return list(picks.items())


def _jacobian(fun, best, rest, lo, hi):
    """Forward-difference Jacobian at ``best.x`` of the parameters ``rest`` (one evaluation each, a
    secant over 10 % of the parameter's range, inwards: a stiffness 40 % off responds far from
    linearly, and a 3 % step ranked the string stiffness last after the formation's on planted
    string-and-formation runs); the other columns ``best.jac``'s (the last fit's)."""
    J = np.array(best.jac, dtype=float)
    for j in rest:
        h = secant_step(best.x, lo, hi, j, 0.1)
        xx = best.x.copy()
        xx[j] += h
        J[:, j] = (fun(xx) - best.fun) / h
    return J


def secant_step(x, lo, hi, j, share) -> float:
    """A finite-difference step of fit-vector entry ``j``: ``share`` of its search range [lo, hi], inwards
    (backwards where a step forwards would leave the box).

    Parameters
    ----------
    x : numpy.ndarray
        The fit vector the step is taken from.
    lo, hi : numpy.ndarray
        Its bounds.
    j : int
        The entry stepped.
    share : float [-]
        The step's share of the entry's range.
    """
    h = share * (hi[j] - lo[j])
    return h * (1 if x[j] + h <= hi[j] else -1)


def _lin_fit(J, r, act):
    """The linearised least-squares fit of the residual ``r`` by the Jacobian columns ``act``: its
    predicted cost (sum of squares) and the step (zero outside ``act``)."""
    dz, *_ = np.linalg.lstsq(J[:, act], -r, rcond=None)
    left = r + J[:, act] @ dz
    dx = np.zeros(J.shape[1])
    dx[act] = dz
    return float(left @ left), dx


def _refit_subset(fun, x, act, lo, hi, budget, n_jobs, step=None, smooth=False, noise=0.0):
    """The fit vector ``x`` with its entries ``act`` refitted (Nelder-Mead up to two, else, or ``smooth``,
    least squares; ``budget`` evaluations) and the rest held: a result with ``x``, ``fun``, ``jac`` (zero
    columns for the held entries), ``nfev`` and ``cost`` (half the sum of squares).  ``step``: Nelder-Mead's
    first simplex step (share of the range; None: :data:`NM_STEP`); ``noise``: its stop (:func:`nelder_mead`)."""
    act = np.asarray(act, dtype=int)

    def f(z, t_stop=None):
        xx = x.copy()
        xx[act] = z
        return fun(xx) if t_stop is None else fun(xx, t_stop)

    z0 = np.clip(x[act], lo[act] + 1e-9, hi[act] - 1e-9)
    r = nelder_mead(f, z0, lo[act], hi[act], budget, NM_STEP if step is None else step, noise) \
        if act.size <= 2 and not smooth else least_squares(f, z0, lo[act], hi[act], budget, n_jobs)
    xx = x.copy()
    xx[act] = r.x
    J = np.zeros((r.fun.size, x.size))
    J[:, act] = r.jac
    return types.SimpleNamespace(x=xx, fun=np.asarray(r.fun), jac=J, nfev=int(r.nfev), cost=float(r.cost))


def _grid_axis(lo, hi, n):
    """``n`` scan points over 10-90 % of the range [``lo``, ``hi``] of one parameter."""
    return np.linspace(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo), n)


def _scan_refine(obj, xs, **options):
    """``obj`` at the points ``xs``, then a bounded scalar search between the best point's neighbours
    (``options``: scipy's ``minimize_scalar`` options): the best point's value and position, and the
    search's result (the callers choose between the two)."""
    from scipy.optimize import minimize_scalar

    costs = [obj(x) for x in xs]
    k = int(np.argmin(costs))
    r = minimize_scalar(obj, bounds=(xs[max(k - 1, 0)], xs[min(k + 1, xs.size - 1)]), method="bounded",
                        options=options)
    return costs[k], float(xs[k]), r


def _start(cls, fun, x0, lo, hi, t_grid, grid, hint):
    """The start of a fit: the equation-error start ``hint`` (a linear least-squares fit of the component
    residual, blind to stick timing) when it costs less on the first ``t_grid`` s than the default, and
    then no grid (issue 32: start where the equations point); else, with <= 2 parameters, the best point
    of a coarse grid (stick-slip makes the cost rough) when it costs less still (the grid only picks the
    start; ``grid`` 0: no grid, a smooth law).  Returns the start and whether it is the equation-error one
    (next to the optimum)."""
    if hint is not None:
        # the component residual's fit as a start, where it fixes every parameter and its cost on the
        # grid span is lower
        x_ee = np.clip(hint, lo + 1e-9, hi - 1e-9)
        if float(np.sum(fun(x_ee, t_grid) ** 2)) < float(np.sum(fun(x0, t_grid) ** 2)):
            return x_ee, True
    k = x0.size
    if k <= 2 and grid > 0:  # grid 0: none (a smooth law, FitSpec.smooth)
        axes = [_grid_axis(lo[i], hi[i], grid if k == 1 else max(3, (grid + 3) // 2)) for i in range(k)]
        pts = np.array(np.meshgrid(*axes)).reshape(k, -1).T
        costs = [float(np.sum(fun(x, t_grid) ** 2)) for x in pts]
        c0 = float(np.sum(fun(x0, t_grid) ** 2))
        if min(costs) < c0:
            x0 = pts[int(np.argmin(costs))]
    return x0, False


@functools.cache
def _least_squares_has_workers() -> bool:
    """Whether scipy's least_squares takes ``workers`` (scipy >= 1.16; read once)."""
    import inspect

    from scipy.optimize import least_squares as ls

    return "workers" in inspect.signature(ls).parameters


def least_squares(fun, x0, lo, hi, budget, n_jobs=1):
    """Bounded least squares on the decimated fit residual (``budget`` evaluations).

    Parameters
    ----------
    fun : callable
        Residual vector of a fit vector ``x`` (weighted, decimated).
    x0 : numpy.ndarray
        Start fit vector.
    lo, hi : numpy.ndarray
        Bounds of the fit vector.
    budget : int
        Maximum number of residual evaluations.
    n_jobs : int
        Threads for the finite-difference Jacobian (scipy >= 1.16; otherwise serial).
    """
    from scipy.optimize import least_squares as ls

    opts = dict(bounds=(lo, hi), diff_step=0.03, max_nfev=budget, x_scale=1.0, xtol=1e-3, ftol=1e-4, gtol=1e-6)
    if n_jobs > 1 and _least_squares_has_workers():  # scipy >= 1.16
        # the finite-difference Jacobian's replays (one per parameter) on n_jobs threads: the same
        # points and differences as the serial one, so the same fit
        with cf.ThreadPoolExecutor(n_jobs) as ex:
            return ls(fun, x0, workers=ex.map, **opts)
    return ls(fun, x0, **opts)


def rescan(cls, fun, r, lo, hi, nominal, search=Search()):
    """Second start for the parameters whose cost is rugged (``cls.fit.rugged``, e.g. the static
    friction force: stick-slip timing makes the cost jump, so a local fit from the nominal can
    settle in a side minimum).  Each such parameter is scanned over its search box (``scan``
    points, 10-90 % of the range, the others at the fit, clipped ones as the model uses them:
    ``cls.effective``); when the best scanned point costs less
    than the fit, the fit restarts from it; the lower fit cost wins (fit part only: the held-out
    data play no part in the choice).  At most ``scan`` evaluations + one more fit per parameter.

    Parameters
    ----------
    cls : type
        The candidate's effect class (its ``fit.rugged`` parameters are rescanned).
    fun : callable
        Residual vector of a fit vector ``x``.
    r : scipy.optimize.OptimizeResult
        The least-squares fit to improve on.
    lo, hi : numpy.ndarray
        Bounds of the fit vector.
    nominal : heavecomp.params.CMCParams
        Nominal parameters (for ``cls.effective``, the clipped model).
    search : Search
        Search effort (``scan`` points per parameter, ``max_nfev`` and ``n_jobs`` of the refit).
    """
    best, nfev = r, int(r.nfev)
    names = [f.name for f in cls.fields()]
    for p in cls.fit.rugged:
        i = names.index(p)
        x = best.x
        if hasattr(cls, "effective"):  # the fitted model with its clips written in (same cost)
            x = np.clip(cls.to_x(cls.effective(nominal, cls.from_x(x))), lo, hi)
        axis = np.linspace(lo[i] + 0.1 * (hi[i] - lo[i]), hi[i] - 0.1 * (hi[i] - lo[i]), search.scan)
        pts = np.repeat(x[None, :], axis.size, axis=0)
        pts[:, i] = axis
        costs = [float(np.sum(fun(x) ** 2)) for x in pts]
        nfev += axis.size
        j = int(np.argmin(costs))
        if costs[j] >= 2 * best.cost:  # least squares' cost is half the sum of squares
            continue
        r2 = least_squares(fun, pts[j], lo, hi, search.max_nfev, search.n_jobs)
        nfev += int(r2.nfev)
        log.debug("diagnose: %s rescan of %s: fit cost %.4g -> %.4g", cls.name, p, 2 * best.cost, 2 * r2.cost)
        if r2.cost < best.cost:
            best = r2
    best.nfev = nfev
    return best


def nelder_mead(fun, x0, lo, hi, budget, step=None, noise=0.0):
    """Derivative-free refinement (Nelder-Mead on the clipped parameters; stick-slip costs are
    piecewise smooth, so finite-difference gradients mislead), then a forward-difference
    Jacobian at the optimum for the uncertainty.  Returns an object like least_squares'.

    Parameters
    ----------
    fun : callable
        Residual vector of a fit vector ``x``.
    x0 : numpy.ndarray
        Start fit vector.
    lo, hi : numpy.ndarray
        Bounds of the fit vector (the parameters are clipped to them).
    budget : int
        Maximum number of cost evaluations of the simplex search.
    step : float, optional
        First simplex step as a share of each parameter's range (None: :data:`NM_STEP`, a start from a
        grid or the defaults; ``VerdictPolicy.start_step`` from a start next to the optimum).
    noise : float [-]
        ``VerdictPolicy.search_resolution`` times the output noise's expected fit cost (:func:`noise_cost`):
        the search stops once its simplex has contracted under half its first step and its vertices' costs
        differ by less than the noise's resolution of the cost (:func:`cost_resolution` at the start's
        residual): the noise can no longer tell its steps apart.  0: the absolute stop (costs within 1e-4,
        vertices within 1e-3 of the fit vector).  Never tighter than the absolute stop.
    """
    from scipy.optimize import minimize

    def cost(x):
        r = fun(np.clip(x, lo, hi))
        return float(r @ r)

    step = (NM_STEP if step is None else step) * (hi - lo)
    simplex = np.vstack([x0] + [x0 + np.where(np.arange(x0.size) == i, np.where(x0 + step <= hi, step, -step), 0.0)
                                for i in range(x0.size)])
    xatol, fatol = 1e-3, 1e-4
    if noise > 0:
        xatol = max(xatol, 0.5 * float(np.min(step)))
        fatol = max(fatol, cost_resolution(noise, fun(np.clip(x0, lo, hi))))
    res = minimize(cost, x0, method="Nelder-Mead",
                   options={"initial_simplex": simplex, "maxfev": budget, "xatol": xatol, "fatol": fatol})
    x = np.clip(res.x, lo, hi)
    f0 = fun(x)
    J = np.empty((f0.size, x.size))
    for i in range(x.size):
        dx = secant_step(x, lo, hi, i, 0.02)
        xi = x.copy()
        xi[i] += dx
        J[:, i] = (fun(xi) - f0) / dx
    return types.SimpleNamespace(x=x, fun=f0, jac=J, nfev=int(res.nfev) + x.size + 1, cost=0.5 * float(f0 @ f0))


def sigma(cls, r) -> dict:
    """1-sigma of the fitted parameters from the Jacobian, inflated for correlated residuals.

    Parameters
    ----------
    cls : type
        The candidate's effect class (its ``fit.log`` parameters are fitted in log).
    r : scipy.optimize.OptimizeResult or types.SimpleNamespace
        A fit with ``x``, residual ``fun`` and Jacobian ``jac``.
    """
    J = r.jac
    m, k = J.shape
    res = r.fun
    s2 = float(res @ res) / max(m - k, 1)
    rho = float(np.corrcoef(res[:-1], res[1:])[0, 1]) if m > 3 and np.std(res) > 0 else 0.0
    rho = min(max(rho, 0.0), 0.99)
    infl = (1 + rho) / (1 - rho)
    try:
        cov = np.linalg.pinv(J.T @ J) * s2 * infl
        sx = np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        sx = np.full(k, math.nan)
    vals = cls.from_x(r.x)
    return {f.name: float(abs(vals[f.name]) * s if f.name in cls.fit.log else s) for f, s in zip(cls.fields(), sx)}


# ------------------------------------------------------------------ channel readings
def fit_delay_output(ctx, cls, fixed=(), channel=None) -> Fit:
    """A channel effect with one nonlinear parameter (sensor_delay): per channel, a scan of the
    parameter over its bounds (``delay_scan`` points of the policy) refined by a bounded scalar search,
    the channel reading made by the effect's own ``apply`` from the replay's grid (no re-simulation);
    the channel whose fit leaves the smallest weighted residual wins.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    cls : type
        The candidate's effect class (one parameter, e.g. sensor_delay's delay [s]).
    fixed : sequence of (str, dict)
        Configurations ``(effect name, values)`` already fitted and held in the model.
    channel : str, optional
        The channel fitted (None: every channel the run has, the best wins).
    """
    (field,) = cls.fields()
    a, b = field.metadata["bounds"]
    base = ctx.simulate(list(fixed), ctx.split["fit"][1])
    grid = base["_grid"]
    best = None
    n_scan = ctx.policy.delay_scan
    for c in ctx.channels if channel is None else (channel,):
        def obj(x, c=c):
            pred = dict(base)
            pred[c] = cls.apply(base["t"], grid[:, 0], grid[:, SC.index(c)], x)
            r = ctx.resid_vec(pred)
            return float(r @ r)
        _, _, r = _scan_refine(obj, np.linspace(a, b, n_scan), xatol=1e-4)
        if best is None or r.fun < best[0]:
            best = (r.fun, c, float(r.x))
    return Fit({"channel": best[1], field.name: best[2]}, {field.name: math.nan}, n_scan * len(ctx.channels), best[0])


def fit_linear_output(ctx, cls, fixed=(), channel=None) -> Fit:
    """A channel effect whose reading is affine in its parameters (``linear``: sensor_gain,
    sensor_offset): per channel, linear least squares of the measured channel on the columns
    the effect's own ``apply`` makes of the replay (no re-simulation, :func:`_fit_channel`); the
    channel whose fit leaves the smallest weighted residual wins.  Parameters are clipped to their
    bounds.  The effect's ``optional`` parameters (a drift) are fitted only when they shrink the
    channel's fit residual by at least :data:`heavecomp.diagnosis.equation_error.MIN_SHRINK`;
    ``n_params`` counts the parameters used.  On stroke and WOB, which also set the replay's start
    (:meth:`~heavecomp.diagnosis.replay.Replay.start_for`), the fit is refined through the replay
    (:func:`_refine_reading`) where it can contend (``VerdictPolicy.reading_contention``); ``refinement``
    says per channel what the refinement predicted and whether it ran.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run (:func:`heavecomp.diagnosis.replay.prepare`).
    cls : type
        The candidate's effect class (affine reading, e.g. sensor_gain, sensor_offset).
    fixed : sequence of (str, dict)
        Configurations ``(effect name, values)`` already fitted and held in the model.
    channel : str, optional
        The channel fitted (None: every channel the run has, the best wins).
    """
    t_end = ctx.split["fit"][1]
    base0 = ctx.simulate(list(fixed), t_end)
    names = [f.name for f in cls.fields()]
    used = np.array([n not in cls.fit.optional for n in names])
    r0 = ctx.resid_vec(base0)
    bar = contention_bar(ctx, float(r0 @ r0))
    best, refinement = None, {}
    for c in ctx.channels if channel is None else (channel,):
        got = _fit_channel(ctx, cls, base0, c, used)
        if c in ("stroke", "wob"):  # they also set the replay's start: Gauss-Newton on every channel
            got, refinement[c] = _refine_reading(ctx, cls, fixed, t_end, c, got, used, bar)
        if best is None or got[0] < best[0]:
            best = got
    cost, c, coef, sig, k_used = best
    values = {"channel": c, **{n: float(v) for n, v in zip(names, coef)}}
    return Fit(values, {n: float(s) for n, s in zip(names, sig)}, 1, cost, n_params=k_used,
               refinement=refinement or None)


def contention_bar(ctx, cost_fixed) -> float:
    """The fit cost [-] a reading must be predicted to reach for its refinement through the replay to run
    (:func:`_refine_reading`): the cost of the model it is added to, ``cost_fixed`` (the nominal, or a joint
    fit's partner), less ``VerdictPolicy.reading_contention`` of that model's gap above the output noise's
    cost (:func:`noise_cost`); inf (always refine) where that model is within the noise or the share is 0.

    Parameters
    ----------
    ctx : heavecomp.diagnosis.replay.ReplayContext
        The prepared run.
    cost_fixed : float [-]
        The fit cost of the model the reading is added to.
    """
    gap, share = cost_fixed - noise_cost(ctx), ctx.policy.reading_contention
    return float(cost_fixed - share * gap) if gap > 0 and share > 0 else math.inf


def _fit_channel(ctx, cls, base, c, used):
    """Linear least squares of channel ``c``'s reading on the replay ``base``: (weighted residual of
    all channels, channel, coefficients, their 1-sigma, parameters used)."""
    names = [f.name for f in cls.fields()]
    lo, hi = cls.bounds_x()  # a reading is affine in its parameters: none is fitted in log
    t = base["t"]
    m = ctx.fitmask[: t.size]
    y = ctx.y[c][: t.size]
    ok = m & np.isfinite(y)
    zero = np.zeros(len(names))
    a0 = cls.apply(t, t, base[c], *zero)
    X = np.column_stack([cls.apply(t, t, base[c], *np.eye(len(names))[i]) - a0 for i in range(len(names))])
    Xo, yo = X[ok], (y - a0)[ok]

    def lsq(cols):
        coef = np.zeros(len(names))
        coef[cols], *_ = np.linalg.lstsq(Xo[:, cols], yo, rcond=None)
        coef = np.clip(coef, lo, hi)
        return coef, yo - Xo @ coef

    coef, r = lsq(used)
    if not used.all():  # the optional parameters only when they shrink the fit residual >= MIN_SHRINK
        coef_f, r_f = lsq(np.ones(len(names), bool))
        if 1.0 - math.sqrt(float(r_f @ r_f) / max(float(r @ r), 1e-300)) >= EE.MIN_SHRINK:
            coef, r = coef_f, r_f
    k_used = int(np.count_nonzero(used | (coef != 0.0)))
    pred = dict(base)
    pred[c] = a0 + X @ coef
    rv = ctx.resid_vec(pred)
    dof = max(int(ok.sum()) - k_used, 1)
    try:
        cov = np.linalg.pinv(Xo.T @ Xo) * float(r @ r) / dof
        sig = np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        sig = np.full(len(names), math.nan)
    return float(rv @ rv), c, coef, sig, k_used


def _refine_reading(ctx, cls, fixed, t_end, c, got, used, bar=math.inf):
    """A stroke or WOB reading also sets the replay's start and heave reference
    (:meth:`~heavecomp.diagnosis.replay.Replay.start_for`), so a misreading there shows in every channel
    (a stroke read 3 cm off: the pressure and WOB of the gas law and the string), not in the channel
    itself, which the start follows.  From the channel's linear fit ``got``, ``start_iterations``
    Gauss-Newton steps on the weighted fit residual of all channels (finite differences through the
    replay; the parameters used by the linear fit only), ending after a step that changed the cost by less
    than the noise resolves (:func:`cost_resolution`); the better of the two is kept.  The first step's
    linearised cost (its Jacobian's prediction, no replay) is the refinement's prediction: where neither it
    nor the linear fit reaches ``bar`` (:func:`contention_bar`) the reading cannot contend and the
    refinement stops there.  Returns the fit and its evidence (``predicted_cost``, ``bar_cost``,
    ``refined``)."""
    names = [f.name for f in cls.fields()]
    lo, hi = cls.bounds_x()
    idx = np.flatnonzero(used | (got[2] != 0.0))
    scale = float(np.nanstd(ctx.y[c][ctx.fitmask])) or 1.0

    def resid(coef):
        vals = {"channel": c, **{n: float(v) for n, v in zip(names, coef)}}
        return ctx.resid_vec(ctx.simulate(list(fixed) + [(cls.name, vals)], t_end))

    coef = np.array(got[2], dtype=float)
    r = resid(coef)
    best = (float(r @ r), coef.copy())
    # a step that changes the cost by less than the noise resolves is the last (VerdictPolicy.search_resolution)
    tol = cost_resolution(ctx.policy.search_resolution * noise_cost(ctx), r)
    evidence = {"predicted_cost": None, "bar_cost": None if math.isinf(bar) else float(bar), "refined": True}
    for it in range(ctx.policy.start_iterations):
        J = np.empty((r.size, idx.size))
        for j, i in enumerate(idx):
            step = 1e-3 * (scale if abs(coef[i]) < 1e-12 or names[i] == "offset" else abs(coef[i]))
            x = coef.copy()
            x[i] += step
            J[:, j] = (resid(x) - r) / step
        dx = np.clip(coef[idx] - np.linalg.lstsq(J, r, rcond=None)[0], lo[idx], hi[idx]) - coef[idx]
        if it == 0:  # the step's linearised cost: what the refinement is predicted to reach
            r_lin = r + J @ dx
            evidence["predicted_cost"] = float(r_lin @ r_lin)
            if min(evidence["predicted_cost"], got[0]) > bar:  # out of contention (reading_contention)
                evidence["refined"] = False
                break
        coef[idx] += dx
        c_before = float(r @ r)
        r = resid(coef)
        if float(r @ r) < best[0]:
            best = (float(r @ r), coef.copy())
        if abs(c_before - float(r @ r)) < tol:
            break
    if best[0] >= got[0]:
        return got, evidence
    return (best[0], c, best[1], got[3], got[4]), evidence
