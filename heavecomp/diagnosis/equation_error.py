"""Equation-error fits: candidates and an open search on one model component's residual.

Plant-independent.  A *component residual* ``r`` is one model equation evaluated on the measured
signals, measured minus nominal (e.g. the seal friction force the top-mass force balance needs
minus the nominal friction law, :mod:`heavecomp.diagnosis.components`).  An effect that lives in
that component adds columns linear in their coefficients (:meth:`heavecomp.effects.base.Effect.features`);
fitting them is a least-squares problem, blind to stick-event timing and thousands of times
cheaper than a replay.

- :func:`fit_columns`: least squares of ``r`` on named columns (plus optional ``base`` columns:
  nominal linear parameters refitted alongside) on the *fit* mask; held-out shrink
  ``1 - rms_after / rms_before`` on the *validate* mask; a fit-part BIC.
- :func:`rank_effects`: every effect class over its :attr:`~heavecomp.effects.base.Effect.feature_grid`,
  best shape per effect, ranked by held-out shrink.
- :func:`library` / :func:`open_search`: a sparse regression (sequentially thresholded least squares,
  STLSQ) over a library of physically meaningful features; the best model is the ``discovered`` term.

Example
-------
>>> import numpy as np
>>> t = np.linspace(0.0, 200.0, 4001); v = np.sin(0.3 * t) * np.cos(0.05 * t)
>>> r = 900.0 * (v > 0) + np.random.default_rng(0).normal(0.0, 50.0, t.size)
>>> fit, val = t < 130.0, t >= 130.0
>>> d = open_search(r, {"t": t, "v": v}, fit, val, component="friction")
>>> d["features"], round(d["shrink"], 1)
(['sign_v_pos'], 0.9)

Why not pysindy: its STLSQ fits ``dx/dt = Theta(x) xi``; here the target is an algebraic residual
and the library is ours (direction-split signs, stroke bands, dwell, dead bands), so what pysindy
would contribute is the ~20-line thresholding loop below, at the cost of pysindy + scikit-learn in
every install.
"""

from __future__ import annotations

import math

import numpy as np

from heavecomp.effects.features import rest_durations
#: a discovered term must shrink the held-out component residual by at least this much [-]
MIN_SHRINK = 0.05
#: STLSQ thresholds tried, on the standardised coefficient relative to std(r) [-]
THRESHOLDS = (0.02, 0.05, 0.1, 0.2, 0.4)
PRUNE = 0.02  #: a term of the discovered model must add at least this much fit-part shrink [-]
STROKE_BANDS = 4  #: stroke-band indicators (equal-count bands of the position)
LAGS = (0.2, 1.0)  #: lagged-velocity features [s]


def _ms(x):
    return float(np.mean(x * x)) if x.size else math.nan


def effective_n(r) -> float:
    """Number of independent samples of an autocorrelated residual, n (1 - rho) / (1 + rho), rho the
    lag-1 autocorrelation (a filtered residual has far fewer than n; BIC with n would accept noise).

    Parameters
    ----------
    r : numpy.ndarray
        Residual samples (any unit).
    """
    n = r.size
    if n < 4 or np.std(r) == 0:
        return float(n)
    rho = min(max(float(np.corrcoef(r[:-1], r[1:])[0, 1]), 0.0), 0.999)
    return max(2.0, n * (1 - rho) / (1 + rho))


def _design(cols: dict, mask, base=None):
    names = list(cols)
    mats = [np.asarray(cols[k], float)[mask] for k in names]
    bnames = list(base or {})
    mats += [np.asarray(base[k], float)[mask] for k in bnames]
    X = np.column_stack(mats) if mats else np.zeros((int(mask.sum()), 0))
    return X, names, bnames


def _scales(X):
    """Per-column scale for a standardised least squares: the spread, or for a constant column (an
    intercept, or a decimated column of ones whose spread is rounding) its size -- dividing by a
    ~1e-16 spread would swamp every other coefficient."""
    s = X.std(axis=0) if X.shape[0] else np.zeros(X.shape[1])  # no rows (a calm log never slides): no spread
    size = np.max(np.abs(X), axis=0) if X.shape[0] else np.ones(X.shape[1])
    flat = s <= 1e-9 * np.maximum(size, 1e-300)
    s[flat] = np.where(size[flat] > 0, size[flat], 1.0)
    return s


def _lstsq(X, y):
    if X.shape[1] == 0:
        return np.zeros(0)
    s = _scales(X)
    c, *_ = np.linalg.lstsq(X / s, y, rcond=None)
    return c / s


