"""The two real-data studies as functions returning plain results (metrics + objects
for figures), so that the scenarios stay thin and tests can call them directly."""

from __future__ import annotations

import math

import numpy as np

from heavecomp.identification.inverse import InverseModelLS, cutoff_sensitivity
from heavecomp.identification.plants import AXIS_TERMS, AXIS_UNITS, SEAL_UNITS, AxisFriction, SealFriction
from heavecomp.identification.residual import ResidualDiagnoser
from heavecomp.identification.seal import BAR, BORE_DIAMETER, METHOD_VARIANTS, SealFrictionFit, scale_by_circumference
from heavecomp.plants.axis import BASE_NAMES, EMPS_PUBLISHED

#: Paper A main-cylinder friction: C_p = 200 N/bar for a 0.72 m plunger.
PAPER_A_CP = 200.0 / BAR
PAPER_A_DIAMETER = 0.72


def emps_study(record, cutoff: float = 50.0, order: int = 4, decimate: int = 10, t_split: float = 15.0,
               sensitivity_cutoffs=(10, 15, 20, 30, 40, 50, 70, 100, 150, 200),
               sensitivity_decimations=(10, 1), edge: float = 0.1) -> dict:
    """Identify the EMPS model on the whole record (benchmark check), its cut-off
    sensitivity, and diagnose the residual on the held-out part ``t >= t_split``
    (``edge`` [s] at both ends of the record, filter edge transients, left out of the diagnosis).

    Returns ``{"metrics": dict, "estimator": InverseModelLS, "diagnoser": ResidualDiagnoser,
    "sensitivity": {label: dict}}``.

    Parameters
    ----------
    record : AxisRecord
        The EMPS estimation record (:func:`heavecomp.plants.axis.load_emps`).
    cutoff : float [Hz]
        Butterworth cut-off of the position filter.
    order : int
        Butterworth order.
    decimate : int
        Decimation factor of the parallel filter.
    t_split : float [s]
        Start of the held-out part of the record (the diagnosis fits before it).
    sensitivity_cutoffs : sequence of float [Hz]
        Cut-offs of the sensitivity study (:func:`cutoff_sensitivity`).
    sensitivity_decimations : sequence of int
        Decimation factors of the sensitivity study (1: no decimation).
    edge : float [s]
        Left out of the diagnosis at both ends of the record (filter edge transients).
    """
    est = InverseModelLS(cutoff, order, decimate).fit(record)
    rel = {k: est.params_[k] / EMPS_PUBLISHED[k] - 1.0 for k in BASE_NAMES}
    sens = {f"decimate {nd} (parallel filter {0.4 * record.fs / nd:.0f} Hz)" if nd > 1 else "no decimation":
            cutoff_sensitivity(record, sensitivity_cutoffs, decimate=nd, order=order)
            for nd in sensitivity_decimations}
    reg = est.regression_
    t0, t1 = float(record.t[0]) + edge, float(record.t[-1]) - edge
    diag = ResidualDiagnoser(fit_window=(t0, t_split), validate_window=(t_split, t1)).fit(reg)
    # the base parameters under the EMPS names (the diagnoser names them in the effects' language)
    base = {k: diag.baseline_["parameters"][AXIS_TERMS[k]] for k in BASE_NAMES}
    baseline = {**diag.baseline_, "parameters": base,
                "stderr": {k: diag.baseline_["stderr"][AXIS_TERMS[k]] for k in BASE_NAMES}}
    metrics = {
        "record": {"name": record.name, "samples": len(record), "fs_Hz": record.fs,
                   "duration_s": float(record.t[-1] - record.t[0])},
        "settings": {"butterworth_cutoff_Hz": cutoff, "butterworth_order": order,
                     "forward_backward": True, "decimate": decimate,
                     "parallel_filter_cutoff_Hz": 0.4 * record.fs / decimate if decimate > 1 else None,
                     "derivative": "central differences of the filtered position"},
        "published": dict(EMPS_PUBLISHED),
        "identified_whole_record": est.params_,
        "stderr_whole_record": est.stderr_,
        "relative_error": rel,
        "max_abs_relative_error": max(abs(v) for v in rel.values()),
        "rms_whole_record_N": est.rms_,
        "sensitivity": sens,
        "split": {"fit": [t0, t_split], "validate": [t_split, t1],
                  "note": f"the first and last {edge:g} s (filter edge transients) are left out"},
        "baseline_fit_part": baseline,
        "asymmetric_coulomb_equivalent": {"coulomb_positive": base["coulomb"] + base["offset"],
                                          "coulomb_negative": base["coulomb"] - base["offset"]},
        "where": diag.where_,
        "candidates": diag.results_,
        "best_single": diag.best_["effect"] if diag.best_ else "none",
        "best_single_parameters": diag.best_["parameters"] if diag.best_ else {},
        "selection": diag.selection_,
        "where_after_selection": diag.where_after_,
        "discovered": _discovered(diag.discovered_),
    }
    p = diag.best_["parameters"] if diag.best_ else {}
    if "asymmetric_viscous" in p:
        fv = p[f"base_{AXIS_TERMS['viscous']}"]
        metrics["asymmetric_viscous_split"] = {"viscous_negative": fv - p["asymmetric_viscous"],
                                               "viscous_positive": fv + p["asymmetric_viscous"],
                                               "offset": p[f"base_{AXIS_TERMS['offset']}"],
                                               "coulomb": p[f"base_{AXIS_TERMS['coulomb']}"]}
    metrics["withheld_terms"] = withheld_terms(
        lambda w: AxisFriction(reg, withheld=w), [(), ("coulomb",), ("offset",)],
        {(): "none", ("coulomb",): "parameter_mismatch", ("offset",): "asymmetric_friction"},
        {(): "none", ("coulomb",): AXIS_TERMS["coulomb"], ("offset",): AXIS_TERMS["offset"]},
        AXIS_UNITS, fit_window=(t0, t_split), validate_window=(t_split, t1))
    return {"metrics": metrics, "estimator": est, "diagnoser": diag, "sensitivity": sens}


