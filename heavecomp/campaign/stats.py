"""WOB exceedance statistics of a campaign: short-term (per sea state) and long-term.

Method
------
Each run stores a histogram of the WOB deviation dW = W - W_0 sampled at the
campaign rate after the fade-in (:mod:`heavecomp.campaign.batch`).  The seeds
of one sea state are pooled (their histograms added), giving the **short-term**
time-fraction exceedance of sea state s

    Q_s(x) = P(|dW| > x | s)          (also one-sided P(dW > x), P(dW < -x))

exact at the bin edges x_m = m w (w = 2 deviation_max / bins).  The
**long-term** exceedance weights the sea states by their scatter-diagram
probabilities p_s (the fraction of time the rig spends in them):

    Q_LT(x) = sum_s p_s Q_s(x) / sum_s p_s

Cycle peaks (max |dW| between zero up-crossings of dW) are pooled the same
way; their long-term distribution weights each sea state by p_s nu_s, with
nu_s its mean cycle rate (cycles per second), as for long-term wave-height
statistics.  The most probable largest deviation within the exposure T is the
level x with Q_peak,LT(x) = 1 / (nu_LT T), nu_LT = sum_s p_s nu_s (independent
peaks assumed; ``nan`` when the histogram range does not reach that level).
It is not extrapolated beyond the largest simulated peak, so with few seeds
and an exposure much longer than the simulated time it is a lower bound.

Tolerance band |dW| <= b: per sea state the fraction of time outside, the rate
of band exits lambda_s (inside -> outside transitions of the sampled WOB per
hour) and, assuming exits form a Poisson process, the probability of leaving
the band at least once within the exposure T, P_s = 1 - exp(-lambda_s T).
Long-term values are p-weighted means.  The empirical fraction of runs
(seeds) that left the band within their statistics window is reported beside
it as a check of the Poisson assumption at T = window length.
"""

from __future__ import annotations

import math

import numpy as np

from heavecomp.campaign.batch import hist_columns


def _abs_bins(hist, nbins):
    """Histogram of |dW| (nbins/2 bins + overflow) from the signed histogram (under, bins, over)."""
    half = nbins // 2
    inner = hist[..., 1:nbins + 1]
    neg = inner[..., :half][..., ::-1]
    pos = inner[..., half:]
    over = hist[..., 0] + hist[..., nbins + 1]
    return np.concatenate([neg + pos, over[..., None]], axis=-1)


def exceedance_from_counts(counts):
    """P(X > x_m) for x_m at the lower edge of each bin: counts of bins 0..K-1 plus overflow.

    Parameters
    ----------
    counts : array_like
        Histogram counts, bins along the last axis (overflow last).

    Returns
    -------
    numpy.ndarray [-]
        Exceedance probability per bin, same shape; nan where a histogram is empty.
    """
    counts = np.asarray(counts, dtype=float)
    tot = counts.sum(axis=-1, keepdims=True)
    tail = np.cumsum(counts[..., ::-1], axis=-1)[..., ::-1]  # sum of bins >= m
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(tot > 0, tail / tot, np.nan)


def level_at(x, q, level):
    """Smallest x with Q(x) <= level (linear interpolation in log Q); nan if not reached.

    Parameters
    ----------
    x : array_like
        Levels, increasing [their unit, e.g. N].
    q : array_like [-]
        Exceedance probability at ``x``.
    level : float [-]
        The probability looked for (> 0).

    Returns
    -------
    float
        The level [the unit of ``x``], or nan.
    """
    q = np.asarray(q, dtype=float)
    idx = np.flatnonzero(q <= level)
    if idx.size == 0:
        return math.nan
    k = idx[0]
    if k == 0 or q[k] <= 0 or q[k - 1] <= 0:
        return float(x[k])
    f = (math.log(level) - math.log(q[k - 1])) / (math.log(q[k]) - math.log(q[k - 1]))
    return float(x[k - 1] + f * (x[k] - x[k - 1]))


