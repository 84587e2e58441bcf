"""Does the EMPS inverse model identified here reproduce the published M, F_v, F_c and offset
(within 2 %), and on a held-out part of the record, where does its residual live and which
friction effect shrinks it?

Real data: EMPS benchmark (Janot, Gautier, Brunot 2019), DATA_EMPS.mat, 24.8 s at 1 kHz.
Whole record for the published-values check (as the benchmark does); t < 15 s fitted and
t >= 15 s held out for the residual diagnosis.
"""

from __future__ import annotations

import sys

from heavecomp.data import EMPS
from heavecomp.report import identification as plots
from heavecomp.identification.study import emps_study
from heavecomp.plants.axis import load_emps
from heavecomp.report.figures import save
from heavecomp.report.scenario import parse_args, run, write_metrics, write_report

DATA = EMPS


def build(quick: bool = False, path=DATA) -> dict:
    cutoffs = (10, 20, 50, 100) if quick else (10, 15, 20, 30, 40, 50, 70, 100, 150, 200)
    return emps_study(load_emps(path), sensitivity_cutoffs=cutoffs)


def _findings(m: dict) -> str:
    b, eq = m["baseline_fit_part"]["parameters"], m["asymmetric_coulomb_equivalent"]
    lines = [f"Base model on the fit part: offset {b['offset']:.2f} N + F_c sign(v) is the same as an asymmetric "
             f"Coulomb force F_c+ = {eq['coulomb_positive']:.2f} N, F_c- = {eq['coulomb_negative']:.2f} N (with "
             f"the axis moving the two cannot be told apart: asymmetric_friction's Coulomb column is the offset's, so "
             f"it keeps only its viscous column here)."]
    if "asymmetric_viscous_split" in m:
        a = m["asymmetric_viscous_split"]
        lines.append(f"Best single effect: asymmetric_friction, through its viscous column, F_v+ = {a['viscous_positive']:.1f} N s/m, "
                     f"F_v- = {a['viscous_negative']:.1f} N s/m; with it the offset falls to {a['offset']:.2f} N "
                     f"(F_c = {a['coulomb']:.2f} N): the published offset mostly stands in for a direction-dependent "
                     f"viscous term (its Coulomb column is the offset itself, already in the model).")
    else:
        lines.append(f"Best single effect: {m['best_single']}.")
    return " ".join(lines)


def main(argv=None) -> int:
    args = parse_args(argv, "emps_identification", __doc__,
                      extra=lambda p: p.add_argument("--data", default=str(DATA), help="DATA_EMPS.mat"))
    res = build(args.quick, args.data)
    m, diag = res["metrics"], res["diagnoser"]
    reg, mv = diag.reg_, diag.mv_
    after = " + ".join(diag.selection_[-1]["effects"]) if diag.selection_ else "none"
    save(plots.emps_overlay(reg.t_d[mv], reg.force_d[mv], reg.force_d[mv] - diag.residual_before_,
                            reg.force_d[mv] - diag.residual_after_, after), args.out / "overlay.png", dpi=90)
    save(plots.emps_residual_map(reg.dq_d[mv], reg.q_d[mv], diag.residual_before_, diag.residual_after_,
                                 diag.where_, diag.where_after_), args.out / "residual_map.png", dpi=90)
    save(plots.emps_cutoff_sensitivity(res["sensitivity"]), args.out / "cutoff_sensitivity.png", dpi=90)
    write_metrics(args.out, m)
    w, sel = m["where"], m["selection"]
    write_report(args.out, "EMPS: inverse-model identification and residual diagnosis", [
        __doc__,
        f"Settings: {m['settings']}",
        plots.emps_parameter_table(m),
        "![cut-off](cutoff_sensitivity.png)",
        f"Held-out rms residual of the model fitted on t < {m['split']['fit'][1]:g} s: "
        f"{m['baseline_fit_part']['rms_validate']:.3f} N. Share of squared residual: "
        + ", ".join(f"{k} {v['share']:.2f} (mean {v['mean'] if v['mean'] is None else round(v['mean'], 2)} N)"
                    for k, v in {**w["direction"], **w["motion"]}.items()),
        "![map](residual_map.png)",
        "Candidates: the effect library's classes (the same the CMC diagnosis fits), through their "
        "equation-error features; an effect without a form on this plant (no pressure, no gas, ...) "
        "is left out.",
        plots.candidates_table(m),
        "Candidate parameters (fitted on the fit part, SI):\n\n" + plots.candidate_parameters_table(m),
        "Forward selection (each step chosen by the BIC of the fit part, its shrink measured on the "
        "held-out part): "
        + "; ".join(f"{' + '.join(s['effects'])}: shrink {s['shrink']:.3f}" for s in sel),
        "Open search (sparse regression over physical features of the friction residual, "
        "`discovered`, a suggestion, never a name): " + (f"{m['discovered']['term']} (N), held-out shrink "
                                                         f"{m['discovered']['shrink']:.3f}" if m["discovered"] else "none"),
        _findings(m),
        "![overlay](overlay.png)",
        "**Withheld published terms** (issue 12 item 7): the same diagnosis against a nominal model that "
        "lacks one published term (its value 0, its column not refitted): the Coulomb force F_c, or the "
        "direction asymmetry F_off (with the axis moving, F_off + F_c sign(v) is an asymmetric Coulomb "
        "force F_c+- = F_c +- F_off). The first row is the control (full published model; shown, not scored: the remainder the "
        "published model leaves). Reachable "
        "shrink = 1 - held-out rms of the full nominal / rms before: what restoring the term could give. "
        "Fit and held-out parts as above.",
        plots.withheld_terms_table(m["withheld_terms"]),
    ])
    return 0


if __name__ == "__main__":
    sys.exit(run(main))