def _discovered(d):
    """The open search's result for a report: the readable term (coefficients in SI) and its shrink."""
    return None if d is None else {k: d[k] for k in ("term", "features", "shrink", "component", "rms_before",
                                                     "rms_after")}


def withheld_terms(plant_for, cases, expected: dict, labels: dict, units: dict, **settings) -> dict:
    """Diagnose one plant against nominal models that each lack one published term (issue 12 item 7).

    Parameters
    ----------
    plant_for : callable
        ``withheld tuple -> plant`` (:class:`~heavecomp.identification.plants.AxisFriction` or
        :class:`~heavecomp.identification.plants.SealFriction`).
    cases : list of tuple
        The withheld terms of each run; the first, ``()``, is the control (the full nominal).
    expected : dict
        ``case -> the effect the diagnosis should name`` (the control's entry is only shown: a real
        record keeps a remainder the published model lacks, so the control is not scored).
    labels : dict
        ``case -> the withheld term's name`` (in the effects' language).
    units : dict
        Units of the terms [SI].
    **settings : keyword arguments
        ``fit_window``, ``validate_window`` (and ``dead_band``) of :class:`ResidualDiagnoser`.

    Returns
    -------
    dict
        ``rows``: per case ``withheld``, ``published`` ({term: its value in the full nominal}) and its ``unit``,
        ``expected``, the ``verdict`` (effect, component, held-out shrink, parameters, changes),
        ``runner_up`` and its shrink, ``rms_before`` / ``rms_after`` [N] on the held-out part,
        ``reachable_shrink`` (1 - rms of the full nominal / rms before: what restoring the term
        could at most give) and ``discovered`` (the open search's term).
    """
    rows, full_rms = [], None
    for case in cases:
        plant = plant_for(case)
        d = ResidualDiagnoser(**settings).fit(plant)
        v = d.verdict_
        rms0 = d.baseline_["rms_validate"]
        if not case:
            full_rms, full_nominal = rms0, dict(plant.nominal)
        term = labels[case]
        second = d.results_[1] if len(d.results_) > 1 else None
        rows.append({"withheld": term, "published": {term: full_nominal[term]} if case else {},
                     "unit": units.get(term, "-"), "expected": expected[case],
                     "verdict": v["effect"], "component": v["component"], "shrink": v["shrink"],
                     "parameters": v["parameters"], "changes": v["changes"], "units": v["units"],
                     "runner_up": second["effect"] if second else None,
                     "runner_up_shrink": second["shrink"] if second else None,
                     "rms_before": rms0, "rms_after": d.best_["rms_after"] if d.best_ else rms0,
                     "reachable_shrink": 1.0 - full_rms / rms0 if case else None,
                     "discovered": v["discovered"]["term"] if v["discovered"] else None,
                     "discovered_shrink": v["discovered"]["shrink"] if v["discovered"] else None,
                     # the control is reported, not scored: a real record keeps a remainder
                     "right": v["effect"] == expected[case] if case else None})
    return {"rows": rows, "split": {k: list(w) for k, w in settings.items() if k.endswith("_window")},
            "rule": "a candidate is named when its held-out BIC-like score is negative (it earns its "
                    "parameters); the best score wins"}


