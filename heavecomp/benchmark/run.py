"""Diagnose the benchmark's cases and summarise the verdicts."""

from __future__ import annotations

import dataclasses

import numpy as np

from heavecomp.benchmark.case import benchmark_cases, CASES
from heavecomp.benchmark.generate import generate
from heavecomp.diagnosis import GapDiagnoser
from heavecomp.effects.candidates import same_family


def run_benchmark(quick=False, duration=None, progress=None, n_jobs=2, max_nfev=None, seed0=1000):
    """Diagnose every case of :func:`heavecomp.benchmark.benchmark_cases`.

    Parameters
    ----------
    quick : bool
        Three 120 s runs.
    duration : float or None [s]
        Overrides the cases' length.
    progress : callable or None
        ``progress(fraction, message)`` after each run.
    n_jobs : int
        Parallel fits of the diagnoser.
    max_nfev : int or None
        The diagnoser's evaluation budget per fit (None: its default).
    seed0 : int
        First seed of the full set.

    Returns
    -------
    (list of dict, dict)
        One row per run and :func:`summarize` of them.
    """
    rows = []
    cases = benchmark_cases(quick, seed0)
    if duration is not None:
        cases = [dataclasses.replace(c, duration=duration) for c in cases]
    for i, case in enumerate(cases):
        tr = generate(case)
        kw = {} if max_nfev is None else {"max_nfev": max_nfev}
        d = GapDiagnoser(tr.nominal, n_jobs=n_jobs, **kw).fit(tr.to_run())
        v = d.verdict_
        second = (v.get("second_effect") or {}).get("effect")
        effects = tuple(tr.truth["effects"])  # dominant first
        row = {"truth": effects[0], "truth_second": effects[1] if len(effects) > 1 else None,
               "param_set": case.params, "seed": case.seed, "verdict": v["effect"], "confidence": v["confidence"],
               "second_effect": second, "shrink": v["shrink"], "explained": v.get("explained"),
               "gap_to_noise": v.get("gap_to_noise"), "wall_time": d.wall_time_,
               "gap_to_input_envelope": v.get("gap_to_input_envelope"),
               "truth_parameters": tr.truth["parameters"], "fitted_parameters": v.get("parameters"),
               "planted_gap": tr.truth["gap_to_noise"], "second_share": tr.truth.get("second_share"),
               "second_tried": [s["effect"] for s in d.second_tried_],
               "best_partner": max(d.second_tried_, key=lambda s: s["added_explained"])["effect"] if d.second_tried_ else None,
               "stuck_share": tr.truth["stick"]["stuck_share"], "sea": tr.truth["sea"]}
        row["law"] = v.get("law")  # a family's law (friction_lag: time or distance) and the effect fitted
        row["member"] = v.get("member")
        # right when the verdict names the truth's contract class (a friction_lag verdict of either law for a
        # frictional-memory truth: diagnosis-contract.md's effect table, issue 30 item 4)
        row["correct"] = same_family(row["verdict"], row["truth"])
        rows.append(row)
        if progress:
            progress((i + 1) / len(cases), f"{'+'.join(effects)} -> {v['effect']} ({v['confidence']}), "
                                           f"shrink {v['shrink']:.2f}")
    return rows, summarize(rows)


def summarize(rows):
    """Confusion matrix, shrinks and two-effect counts of :func:`run_benchmark`'s rows.

    Parameters
    ----------
    rows : list of dict

    Returns
    -------
    dict
    """
    labels = list(CASES) + ["inconclusive"]
    truths = [lab for lab in CASES if any(r["truth"] == lab for r in rows)]
    cm = {tl: {vl: 0 for vl in labels} for tl in truths}
    for r in rows:
        cm[r["truth"]][r["verdict"] if r["verdict"] in labels else "inconclusive"] += 1  # verdicts: contract names
    eff = [r for r in rows if r["truth"] != "none" and r["correct"]]
    shr = [r["shrink"] for r in rows if r["truth"] != "none"]
    two = [r for r in rows if r["truth_second"]]
    return {"n_runs": len(rows), "accuracy": float(np.mean([r["correct"] for r in rows])),
            "confusion": cm,
            "median_shrink_all_effect_runs": float(np.median(shr)) if shr else None,
            "median_shrink_correct": float(np.median([r["shrink"] for r in eff])) if eff else None,
            "two_effect_second_named": sum(r["second_effect"] == r["truth_second"] for r in two),
            "n_two_effect": len(two),
            "two_effect_second_tried": sum(r["truth_second"] in r["second_tried"] for r in two),
            "two_effect_second_best_partner": sum(r["truth_second"] == r["best_partner"] for r in two),
            "spurious_second": sum(r["second_effect"] is not None for r in rows if not r["truth_second"]),
            "n_single": sum(not r["truth_second"] for r in rows),
            "min_planted_gap": min((g for r in rows for g in r["planted_gap"].values()), default=None),
            "median_wall_time": float(np.median([r["wall_time"] for r in rows]))}