def statistics(campaign, table: dict) -> dict:
    """Short- and long-term WOB statistics per (regime, variant).

    Parameters
    ----------
    campaign : Campaign
    table : dict of arrays
        The results table (:func:`heavecomp.campaign.execute.read_table`).

    Returns
    -------
    dict
        ``{"x": bin edges of |dW| [N], "groups": {"<regime>/<variant>": {...}},
        "regime_effect": {...}}`` — see the module docstring for the method.
    """
    o = campaign.outputs
    nb = o.bins
    dev_cols, pk_cols = hist_columns(nb)
    w = 2.0 * o.deviation_max / nb
    x_abs = np.arange(nb // 2 + 1) * w  # lower edges of |dW| bins + the overflow start
    x_signed = -o.deviation_max + np.arange(nb + 1) * w
    rate = campaign.settings.rate
    T = campaign.band.exposure
    H = np.stack([table[c] for c in dev_cols], axis=1)
    PK = np.stack([table[c] for c in pk_cols], axis=1)
    groups = {}
    for reg in campaign.regimes:
        for var in campaign.variants:
            sel = (table["regime"] == reg) & (table["variant"] == var.name)
            if not sel.any():
                continue
            states = []
            for k in np.unique(table["sea_state"][sel]).astype(int):
                m = sel & (table["sea_state"] == k)
                h = H[m].sum(axis=0)
                pk = PK[m].sum(axis=0)
                n = table["n_samples"][m].sum()
                hours = n / rate / 3600.0
                exits = table["n_band_exits"][m].sum()
                lam = exits / hours if hours > 0 else math.nan
                cycles = table["n_cycles"][m].sum()
                # one-sided: P(dW >= x_j) at the signed bin edges x_j (j = 0..nb)
                p_above = 1.0 - np.cumsum(h)[:-1] / h.sum()
                states.append({
                    "sea_state": k, "hs": float(table["hs"][m][0]), "tp": float(table["tp"][m][0]),
                    "probability": float(table["probability"][m][0]), "n_runs": int(m.sum()),
                    "wob_std": float(np.mean(table["wob_std"][m])),
                    "wob_min": float(np.min(table["wob_min"][m])), "wob_max": float(np.max(table["wob_max"][m])),
                    "stick_fraction": float(np.mean(table["stick_fraction"][m])),
                    "stroke_max": float(np.max(table["stroke_max"][m])),
                    "frac_outside_band": float(np.sum(table["frac_outside_band"][m] * table["n_samples"][m]) / n),
                    "band_exits_per_hour": float(lam),
                    "p_leave_exposure": float(1.0 - math.exp(-lam * T)) if np.isfinite(lam) else math.nan,
                    "p_leave_window_empirical": float(np.mean((table["n_band_exits"][m] > 0)
                                                              | (table["frac_outside_band"][m] > 0))),
                    "p_leave_window_poisson": float(np.mean(1.0 - np.exp(
                        -lam * table["n_samples"][m] / rate / 3600.0))),
                    "cycle_rate": float(cycles / (n / rate)) if n else math.nan,
                    "exceed_abs": exceedance_from_counts(_abs_bins(h, nb)).tolist(),
                    "exceed_above": p_above.tolist(),
                    "exceed_peak": exceedance_from_counts(pk).tolist(),
                })
            p = np.array([s["probability"] for s in states])
            pn = p / p.sum()
            Qa = np.array([s["exceed_abs"] for s in states])
            Qup = np.array([s["exceed_above"] for s in states])
            Qpk = np.array([s["exceed_peak"] for s in states])
            nu = np.array([s["cycle_rate"] for s in states])
            wpk = pn * nu
            lt_abs = pn @ Qa
            lt = {
                # probabilities: clip the last-ulp rounding of the weighted sums into [0, 1]
                "frac_outside_band": float(np.clip(pn @ [s["frac_outside_band"] for s in states], 0.0, 1.0)),
                "p_leave_exposure": float(np.clip(pn @ [s["p_leave_exposure"] for s in states], 0.0, 1.0)),
                "band_exits_per_hour": float(pn @ [s["band_exits_per_hour"] for s in states]),
                "wob_std_rms": float(math.sqrt(pn @ np.square([s["wob_std"] for s in states]))),
                "stick_fraction": float(pn @ [s["stick_fraction"] for s in states]),
                "exceed_abs": lt_abs.tolist(),
                "exceed_above": (pn @ Qup).tolist(),
                "exceed_peak": ((wpk @ Qpk) / wpk.sum()).tolist() if wpk.sum() > 0 else [],
                "dev_exceeded_1e-2": level_at(x_abs, lt_abs, 1e-2),
                "dev_exceeded_1e-3": level_at(x_abs, lt_abs, 1e-3),
                "probability_covered": float(p.sum()),
                "band_half_width": float(np.max(table["band_half_width"][sel])),
                "cycle_rate": float(pn @ nu),
            }
            # most probable largest |dW| in the exposure T: the level exceeded by one of the nu T cycle peaks
            # expected in T (long-term peak distribution; independent peaks assumed)
            n_exp = lt["cycle_rate"] * T
            lt["dev_max_in_exposure"] = (level_at(x_abs, lt["exceed_peak"], 1.0 / n_exp)
                                         if lt["exceed_peak"] and n_exp > 1 else math.nan)
            groups[f"{reg}/{var.name}"] = {"regime": reg, "variant": var.name, "short_term": states, "long_term": lt}
    effect = {}
    for var in campaign.variants:
        ref = groups.get(f"none/{var.name}")
        for reg in campaign.regimes:
            g = groups.get(f"{reg}/{var.name}")
            if g is None:
                continue
            e = {"frac_outside_band": g["long_term"]["frac_outside_band"],
                 "p_leave_exposure": g["long_term"]["p_leave_exposure"],
                 "wob_std_rms": g["long_term"]["wob_std_rms"]}
            if ref is not None and ref["long_term"]["frac_outside_band"] > 0:
                e["frac_outside_ratio_to_none"] = e["frac_outside_band"] / ref["long_term"]["frac_outside_band"]
            effect[f"{reg}/{var.name}"] = e
    return {"x_abs": x_abs.tolist(), "x_signed": x_signed.tolist(), "bin_width": w,
            "band_half_width": float(np.unique(table["band_half_width"])[0]) if table["band_half_width"].size else None,
            "exposure": T, "rate": rate, "n_runs": int(table["run_id"].size),
            "groups": groups, "regime_effect": effect}
