"""Where the friction residual of a measured plant lives, and which effect shrinks it.

One candidate abstraction for every plant (issue 11 item 5): the candidates are the effect
library's classes (:mod:`heavecomp.effects`), the same the CMC's gap diagnosis fits, through their
equation-error :meth:`~heavecomp.effects.base.Effect.features`; the plants are adapters
(:mod:`heavecomp.identification.plants`: the EMPS axis, the O-ring seal rig) and the fits are the
plant-independent engine's (:mod:`heavecomp.diagnosis.equation_error`).

The nominal model's linear parameters (the base columns) are refitted on the first part of the
record; the residual on the held-out rest is localised (by velocity, direction, position,
acceleration vs deceleration) and each candidate's columns are added in turn, fitted on the fit
part only (linear coefficients by least squares, its one shape parameter, the effect's
``feature_grid``, chosen by the fit-part BIC) and scored on the held-out part:

    shrink = 1 - rms_after / rms_before                      (held-out)
    score  = n_v ln(RSS_after / RSS_before) + k ln(n_v)        (BIC-like, held-out)

with ``n_v`` held-out samples and ``k`` extra parameters (linear + shape); a
negative score means the candidate earns its parameters.  A greedy forward
selection then adds candidates while the engine's BIC **of the fit part** (with the
effective sample size of the autocorrelated residual) keeps falling, so that the held-out
part is used only to report each step's shrink, never to choose.  The open search
(:func:`~heavecomp.diagnosis.equation_error.open_search`) reports its best sparse term as
``discovered``.

Naming (contract ``diagnosis-contract.md``): a term of the nominal friction law that the nominal
lacks or gets wrong comes back as ``parameter_mismatch`` with the term's parameter-file key and
its value moved from the nominal (e.g. ``friction.coulomb_force`` 0 -> 23 N); a missing physical
effect comes back under its effect name (``asymmetric_friction``, ``pressure_friction``, ...).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.effects.candidates import CANDIDATES, family_of, get, law_of
from heavecomp.errors import ParameterError
from heavecomp.diagnosis.equation_error import fit_columns, open_search
from heavecomp.estimator import GapEstimator
from heavecomp.identification.inverse import AxisRegression, least_squares
from heavecomp.identification.plants import AxisFriction

log = logging.getLogger(__name__)


def get_candidates(names=None) -> list[type]:
    """Candidate effects (:class:`heavecomp.effects.base.Effect` classes) by contract name or as
    classes; None = every candidate of the library (:data:`heavecomp.effects.candidates.CANDIDATES`).
    An unknown name raises with the list of known ones.  :class:`ResidualDiagnoser` fits those of the
    friction component (and ``parameter_mismatch``, the nominal law's own terms); a candidate without
    an equation-error form on a plant (``features`` returns None) is skipped there.

    Parameters
    ----------
    names : sequence of str or Effect classes, optional
        Candidate contract names or classes; ``None`` for every candidate of the library.
    """
    if names is None:
        return list(CANDIDATES.values())
    return [n if isinstance(n, type) and issubclass(n, Effect) else get(n) for n in names]


def _bin_stats(r, sel, total):
    n = int(np.count_nonzero(sel))
    if n == 0:
        return {"n": 0, "mean": None, "rms": None, "share": 0.0}
    rr = r[sel]
    return {"n": n, "mean": float(rr.mean()), "rms": float(np.sqrt(np.mean(rr * rr))),
            "share": float(np.sum(rr * rr) / total)}


def localise(r, v, q, a, dead_band: float = 0.005, n_velocity: int = 10, n_position: int = 8) -> dict:
    """Where the squared residual lives.

    Parameters
    ----------
    r : array, N
        Residual (measured - model force).
    v, q, a : array
        Velocity [m/s], position [m], acceleration [m/s^2] at the same samples.
    dead_band : float, m/s
        |v| below this counts as near rest.
    n_velocity : int
        Number of equal velocity bins over [-max |v|, max |v|].
    n_position : int
        Number of equal position bins over the range of ``q``.

    Returns
    -------
    dict
        ``direction`` (positive / negative / near_rest), ``motion`` (accelerating:
        v a > 0, decelerating: v a < 0, while moving), ``acceleration`` (sign of a),
        ``velocity`` and ``position`` bins; each entry has ``n``, ``mean`` [N], ``rms`` [N] and ``share`` of the
        total squared residual.  Also ``rms`` (total) [N].
    """
    r, v, q, a = (np.asarray(x, dtype=float) for x in (r, v, q, a))
    total = float(np.sum(r * r))
    moving = np.abs(v) > dead_band
    out = {"rms": float(np.sqrt(total / r.size)), "dead_band": dead_band}
    out["direction"] = {"positive": _bin_stats(r, v > dead_band, total),
                        "negative": _bin_stats(r, v < -dead_band, total),
                        "near_rest": _bin_stats(r, ~moving, total)}
    out["motion"] = {"accelerating": _bin_stats(r, moving & (v * a > 0), total),
                     "decelerating": _bin_stats(r, moving & (v * a < 0), total)}
    out["acceleration"] = {"positive": _bin_stats(r, a > 0, total), "negative": _bin_stats(r, a < 0, total)}
    vmax = float(np.max(np.abs(v)))
    edges = np.linspace(-vmax, vmax, n_velocity + 1)
    idx = np.clip(np.searchsorted(edges, v, side="right") - 1, 0, n_velocity - 1)
    out["velocity"] = [{"lo": float(edges[i]), "hi": float(edges[i + 1]), **_bin_stats(r, idx == i, total)}
                       for i in range(n_velocity)]
    qe = np.linspace(q.min(), q.max(), n_position + 1)
    idx = np.clip(np.searchsorted(qe, q, side="right") - 1, 0, n_position - 1)
    out["position"] = [{"lo": float(qe[i]), "hi": float(qe[i + 1]), **_bin_stats(r, idx == i, total)}
                       for i in range(n_position)]
    return out


def _by_effect(coefficients: dict) -> dict:
    """``{"effect:column": value}`` -> ``{effect: {column: value}}``."""
    out: dict = {}
    for key, value in coefficients.items():
        effect, column = key.split(":", 1)
        out.setdefault(effect, {})[column] = value
    return out


def _shape_label(effect) -> tuple:
    """(name, unit) of an effect's equation-error shape parameter."""
    return getattr(effect, "feature_shape", ("shape", ""))


class ResidualDiagnoser(GapEstimator):
    """Localise the held-out friction residual of a plant's nominal model and rank candidate effects.

    The plant is the EMPS axis (:class:`~heavecomp.identification.plants.AxisFriction`; an
    :class:`~heavecomp.identification.inverse.AxisRegression` is wrapped with the published nominal)
    or the O-ring seal rig (:class:`~heavecomp.identification.plants.SealFriction`); the candidates
    are the library's Effect classes, whose ``features`` give the columns (one candidate abstraction
    for every plant).

    Parameters
    ----------
    candidates : list of str or Effect classes, or None
        Contract names (:data:`heavecomp.effects.candidates.CANDIDATES`); None = all (those without
        an equation-error form on the plant are skipped).
    fit_window, validate_window : (float, float), s
        Time windows of the fit and held-out parts (regression samples with ``t0 <= t < t1``).
    dead_band : float, m/s
        |v| below this counts as near rest in the localisation.
    forward_selection : bool
        Also add candidates greedily while the fit-part BIC falls.

    Attributes
    ----------
    plant_ : AxisFriction or SealFriction
        The plant fitted.
    baseline_ : dict
        Base parameters (nominal + refit on the fit part), rms on fit and held-out parts [N].
    where_ : dict
        :func:`localise` of the held-out residual of the base model.
    results_ : list of dict
        Every candidate, best score first: ``effect``, ``component``, ``parameters`` (the
        coefficients of its feature columns, its shape parameter), ``changes`` (for
        ``parameter_mismatch``: term -> [nominal, fitted]), ``rms_before``, ``rms_after`` [N],
        ``shrink``, ``score``.
    best_ : dict or None
        The best candidate if it earns its parameters (score < 0), else None.
    selection_ : list of dict
        Forward-selection steps (chosen by the fit-part BIC ``bic_fit``): ``effects`` so far,
        held-out ``rms_after``, ``shrink`` and ``score``.
    where_after_ : dict
        :func:`localise` of the held-out residual after the forward selection.
    discovered_ : dict or None
        The open search's best sparse term on the friction residual
        (:func:`heavecomp.diagnosis.equation_error.open_search`), a suggestion, never a name.
    verdict_ : dict
        ``effect`` (the best candidate's name, or ``"none"`` when none earns its parameters),
        ``component``, held-out ``shrink``, fitted ``parameters``, ``changes`` (a nominal term
        moved by ``parameter_mismatch``: [nominal, fitted]) and ``discovered``.
    """

    def __init__(self, candidates=None, fit_window=(0.0, 15.0), validate_window=(15.0, math.inf),
                 dead_band: float = 0.005, forward_selection: bool = True):
        self.candidates = get_candidates(candidates)
        self.fit_window, self.validate_window = tuple(fit_window), tuple(validate_window)
        self.dead_band, self.forward_selection = dead_band, forward_selection

    # -- helpers --------------------------------------------------------------
    def _solve(self, extra_cols):
        """Residual on the held-out part after a least-squares fit on the fit part (for the figures)."""
        pl, mf, mv = self.plant_, self.mf_, self.mv_
        X = pl.base
        if extra_cols:
            X = np.column_stack([X] + list(extra_cols))
        res = least_squares(X[mf], pl.y[mf])
        rv = pl.y[mv] - X[mv] @ res.theta
        return res, rv

    def _columns(self, effect, shape):
        """The effect's columns on the plant, without those the base already holds (same name or,
        on the fit part, in the span of the base columns); None when it has no equation-error form."""
        cols = self.plant_.features(effect, shape)
        if cols is None:
            return None
        out = {}
        B = self.plant_.base[self.mf_]
        for k, c in cols.items():
            if k in self.plant_.base_names:
                continue
            cf = c[self.mf_]
            r = cf - B @ np.linalg.lstsq(B, cf, rcond=None)[0]
            if np.linalg.norm(r) > 1e-9 * max(np.linalg.norm(cf), 1e-300):
                out[k] = c
        return out

    def _fit(self, cols: dict) -> dict:
        """The engine's fit (:func:`heavecomp.diagnosis.equation_error.fit_columns`) on this plant."""
        return fit_columns(self.plant_.y, cols, self.mf_, self.mv_, base=self.base_)

    def _fit_candidate(self, effect):
        """Best shape value by the fit-part BIC: (shape, columns, engine result) or None."""
        best = None
        for shape in (effect.feature_grid or (None,)):
            cols = self._columns(effect, shape)
            if not cols:    # no form on this plant, or nothing beyond the base at this shape
                continue
            res = self._fit(cols)
            if best is None or res["bic"] < best[2]["bic"]:
                best = (shape, cols, res)
        return best

    def _score(self, res, k_extra):
        """Held-out BIC-like score and rms of an engine result."""
        n = int(self.mv_.sum())
        return 2 * n * math.log(res["rms_after"] / res["rms_before"]) + k_extra * math.log(n), res["rms_after"]

    # -- estimator ------------------------------------------------------------
    def fit(self, plant) -> "ResidualDiagnoser":
        """Diagnose ``plant`` (an ``AxisFriction`` / ``SealFriction``, or an ``AxisRegression``
        diagnosed against the published EMPS model)."""
        if isinstance(plant, AxisRegression):
            plant = AxisFriction(plant, dead_band=self.dead_band)
        self.plant_ = pl = plant
        self.reg_ = getattr(plant, "reg", None)     # the axis' filtered record (figures)
        self.mf_, self.mv_ = pl.mask(self.fit_window), pl.mask(self.validate_window)
        if self.mf_.sum() < 50 or self.mv_.sum() < 50:
            raise ParameterError(f"fit window {self.fit_window} and validate window "
                                 f"{self.validate_window} need at least 50 samples each")
        self.base_ = dict(zip(pl.base_names, pl.base.T))
        res0, rv0 = self._solve([])
        self.rss0_ = float(rv0 @ rv0)
        rms0 = math.sqrt(self.rss0_ / rv0.size)
        self.baseline_ = {"parameters": {k: pl.nominal[k] + float(d) for k, d in zip(pl.base_names, res0.theta)},
                          "stderr": dict(zip(pl.base_names, map(float, res0.stderr))),
                          "nominal": dict(pl.nominal), "withheld": list(getattr(pl, "withheld", ())),
                          "rms_fit": res0.rms, "rms_validate": rms0}
        mv = self.mv_
        self.residual_before_ = rv0
        self.where_ = localise(rv0, pl.v_s[mv], pl.x_s[mv], pl.a_s[mv], self.dead_band)

        results = []
        self._chosen = {}
        for eff in self.candidates:
            if eff.component() not in ("friction", ""):     # "": parameter_mismatch (the nominal law)
                continue
            got = self._fit_candidate(eff)
            if got is None:
                log.debug("candidate %s: no equation-error form on %s", eff.name, pl.name)
                continue
            shape, cols, res = got
            k = len(cols) + (len(shape) if isinstance(shape, tuple) else 1 if eff.feature_grid else 0)
            score, rms = self._score(res, k)
            coef = res["coefficients"]
            params = dict(coef)
            if eff.feature_grid:
                sname, sunit = _shape_label(eff)
                params[sname] = [float(s) for s in shape] if isinstance(shape, tuple) else float(shape)
                if shape in (eff.feature_grid[0], eff.feature_grid[-1]):
                    log.info("candidate %s: shape %s at the edge of its grid (%s %s)", eff.name, sname, shape, sunit)
            params.update({f"base_{n}": pl.nominal[n] + v for n, v in res["base"].items()})
            # a nominal parameter moved (a term the nominal lacks has nominal value 0)
            changes = ({n: [pl.nominal.get(n, 0.0), pl.nominal.get(n, 0.0) + c] for n, c in coef.items()}
                       if eff.kind == "nominal" else {})
            self._chosen[eff.name] = (cols, k)
            units = {**pl.units, **getattr(eff, "feature_units", {})}
            results.append({"effect": eff.name, "component": eff.component() or "friction",
                            "units": {k: units.get(k, "?") for k in params if not k.startswith("base_")},
                            "description": (eff.__doc__ or "").strip().splitlines()[0],
                            "parameters": params, "changes": changes, "n_parameters": k,
                            "rms_before": rms0, "rms_after": rms, "shrink": 1.0 - rms / rms0,
                            "score": score, "bic_fit": res["delta_bic"]})
        self.results_ = sorted(results, key=lambda d: d["score"])
        self.best_ = self.results_[0] if self.results_ and self.results_[0]["score"] < 0 else None

        # forward selection by the engine's fit-part BIC (effective sample size of the residual)
        self.selection_ = []
        chosen, cols, k_tot, current = [], {}, 0, 0.0
        while self.forward_selection:
            step = None
            for name, (c_cols, k) in self._chosen.items():
                if name in chosen:
                    continue
                res = self._fit({**cols, **{f"{name}:{c}": x for c, x in c_cols.items()}})
                if step is None or res["delta_bic"] < step[1]["delta_bic"]:
                    step = (name, res, c_cols, k)
            if step is None or step[1]["delta_bic"] >= current:
                break
            name, res, c_cols, k = step
            current = res["delta_bic"]
            chosen.append(name)
            cols.update({f"{name}:{c}": x for c, x in c_cols.items()})
            k_tot += k
            score, rms = self._score(res, k_tot)
            self.selection_.append({"effects": list(chosen), "bic_fit": current, "rms_after": rms,
                                    "shrink": 1.0 - rms / rms0, "score": score,
                                    "coefficients": _by_effect(res["coefficients"])})
        rv_sel = self._solve(list(cols.values()))[1] if cols else rv0
        sig_s = {**pl.sig_s, "still": np.abs(pl.v_s) <= self.dead_band}
        self.discovered_ = open_search(pl.y, sig_s, self.mf_, self.mv_, base=self.base_, component="friction")
        self.residual_after_ = rv_sel
        self.where_after_ = localise(rv_sel, pl.v_s[mv], pl.x_s[mv], pl.a_s[mv], self.dead_band)
        best = self.best_
        self.verdict_ = {"effect": best["effect"] if best else "none",
                         "component": best["component"] if best else None,
                         "shrink": best["shrink"] if best else 0.0,
                         "parameters": {k: v for k, v in best["parameters"].items() if not k.startswith("base_")}
                         if best else {},
                         "changes": best["changes"] if best else {},
                         "units": best["units"] if best else {},
                         "discovered": self.discovered_}
        if best and law_of(best["effect"]):  # a law of a family: the contract's name, its law and the member fitted
            self.verdict_.update(effect=family_of(best["effect"]), law=law_of(best["effect"]), member=best["effect"])
        log.info("residual diagnosis (%s): best single %s (shrink %.3f); forward selection %s", pl.name,
                 self.results_[0]["effect"] if self.results_ else "none",
                 self.results_[0]["shrink"] if self.results_ else 0.0,
                 self.selection_[-1]["effects"] if self.selection_ else "none")
        return self
