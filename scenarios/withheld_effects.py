"""Does the diagnosis name an unmodelled effect it was never shown, and how far does the gap shrink?

Withheld-effect benchmark (issue 4, item 7): runs generated with one effect by a law of its own
(not the candidate's equations; pairs in heavecomp.diagnosis.generator), in irregular seas
(JONSWAP) with measurement noise, on three nominal parameter sets, plus runs with no effect,
with only wrong parameters and with two effects. Each run is diagnosed blind against its
nominal parameters; a confusion matrix and a shrink table result.
"""

from __future__ import annotations

import logging
import time

from heavecomp.diagnosis.generator import run_benchmark
from heavecomp.diagnosis.report import fig_confusion, fig_shrink
from heavecomp.report.figures import save
from heavecomp.report.scenario import md_table, parse_args, write_metrics, write_report

log = logging.getLogger("withheld_effects")


def build(quick: bool = False):
    t0 = time.perf_counter()
    rows, summary = run_benchmark(quick=quick, progress=lambda f, m: log.info("[%3.0f %%] %s", 100 * f, m))
    summary["wall_time_s"] = time.perf_counter() - t0
    return rows, summary


def main(argv=None) -> int:
    args = parse_args(argv, "withheld_effects", __doc__)
    rows, summary = build(args.quick)
    write_metrics(args.out, {"summary": summary, "runs": rows, "quick": args.quick})
    save(fig_confusion(summary), args.out / "confusion.png", dpi=90)
    save(fig_shrink(rows), args.out / "shrink.png", dpi=90)
    table = md_table(["withheld", "second", "set", "verdict", "confidence", "named 2nd", "shrink", "explained",
                      "time [s]"],
                     [[r["truth"], r["truth_second"] or "", r["param_set"], r["verdict"], r["confidence"],
                       r["second_effect"] or "", f"{r['shrink']:.2f}", f"{r['explained']:.2f}",
                       f"{r['wall_time']:.1f}"] for r in rows])
    s = summary
    write_report(args.out, "Withheld-effect benchmark of the gap diagnosis", [
        __doc__.split("\n\n", 1)[1],
        f"**{s['n_runs']} runs: accuracy {100 * s['accuracy']:.0f} %**, median held-out shrink over all effect "
        f"runs {s['median_shrink_all_effect_runs']:.2f} (correct verdicts: {s['median_shrink_correct']}), "
        f"second effect named in {s['two_effect_second_named']} of {s['n_two_effect']} two-effect runs; "
        f"median diagnosis time {s['median_wall_time']:.1f} s per run, {s['wall_time_s']:.0f} s in all."
        + (" (quick mode: 3 short runs)" if args.quick else ""),
        "![confusion](confusion.png)", "![shrink](shrink.png)", "## Runs", table])
    log.info("accuracy %.2f, median shrink %.2f -> %s", s["accuracy"], s["median_shrink_all_effect_runs"] or 0,
             args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