def method_sensitivity(records, fit: SealFrictionFit, variants=None) -> dict:
    """C_p of the ``split`` and ``file_means`` fits when the analysis choices of ``fit`` are
    changed as :data:`~heavecomp.identification.seal.METHOD_VARIANTS` lists (no bootstrap).

    Returns {label: {"settings": dict, "C_p_split_N_per_bar", "C_p_file_means_N_per_bar" (None
    with fewer than 3 files),
    "n_strokes", "change_in_uncertainties": (C_p_split - C_p of ``fit``) / its uncertainty}}.

    Parameters
    ----------
    records : list of SealRecord
        The constant-pressure O-ring files.
    fit : SealFrictionFit
        The fitted headline (its settings are the base each variant changes).
    variants : dict, optional
        label -> settings of :class:`SealFrictionFit` changed; default
        :data:`~heavecomp.identification.seal.METHOD_VARIANTS`.
    """
    base = {"v_min": fit.v_min, "trim": fit.trim, "area": fit.area, "velocity": fit.velocity,
            "statistic": fit.statistic}
    out = {}
    for label, change in (METHOD_VARIANTS if variants is None else variants).items():
        f = SealFrictionFit(n_boot=0, **{**base, **change}).fit(records)
        out[label] = {"settings": {**base, **change},
                      "C_p_split_N_per_bar": f.fits_["split"]["C_p"] * BAR,
                      "C_p_file_means_N_per_bar": f.fits_["file_means"]["C_p"] * BAR if "file_means" in f.fits_ else None,
                      "n_strokes": len(f.strokes_),
                      "change_in_uncertainties": (f.C_p_ - fit.C_p_) / fit.C_p_se_}
    return out


