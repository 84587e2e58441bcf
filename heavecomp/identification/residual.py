"""Where the residual of the EMPS inverse model lives, and which effect shrinks it.

The base model (EMPS eq., :mod:`heavecomp.plants.axis`) is fitted on the first
part of the record; its residual on the held-out rest is localised (by velocity,
direction, position, acceleration vs deceleration) and each candidate term of
:mod:`heavecomp.identification.terms` is added in turn, fitted on the fit part
only (linear coefficients by least squares, its one shape parameter by a grid
search on the fit part) and scored on the held-out part:

    shrink = 1 - rms_after / rms_before                      (held-out)
    score  = n_v ln(RSS_after / RSS_before) + k ln(n_v)        (BIC-like, held-out)

with ``n_v`` held-out samples and ``k`` extra parameters (linear + shape); a
negative score means the candidate earns its parameters.  A greedy forward
selection then adds candidates while the BIC **of the fit part**
(n_f ln(RSS_f/RSS_f0) + k ln n_f) keeps falling, so that the held-out part is
used only to report each step's shrink, never to choose.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.estimator import GapEstimator
from heavecomp.identification import terms as T
from heavecomp.identification.inverse import AxisRegression, least_squares
from heavecomp.plants.axis import BASE_NAMES

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Candidate:
    """A candidate term: full-rate regressor columns for one shape parameter value.

    ``columns(reg, shape)`` returns a list of full-rate arrays; ``grid`` holds the
    shape values searched on the fit part (empty = no shape parameter).
    """

    name: str
    description: str
    coefficients: tuple
    columns: Callable
    grid: tuple = ()
    shape_name: str = ""
    shape_unit: str = ""


def _span(reg):
    q = reg.q
    return float(q.min()), float(q.max() - q.min())


def _fourier(reg, with_sign, harmonics=3):
    q0, length = _span(reg)
    s = np.sign(reg.dq) if with_sign else 1.0
    cols = []
    for k in range(1, harmonics + 1):
        cols.append(s * T.fourier_position(reg.q, q0, length, k, 0.0))
        cols.append(s * T.fourier_position(reg.q, q0, length, k, -0.5 * np.pi))
    return cols


def _fourier_names(prefix, harmonics=3):
    return tuple(f"{prefix}_{cs}{k}" for k in range(1, harmonics + 1) for cs in ("cos", "sin"))


CANDIDATES: dict[str, Candidate] = {c.name: c for c in (
    Candidate("asymmetric_viscous", "viscous coefficient differs by direction: + dF_v max(v, 0)",
              ("viscous_asymmetry",), lambda reg, _: [T.positive_velocity(reg.dq)]),
    Candidate("stribeck", "Stribeck excess: + (F_S - F_C) exp(-|v|/v_S) sign(v)",
              ("stribeck_excess",), lambda reg, vs: [T.stribeck_excess(reg.dq, vs)],
              tuple(np.geomspace(1e-3, 0.1, 13)), "stribeck_velocity", "m/s"),
    Candidate("position_friction", "Coulomb force varies along the stroke: sign(v) x 3 Fourier harmonics in q",
              _fourier_names("fc"), lambda reg, _: _fourier(reg, True)),
    Candidate("position_force", "a force that depends on position only (cable, cogging): 3 Fourier harmonics in q",
              _fourier_names("f"), lambda reg, _: _fourier(reg, False)),
    Candidate("friction_lag", "Dahl pre-sliding lag: friction F_c z, dz/dt = (v - |v| z)/delta, "
              "added as + F_lag (z - sign v)", ("lag_force",),
              lambda reg, d: [T.run_state(T.dahl_step, reg.dq, 1.0 / reg.fs, d) - np.sign(reg.dq)],
              tuple(np.geomspace(2e-5, 5e-3, 12)), "presliding_length", "m"),
    Candidate("friction_lag_time", "Coulomb friction follows sign(v) through a first-order lag tau: "
              "+ F_lag (lag_tau[sign v] - sign v)", ("lag_force",),
              lambda reg, tau: [T.run_state(T.lag_step, np.sign(reg.dq), 1.0 / reg.fs, tau) - np.sign(reg.dq)],
              tuple(np.geomspace(1e-3, 0.2, 12)), "lag_time", "s"),
)}


def get_candidates(names=None) -> list[Candidate]:
    """Candidates by name or as :class:`Candidate` objects (None = all); an unknown name raises
    with the list of known ones."""
    if names is None:
        return list(CANDIDATES.values())
    out = []
    for n in names:
        if isinstance(n, Candidate):
            out.append(n)
            continue
        if n not in CANDIDATES:
            raise ParameterError(f"unknown candidate '{n}'{did_you_mean(n, CANDIDATES)}; "
                                 f"known: {', '.join(CANDIDATES)}")
        out.append(CANDIDATES[n])
    return out


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


@dataclass
class _Design:
    columns: list = field(default_factory=list)
    names: list = field(default_factory=list)
    k_extra: int = 0


class ResidualDiagnoser(GapEstimator):
    """Localise the held-out residual of the EMPS model and rank candidate effects.

    Parameters
    ----------
    candidates : list of str or None
        Candidate names (see :data:`CANDIDATES`); None = all.
    fit_window, validate_window : (float, float), s
        Time windows of the fit and held-out parts (decimated samples with
        ``t0 <= t < t1``).
    dead_band : float, m/s
        |v| below this counts as near rest in the localisation.
    forward_selection : bool
        Also add candidates greedily while the fit-part BIC falls.

    Attributes
    ----------
    baseline_ : dict
        Base parameters fitted on the fit part, rms on fit and held-out parts [N].
    where_ : dict
        :func:`localise` of the held-out residual of the base model.
    results_ : list of dict
        Every candidate, best score first: ``effect``, ``parameters`` (coefficients
        [N, N s/m] and shape), ``rms_before``, ``rms_after`` [N], ``shrink``, ``score``.
    best_ : dict or None
        The best candidate if it earns its parameters (score < 0), else None.
    selection_ : list of dict
        Forward-selection steps (chosen by the fit-part BIC ``bic_fit``): ``effects`` so far,
        held-out ``rms_after``, ``shrink`` and ``score``.
    where_after_ : dict
        :func:`localise` of the held-out residual after the forward selection.
    """

    def __init__(self, candidates=None, fit_window=(0.0, 15.0), validate_window=(15.0, math.inf),
                 dead_band: float = 0.005, forward_selection: bool = True):
        self.candidates = get_candidates(candidates)
        self.fit_window, self.validate_window = tuple(fit_window), tuple(validate_window)
        self.dead_band, self.forward_selection = dead_band, forward_selection

    # -- helpers --------------------------------------------------------------
    def _solve(self, extra_cols):
        reg, mf, mv = self.reg_, self.mf_, self.mv_
        X = reg.base_matrix()
        if extra_cols:
            X = np.column_stack([X, reg.matrix(extra_cols)])
        res = least_squares(X[mf], reg.force_d[mf])
        rv = reg.force_d[mv] - X[mv] @ res.theta
        return res, rv

    def _fit_candidate(self, cand: Candidate, base_cols=()):
        """Best shape value on the fit part; returns (shape, columns, LSResult, held-out residual)."""
        best = None
        for shape in (cand.grid or (None,)):
            cols = list(base_cols) + cand.columns(self.reg_, shape)
            res, rv = self._solve(cols)
            if best is None or res.rss < best[2].rss:
                best = (shape, cols, res, rv)
        return best

    def _score(self, rv, k_extra):
        n = rv.size
        rss = float(rv @ rv)
        return n * math.log(rss / self.rss0_) + k_extra * math.log(n), math.sqrt(rss / n)

    # -- estimator ------------------------------------------------------------
    def fit(self, reg: AxisRegression) -> "ResidualDiagnoser":
        self.reg_ = reg
        self.mf_, self.mv_ = reg.mask(self.fit_window), reg.mask(self.validate_window)
        if self.mf_.sum() < 50 or self.mv_.sum() < 50:
            raise ParameterError(f"fit window {self.fit_window} and validate window "
                                 f"{self.validate_window} need at least 50 samples each")
        res0, rv0 = self._solve([])
        self.rss0_ = float(rv0 @ rv0)
        rms0 = math.sqrt(self.rss0_ / rv0.size)
        self.baseline_ = {"parameters": dict(zip(BASE_NAMES, map(float, res0.theta))),
                          "stderr": dict(zip(BASE_NAMES, map(float, res0.stderr))),
                          "rms_fit": res0.rms, "rms_validate": rms0}
        mv = self.mv_
        self.residual_before_ = rv0
        self.where_ = localise(rv0, reg.dq_d[mv], reg.q_d[mv], reg.ddq_d[mv], self.dead_band)

        results = []
        self._chosen = {}
        for cand in self.candidates:
            shape, cols, res, rv = self._fit_candidate(cand)
            k = len(cand.coefficients) + (1 if cand.grid else 0)
            score, rms = self._score(rv, k)
            params = dict(zip(cand.coefficients, map(float, res.theta[4:])))
            if cand.grid:
                params[cand.shape_name] = float(shape)
                if shape in (cand.grid[0], cand.grid[-1]):
                    log.info("candidate %s: shape %s at the edge of its grid (%g %s)", cand.name,
                             cand.shape_name, shape, cand.shape_unit)
            params.update({f"base_{n}": float(v) for n, v in zip(BASE_NAMES, res.theta[:4])})
            self._chosen[cand.name] = (cand.columns(reg, shape), k)
            results.append({"effect": cand.name, "description": cand.description, "parameters": params,
                            "n_parameters": k, "rms_before": rms0, "rms_after": rms,
                            "shrink": 1.0 - rms / rms0, "score": score, "rms_fit": res.rms})
        self.results_ = sorted(results, key=lambda d: d["score"])
        self.best_ = self.results_[0] if self.results_ and self.results_[0]["score"] < 0 else None

        self.selection_ = []
        chosen, cols, k_tot, current = [], [], 0, 0.0
        rv_sel = rv0
        n_f = int(self.mf_.sum())
        while self.forward_selection:
            step = None
            for name, (c_cols, k) in self._chosen.items():
                if name in chosen:
                    continue
                res, rv = self._solve(cols + c_cols)
                bic = n_f * math.log(res.rss / res0.rss) + (k_tot + k) * math.log(n_f)   # fit part only
                if step is None or bic < step[1]:
                    step = (name, bic, c_cols, k, rv, res)
            if step is None or step[1] >= current:
                break
            name, current, c_cols, k, rv_sel, res = step
            chosen.append(name)
            cols += c_cols
            k_tot += k
            score, rms = self._score(rv_sel, k_tot)
            self.selection_.append({"effects": list(chosen), "bic_fit": current, "rms_after": rms,
                                    "shrink": 1.0 - rms / rms0, "score": score,
                                    "theta": [float(x) for x in res.theta]})
        self.residual_after_ = rv_sel
        self.where_after_ = localise(rv_sel, reg.dq_d[mv], reg.q_d[mv], reg.ddq_d[mv], self.dead_band)
        log.info("residual diagnosis: best single %s (shrink %.3f); forward selection %s",
                 self.results_[0]["effect"], self.results_[0]["shrink"],
                 self.selection_[-1]["effects"] if self.selection_ else "none")
        return self
