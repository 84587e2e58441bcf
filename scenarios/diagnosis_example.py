"""What does a diagnosis report look like for a rig log whose drill string damps more than the model says?

A 600 s run (JONSWAP sea, sensor noise, paper A parameter set) is generated with quadratic
drag in the drill string — withheld from the diagnosis, whose string-damping candidate is a linear
dashpot — written as a contract CSV, and diagnosed blind against the nominal parameters exactly as
`heavecomp diagnose RUN.csv --params NOMINAL.toml --out DIR` does.
"""

from __future__ import annotations

from heavecomp.diagnosis.data import load_run
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.benchmark import benchmark_case, generate
from heavecomp.report.diagnosis import write_report
from heavecomp.params import dumps
from heavecomp.report.provenance import annotate_json, stamp
from heavecomp.report.scenario import parse_args, run, write_metrics


def build(quick: bool = False, out=None):
    tr = generate(benchmark_case("string_damping", seed=2024, duration=120.0 if quick else 600.0, param_set="paper_a"))
    csv = tr.to_csv(out / "run.csv")
    (out / "nominal.toml").write_text(dumps(tr.nominal, header="nominal parameters given to the diagnosis"))
    d = GapDiagnoser(tr.nominal).fit(load_run(csv, tr.nominal))
    return tr, d


def main(argv=None) -> int:
    args = parse_args(argv, "diagnosis_example", __doc__)
    tr, d = build(args.quick, args.out)
    write_report(d, args.out, title="Diagnosis example: withheld quadratic string drag")
    # as `heavecomp diagnose` does: fit wall times to the untracked timings.json, stamp and units in
    annotate_json(args.out / "diagnosis.json", stamp("nominal.toml"))
    v = d.verdict_
    write_metrics(args.out, {"truth": tr.truth, "verdict": v, "candidates": d.candidates_, "gap": d.gap_,
                             "wall_time_s": d.wall_time_, "quick": args.quick})
    if not args.quick:  # the CSV is reproducible from the seed; keep the committed folder small
        (args.out / "run.csv").unlink()
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