def fit_columns(r, cols: dict, fit, validate, base=None) -> dict:
    """Least squares of the residual ``r`` on ``cols`` (plus ``base``) on the ``fit`` mask.

    Parameters
    ----------
    r : array [unit of the component]
    cols : {name: array}
        Regressors, linear in their coefficients.
    fit, validate : boolean arrays
        Samples to fit on / to score on (held out); non-finite samples of ``r`` or a column are left out.
    base : {name: array}, optional
        Columns refitted with every candidate and in the reference (nominal linear parameters).

    Returns
    -------
    dict: ``coefficients`` {name: value [unit of r / unit of column]}, ``base`` coefficients,
    ``rms_before`` / ``rms_after`` on ``validate`` (before: ``r`` after the base-only refit),
    ``shrink`` = 1 - rms_after/rms_before, ``shrink_fit`` the same on the fit part, ``bic`` on the fit part (effective sample size,
    :func:`effective_n`), ``n_terms``.
    """
    r = np.asarray(r, float)
    ok = np.isfinite(r)
    for c in list(cols.values()) + list((base or {}).values()):
        ok &= np.isfinite(c)
    fm, vm = fit & ok, validate & ok
    Xb_f, _, bn = _design({}, fm, base)
    Xb_v, _, _ = _design({}, vm, base)
    cb = _lstsq(Xb_f, r[fm])
    rb_v = r[vm] - Xb_v @ cb
    rb_f = r[fm] - Xb_f @ cb
    X_f, names, _ = _design(cols, fm, base)
    X_v, _, _ = _design(cols, vm, base)
    c = _lstsq(X_f, r[fm])
    ra_f = r[fm] - X_f @ c
    ra_v = r[vm] - X_v @ c
    before, after = math.sqrt(_ms(rb_v)), math.sqrt(_ms(ra_v))
    before_f, after_f = math.sqrt(_ms(rb_f)), math.sqrt(_ms(ra_f))
    n_eff = effective_n(rb_f)
    k = len(names)
    bic = n_eff * math.log(max(_ms(ra_f), 1e-300)) + k * math.log(max(n_eff, 2.0))
    bic0 = n_eff * math.log(max(_ms(rb_f), 1e-300))
    return {"coefficients": {n: float(x) for n, x in zip(names, c[:k])},
            "base": {n: float(x) for n, x in zip(bn, c[k:])},
            "rms_before": before, "rms_after": after,
            "shrink": 1.0 - after / before if before > 0 else 0.0,
            "shrink_fit": 1.0 - after_f / before_f if before_f > 0 else 0.0,
            "bic": float(bic), "delta_bic": float(bic - bic0), "n_terms": k}


def rank_effects(r, sig, effects, fit, validate, base=None, component="") -> list:
    """Fit every effect class's equation-error columns (:meth:`Effect.features` over its
    ``feature_grid``) to the component residual ``r``; the best shape per effect by the *fit* part's
    BIC (the held-out part only scores, never chooses).  Columns named like a ``base`` column are
    dropped (the base already refits that parameter; two copies would split its coefficient).

    Returns a list, best first, of {``effect``, ``component``, ``shape``, ``coefficients``,
    ``shrink``, ``bic``, ``delta_bic``, ``rms_before``, ``rms_after``}; effects without an
    equation-error form here (``features`` returns None) are left out.

    Parameters
    ----------
    r : numpy.ndarray [unit of the component]
        Component residual.
    sig : dict
        Measured signals of the component ({``t`` [s], ``v`` [m/s], ``x`` [m], ``p`` [Pa], ...}:
        :meth:`heavecomp.diagnosis.components.ComponentResiduals.signals_for`).
    effects : iterable of type
        Effect classes (:class:`heavecomp.effects.base.Effect` subclasses).
    fit, validate : numpy.ndarray of bool
        Samples to fit on / to score on (held out).
    base : dict, optional
        {name: array} columns refitted with every candidate and in the reference (nominal linear
        parameters).
    component : str
        Component name reported for every row; empty: each class's own :meth:`Effect.component`.
    """
    out = []
    for cls in effects:
        best = None
        for shape in (cls.feature_grid or (None,)):
            cols = cls.features(sig, shape)
            if cols and base:
                cols = {n: c for n, c in cols.items() if n not in base}
            if not cols:
                continue
            res = fit_columns(r, cols, fit, validate, base)
            if best is None or res["bic"] < best["bic"]:
                best = dict(res, shape=shape)
        if best is not None:
            out.append(dict(best, effect=cls.name, component=component or cls.component()))
    out.sort(key=lambda d: -d["shrink"])
    return out


