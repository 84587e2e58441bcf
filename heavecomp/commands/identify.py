"""Identify from measured data: the EMPS axis inverse model (+ residual diagnosis) or seal friction vs pressure.

Writes DIR/metrics.json, DIR/report.md and report.html (self-contained) and the figures.
"""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp identify`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    sub = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    e = sub.add_parser("emps", help="EMPS axis: M, F_v, F_c, offset by inverse-model least squares, "
                                    "then the held-out residual diagnosis")
    e.add_argument("data", metavar="DATA_EMPS.mat", help="EMPS benchmark file (t, qm, qg, vir, gtau)")
    e.add_argument("--out", required=True, metavar="DIR", help="output folder")
    e.add_argument("--cutoff", type=float, default=50.0, metavar="HZ",
                   help="Butterworth cut-off of the position filter [Hz] (default 50)")
    e.add_argument("--order", type=int, default=4, help="Butterworth order (default 4, forward-backward)")
    e.add_argument("--decimate", type=int, default=10, help="parallel-filter decimation factor (default 10)")
    e.add_argument("--split", type=float, default=15.0, metavar="S",
                   help="fit t < S, hold out t >= S for the residual diagnosis [s] (default 15)")
    s = sub.add_parser("seal", help="seal friction F_C + C_p dp over constant-pressure O-ring files")
    s.add_argument("files", nargs="+", metavar="FILE", help="7-column O-ring files (time [ms] ... force [N])")
    s.add_argument("--out", required=True, metavar="DIR", help="output folder")
    s.add_argument("--v-min", type=float, default=2e-3, metavar="M/S", help="sliding speed threshold (default 0.002)")
    s.add_argument("--trim", type=float, default=0.2, help="fraction of each stroke dropped at both ends (default 0.2)")
    s.add_argument("--n-boot", type=int, default=2000, help="bootstrap resamples over strokes (default 2000)")


def run(args) -> int:
    """Run ``heavecomp identify``: the EMPS study (``emps``) or the seal-friction fit (``seal``) written to
    ``--out`` (figures, metrics.json, report), the identified values printed on one line.

    Parameters
    ----------
    args : argparse.Namespace
        The arguments of :func:`add_arguments`; while it runs ``args.out`` is the staging folder and
        ``args.out_final`` the folder the user named.

    Returns
    -------
    int
        Exit code (0).

    Raises
    ------
    heavecomp.errors.InputError
        Bad input (the CLI prints one line and exits 2).
    """
    from pathlib import Path

    from heavecomp.errors import ParameterError
    from heavecomp.report import identification as plots
    from heavecomp.report.figures import save
    from heavecomp.report.provenance import finish
    from heavecomp.report.scenario import write_metrics

    from heavecomp.commands._output import final

    out = Path(args.out)
    if args.kind == "emps":
        from heavecomp.identification.study import emps_study
        from heavecomp.plants.axis import load_emps

        rec = load_emps(args.data)
        if not rec.t[0] + 1.0 < args.split < rec.t[-1] - 1.0:
            raise ParameterError(f"--split must lie inside the record ({rec.t[0] + 1:g} .. {rec.t[-1] - 1:g} s), "
                                 f"got {args.split:g}")
        res = emps_study(rec, cutoff=args.cutoff, order=args.order, decimate=args.decimate, t_split=args.split,
                         sensitivity_cutoffs=(10, 20, 50, 100, 200), sensitivity_decimations=(args.decimate,))
        out.mkdir(parents=True, exist_ok=True)
        m, diag = res["metrics"], res["diagnoser"]
        reg, mv = diag.reg_, diag.mv_
        after = " + ".join(diag.selection_[-1]["effects"]) if diag.selection_ else "none"
        save(plots.emps_overlay(reg.t_d[mv], reg.force_d[mv], reg.force_d[mv] - diag.residual_before_,
                                reg.force_d[mv] - diag.residual_after_, after), out / "overlay.png", dpi=90)
        save(plots.emps_residual_map(reg.dq_d[mv], reg.q_d[mv], diag.residual_before_, diag.residual_after_,
                                     diag.where_, diag.where_after_), out / "residual_map.png", dpi=90)
        save(plots.emps_cutoff_sensitivity(res["sensitivity"]), out / "cutoff_sensitivity.png", dpi=90)
        write_metrics(out, m)
        plots.emps_report(out, m, Path(args.data).name)
        finish(out, inputs=[str(Path(args.data).resolve())])
        p = m["identified_whole_record"]
        best = m["candidates"][0]
        print(f"M = {p['mass']:.3f} kg, F_v = {p['viscous']:.2f} N s/m, F_c = {p['coulomb']:.3f} N, "
              f"offset = {p['offset']:.3f} N (max deviation from published {100 * m['max_abs_relative_error']:.2f} %); "
              f"held-out residual {m['baseline_fit_part']['rms_validate']:.2f} N rms, best effect {best['effect']} "
              f"(shrink {best['shrink']:.3f}) -> {final(args)}")
        return 0

    from heavecomp.identification.study import seal_study
    from heavecomp.identification.seal import SealFrictionFit, load_seal_csv

    if args.n_boot < 10:
        raise ParameterError(f"--n-boot must be at least 10, got {args.n_boot}")
    if not 0.0 <= args.trim < 0.5:
        raise ParameterError(f"--trim must be in [0, 0.5), got {args.trim:g}")
    if not args.v_min > 0:
        raise ParameterError(f"--v-min must be positive, got {args.v_min:g}")
    recs = [load_seal_csv(f) for f in args.files]
    res = seal_study(recs, n_boot=args.n_boot,
                     fit=SealFrictionFit(v_min=args.v_min, trim=args.trim, n_boot=args.n_boot))
    out.mkdir(parents=True, exist_ok=True)
    save(plots.seal_friction_vs_pressure(res["fit"].strokes_, res["fit"].fits_), out / "friction_vs_pressure.png",
         dpi=90)
    m = res["metrics"]
    write_metrics(out, m)
    plots.seal_report(out, m, len(res["fit"].strokes_))
    finish(out, inputs=[str(Path(f).resolve()) for f in args.files])
    print(f"C_p = {m['C_p_N_per_bar']:.3f} +- {m['C_p_uncertainty_N_per_bar']:.3f} N/bar, F_C = {m['F_C_N']:.2f} N "
          f"over {len(res['fit'].strokes_)} strokes -> {final(args)}")
    return 0