def seal_study(records, n_boot: int = 2000, seed: int = 0, fit: SealFrictionFit | None = None,
               seal_split: float = 45.0) -> dict:
    """Fit F_C + C_p dp over the O-ring files; how much the analysis choices move C_p
    (:func:`method_sensitivity`); compare with paper A scaled by circumference; diagnose the
    friction against the nominal without C_p (``withheld_terms``: the first ``seal_split`` [s] of
    every file fitted, the rest held out).

    Returns ``{"metrics": dict, "fit": SealFrictionFit}``; pass ``fit`` (unfitted) to
    change its settings.

    Parameters
    ----------
    records : list of SealRecord
        The constant-pressure O-ring files (:func:`~heavecomp.identification.seal.load_seal_csv`).
    n_boot : int
        Bootstrap resamples of the default fit (ignored when ``fit`` is given).
    seed : int
        Bootstrap seed of the default fit (ignored when ``fit`` is given).
    fit : SealFrictionFit, optional
        An unfitted fit with other settings.
    seal_split : float [s]
        Of every file, the first ``seal_split`` are fitted and the rest held out.
    """
    fit = (fit or SealFrictionFit(n_boot=n_boot, seed=seed)).fit(records)
    per_file = {}
    for rec in records:
        rows = [r for r in fit.strokes_ if r["file"] == rec.name]
        per_file[rec.name] = {
            "dp_bar": float(np.mean([r["dp"] for r in rows]) / BAR),
            "strokes_positive": sum(r["direction"] > 0 for r in rows),
            "strokes_negative": sum(r["direction"] < 0 for r in rows),
            "friction_positive_N": float(np.mean([r["friction"] for r in rows if r["direction"] > 0])),
            "friction_negative_N": float(np.mean([r["friction"] for r in rows if r["direction"] < 0])),
            "speed_positive_mm_s": float(np.mean([r["speed"] for r in rows if r["direction"] > 0]) * 1e3),
            "speed_negative_mm_s": float(np.mean([r["speed"] for r in rows if r["direction"] < 0]) * 1e3),
        }
    fits = {k: {**f, "C_p_N_per_bar": f["C_p"] * BAR, "C_p_se_N_per_bar": f["C_p_se"] * BAR,
                "C_p_boot_N_per_bar": None if f["C_p_boot"] is None else f["C_p_boot"] * BAR}
            for k, f in fit.fits_.items()}
    scaled = scale_by_circumference(PAPER_A_CP, PAPER_A_DIAMETER, BORE_DIAMETER)
    metrics = {
        "settings": {"v_min_m_s": fit.v_min, "trim": fit.trim, "n_boot": fit.n_boot, "area_m2": fit.area,
                     "velocity": {"slope": "slope over +-10 samples (0.2 s)",
                                  "fir": "paper B: 100 Hz resampling, 2 Hz zero-phase FIR derivative"}[fit.velocity],
                     "statistic": fit.statistic},
        "files": per_file,
        "fits": fits,
        "C_p_N_per_Pa": fit.C_p_, "C_p_uncertainty_N_per_Pa": fit.C_p_se_,
        "C_p_N_per_bar": fit.C_p_ * BAR, "C_p_uncertainty_N_per_bar": fit.C_p_se_ * BAR,
        "F_C_N": fit.F_C_,
        "headline_fit": "split",
        "method_sensitivity": method_sensitivity(records, fit),
        "paper_a": {"C_p_N_per_bar": PAPER_A_CP * BAR, "plunger_diameter_m": PAPER_A_DIAMETER,
                    "scaled_to_bore_N_per_bar": scaled * BAR,
                    "ratio_measured_to_scaled": fit.C_p_ / scaled if scaled else math.nan},
    }
    sp = fit.fits_["split"]
    nominal = {"friction.coulomb_force": sp["F_C"], "friction.pressure_coefficient": sp["C_p"],
               "direction_offset": sp["F_0"], "direction_offset_pressure": sp["C_0"]}
    cp = "friction.pressure_coefficient"
    metrics["withheld_terms"] = withheld_terms(
        lambda w: SealFriction(records, nominal, withheld=w, v_min=fit.v_min, trim=fit.trim, area=fit.area),
        [(), (cp,)], {(): "none", (cp,): "pressure_friction"}, {(): "none", (cp,): cp}, SEAL_UNITS,
        fit_window=(0.0, seal_split), validate_window=(seal_split, math.inf), dead_band=fit.v_min)
    return {"metrics": metrics, "fit": fit}