# ---------------------------------------------------------------------------- open search
def library(sig: dict, names=None) -> dict:
    """The open search's features from the signals present in ``sig`` (names as
    :meth:`heavecomp.effects.base.Effect.features`; optional ``rel`` relative displacement of a
    spring [m], ``still`` boolean at rest).

    Returns {name: (array, readable expression)}.  A feature whose signal is missing is left out.

    Parameters
    ----------
    sig : dict
        Measured signals of the component ({``t`` [s], ``v`` [m/s], ``x`` [m], ``p`` [Pa], ...}:
        :meth:`heavecomp.diagnosis.components.ComponentResiduals.signals_for`). Optional ``rel`` [m] and ``still`` (bool) add their features.
    names : sequence of str, optional
        Only these features (a component's own parts,
        :meth:`heavecomp.diagnosis.components.ComponentResiduals.own_features`); a name that is not a
        library feature but a signal of ``sig`` (``a`` the acceleration, ``dp``, ``zh`` ...) is that
        signal itself.  None: the whole library.
    """
    if names is not None:
        full = library(sig)
        return {n: full[n] if n in full else (np.asarray(sig[n], float), n) for n in names
                if n in full or n in sig}
    t = np.asarray(sig["t"], float)
    L = {"const": (np.ones(t.size), "1"), "t": (t - t[0], "(t - t0)")}
    v = sig.get("v")
    if v is not None:
        sv = np.sign(v)
        L.update({"sign_v_pos": ((v > 0).astype(float), "sign(v)*(v>0)"),
                  "sign_v_neg": (-(v < 0).astype(float), "sign(v)*(v<0)"),
                  "v": (v, "v"), "v_abs_v": (v * np.abs(v), "v*|v|"), "abs_v": (np.abs(v), "|v|")})
        for lag in LAGS:
            L[f"v_lag{lag:g}"] = (np.interp(t - lag, t, v, left=v[0]), f"v(t-{lag:g}s)")
        still = sig.get("still")
        if still is not None:
            rest = sig["rest"] if "rest" in sig else rest_durations(t, still)[1]
            L["rest_sign_v"] = (np.log1p(rest) * sv * (~np.asarray(still, bool)), "log(1+t_rest)*sign(v)")
    else:
        sv = None
    p = sig.get("p")
    if p is not None:
        L["p"] = (p, "p")
        if sv is not None:
            L["p_sign_v"] = (p * sv, "p*sign(v)")
    x = sig.get("x")
    if x is not None:
        L["x"] = (x - np.nanmean(x), "(x - mean x)")
        if sv is not None:
            edges = np.nanquantile(x, np.linspace(0, 1, STROKE_BANDS + 1))
            for k in range(STROKE_BANDS):
                lo, hi = edges[k], edges[k + 1]
                inb = (x >= lo) & (x <= hi) if k == STROKE_BANDS - 1 else (x >= lo) & (x < hi)
                L[f"band{k}_sign_v"] = (inb * sv, f"sign(v)*({lo:.3g}<=x<{hi:.3g})")
    rel = sig.get("rel")
    if rel is not None:
        m = np.nanmedian(rel)
        d = rel - m
        L["rel"] = (d, "(rel - median rel)")
        # a spring that stiffens or softens with its stretch (odd and even powers)
        L["rel_abs_rel"] = (d * np.abs(d), "(rel - median rel)*|rel - median rel|")
        L["rel_cubed"] = (d ** 3, "(rel - median rel)^3")
        for q in (0.25, 0.5):
            w = float(np.nanquantile(np.abs(d), q))
            L[f"deadband{q:g}"] = (np.sign(d) * np.maximum(np.abs(d) - w, 0.0) - d,
                                   f"(deadband(rel, {w:.3g}) - rel)")
            L[f"saturation{q:g}"] = (np.clip(d, -w, w) - d, f"(clip(rel, +-{w:.3g}) - rel)")
    return L


def stlsq(X, y, threshold, iters=10):
    """Sequentially thresholded least squares on standardised columns: refit on the surviving
    columns, drop those whose standardised coefficient is below ``threshold`` x std(y).
    Returns the boolean support.

    Parameters
    ----------
    X : numpy.ndarray
        Feature columns (n samples x k).
    y : numpy.ndarray
        Target (the component residual on the fit part).
    threshold : float [-]
        Smallest standardised coefficient kept, relative to std(y).
    iters : int
        Maximum thresholding rounds.
    """
    Z = X / _scales(X)
    keep = np.ones(X.shape[1], bool)
    sy = float(np.std(y)) or 1.0
    for _ in range(iters):
        if not keep.any():
            break
        c, *_ = np.linalg.lstsq(Z[:, keep], y, rcond=None)
        small = np.abs(c) < threshold * sy
        if not small.any():
            break
        idx = np.flatnonzero(keep)
        keep[idx[small]] = False
    return keep


def open_search(r, sig, fit, validate, *, base=None, component="", max_terms=3, min_shrink=MIN_SHRINK,
                features=None) -> dict | None:
    """The best sparse model of a component residual over :func:`library` (or ``features``).

    STLSQ at each of :data:`THRESHOLDS` on the fit part; among the supports with at most
    ``max_terms`` terms, the one with the lowest fit-part BIC (effective sample size) that lowers the
    BIC at all; then terms that add less than :data:`PRUNE` of the *fit part's* shrink are dropped
    (the held-out part never chooses, as in :func:`rank_effects`: it only scores); the held-out
    shrink of the chosen model must reach ``min_shrink``, else None (pure noise is rejected).

    Returns {``term``: readable sum of coefficient x feature, SI; ``features``: names; ``coefficients``;
    ``shrink``: held-out; ``component``; ``bic``, ``delta_bic``, ``rms_before``, ``rms_after``} or None.

    Parameters
    ----------
    r : numpy.ndarray [unit of the component]
        Component residual.
    sig : dict
        Measured signals of the component ({``t`` [s], ``v`` [m/s], ``x`` [m], ``p`` [Pa], ...}:
        :meth:`heavecomp.diagnosis.components.ComponentResiduals.signals_for`).
    fit, validate : numpy.ndarray of bool
        Samples to fit on / to score on (held out).
    base : dict, optional
        {name: array} columns refitted in every model and in the reference.
    component : str
        Component name reported.
    max_terms : int
        Most terms of the chosen model.
    min_shrink : float [-]
        Held-out shrink the chosen model must reach.
    features : dict, optional
        {name: (array, readable expression)} searched instead of :func:`library`.
    """
    lib = features if features is not None else library(sig)
    r = np.asarray(r, float)
    ok = np.isfinite(r)
    for a, _ in lib.values():
        ok &= np.isfinite(a)
    fm = fit & ok
    if fm.sum() < 10 or (validate & ok).sum() < 10:
        return None
    names = list(lib)
    X = np.column_stack([lib[k][0][fm] for k in names])
    y = r[fm]
    if base:
        Xb = np.column_stack([np.asarray(b, float)[fm] for b in base.values()])
        y = y - Xb @ _lstsq(Xb, y)
    best = None
    seen = set()
    for thr in THRESHOLDS:
        keep = stlsq(X, y, thr)
        sel = tuple(n for n, k in zip(names, keep) if k)
        # too many survivors: keep the max_terms largest standardised contributions
        if len(sel) > max_terms:
            Z = X[:, keep]
            c = _lstsq(Z, y) * Z.std(axis=0)
            order = np.argsort(-np.abs(c))[:max_terms]
            sel = tuple(sel[i] for i in sorted(order))
        if not sel or sel in seen:
            continue
        seen.add(sel)
        res = fit_columns(r, {n: lib[n][0] for n in sel}, fit, validate, base)
        if res["delta_bic"] < 0 and (best is None or res["bic"] < best["bic"]):
            best = dict(res, features=list(sel))
    if best is None:
        return None
    # parsimony: drop a term whose removal costs less than PRUNE of the fit part's shrink
    while len(best["features"]) > 1:
        trials = []
        for n in best["features"]:
            sub = [m for m in best["features"] if m != n]
            trials.append(dict(fit_columns(r, {m: lib[m][0] for m in sub}, fit, validate, base), features=sub))
        alt = max(trials, key=lambda d: d["shrink_fit"])
        if alt["shrink_fit"] < best["shrink_fit"] - PRUNE:
            break
        best = alt
    if best["shrink"] < min_shrink:
        return None
    term = " + ".join(f"{best['coefficients'][n]:.3g}*{lib[n][1]}" for n in best["features"])
    return {"term": term, "features": best["features"], "coefficients": best["coefficients"],
            "shrink": float(best["shrink"]), "component": component, "bic": best["bic"],
            "delta_bic": best["delta_bic"], "rms_before": best["rms_before"], "rms_after": best["rms_after"]}
