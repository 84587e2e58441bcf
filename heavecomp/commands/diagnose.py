"""Diagnose the sim-to-real gap of a measured CMC run: where it lies, which unmodelled effect causes it, how far it shrinks."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp diagnose`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("run", metavar="RUN", help="measured run: columns t, heave, stroke, pressure, wob; CSV (any "
                   "delimiter, decimal comma, .gz/.bz2/.xz/.zip), Parquet or .mat (docs/contracts/measured-run.md)")
    p.add_argument("--columns", default=None, metavar="t=NAME,...",
                   help="map contract columns to the file's, e.g. t=Time,heave=MRU_heave,wob=WOB "
                        "(overrides [measurement] columns)")
    p.add_argument("--units", default=None, metavar="t=ms,...",
                   help="declare units, e.g. t=ms,pressure=bar,wob=kN,stroke=mm (converted to SI and recorded; "
                        "overrides [measurement] units)")
    p.add_argument("--params", required=True, metavar="NOMINAL.toml", help="nominal CMC parameter file")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (diagnosis.json, report.md, PNGs)")
    p.add_argument("--candidates", default=None, metavar="A,B",
                   help="comma-separated effect names (default: all)")
    p.add_argument("--split", type=float, default=0.67, metavar="F", help="fraction of the run fitted (default 0.67)")
    p.add_argument("--settle", type=float, default=None, metavar="S",
                   help="start-up window left out of the residuals [s] (default min(30 s, 10 %% of the run))")
    p.add_argument("--span", default=None, metavar="START:END",
                   help="the stretch of the log diagnosed, in s from its first sample (e.g. 3600:4200; either end "
                        "may be left out). Default: a log up to 1200 s whole, a longer one its last 600 s, said in "
                        "the report and diagnosis.json; heavecomp monitor follows the whole log")
    p.add_argument("--jobs", type=int, default=2, metavar="N", help="candidates fitted concurrently (default 2)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress output")


def run(args) -> int:
    """Run ``heavecomp diagnose``: the measured run read and checked against the nominal parameter
    file, the gap diagnosed (:class:`heavecomp.diagnosis.GapDiagnoser`, which replays the file's plant effects too), ``diagnosis.json``,
    ``report.md`` and ``calibrated.toml`` written to ``--out`` and the verdict printed on one line.

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
    import sys
    import time
    from pathlib import Path

    from heavecomp.diagnosis.data import load_run
    from heavecomp.diagnosis.estimator import GapDiagnoser, check_memory
    from heavecomp.errors import InputError
    from heavecomp.io.series import check_spec, parse_mapping
    from heavecomp.effects.spec import load  # the file with its [[effects]] checked

    columns, units = check_spec(parse_mapping(args.columns, "--columns"), parse_mapping(args.units, "--units"),
                                "cli")
    params = load(args.params, heave_file=False)  # the log carries the heave: an unused heave file may be absent
    cands = None
    if args.candidates:
        from heavecomp.effects import get

        cands = [c.strip() for c in args.candidates.split(",") if c.strip()]
        for c in cands:
            get(c)  # unknown names fail before any work
    if args.jobs < 1:
        raise InputError(f"--jobs must be >= 1, got {args.jobs}")
    from heavecomp.diagnosis import span as SP

    wanted = SP.parse(args.span)  # a malformed span fails before the log is read
    from heavecomp.io.series import estimate_rows, short
    from heavecomp.params.budget import check_read_memory

    check_read_memory(estimate_rows(args.run), source=short(args.run))  # the whole-log pass, before reading
    run_ = load_run(args.run, params, columns=columns, units=units)  # read in chunks, checked whole
    SP.check_length(run_, "diagnose", "run")
    span = SP.choose(run_.duration, wanted)
    run_ = SP.cut(run_, span)  # the whole log's arrays are dropped here
    check_memory(run_, params, args.jobs)  # the whole diagnosis' memory (fit checks it too): refused in one line
    if not span.whole:  # never silent, --quiet or not
        print(f"diagnose: {span.reason}; --span START:END names another", file=sys.stderr, flush=True)
    t0 = time.perf_counter()

    def progress(frac, msg):
        if not args.quiet:
            print(f"[{time.perf_counter() - t0:6.1f} s {100 * frac:3.0f} %] {msg}", file=sys.stderr, flush=True)

    d = GapDiagnoser(params, cands, split=args.split, settle=args.settle, n_jobs=args.jobs, progress=progress)
    d.fit(run_)
    from heavecomp.commands._output import final

    cal = write_outputs(d, args.out, params=params, run=run_, run_path=args.run, params_path=args.params, span=span,
                        columns=columns, units=units, shown_dir=final(args))
    v = d.verdict_
    extra = f", second effect {v['second_effect']['effect']}" if v.get("second_effect") else ""
    from heavecomp.diagnosis.verdict import label

    print(f"verdict: {label(v)} (confidence {v['confidence']}), held-out shrink {v['shrink']:.2f} "
          f"on {v.get('shrink_channel', 'wob')}{extra} -> {Path(final(args)) / 'diagnosis.json'}, calibrated model "
          f"({len(cal.changes)} change{'s' if len(cal.changes) != 1 else ''}) -> {Path(final(args)) / 'calibrated.toml'}")
    return 0


def write_outputs(d, out, *, params, run, run_path, params_path, span=None, columns=None, units=None,
                  shown_dir=None):
    """What ``heavecomp diagnose`` writes into its folder ``out`` for a fitted diagnosis ``d``:
    ``diagnosis.json`` with how the log was read and the span analysed, ``report.md`` and its figures,
    ``calibrated.toml`` with its "What next", and the provenance stamp and ``report.html``
    (:func:`heavecomp.report.provenance.finish`).  ``heavecomp monitor --diagnose`` writes each diagnosed
    segment with it.  Returns the :class:`heavecomp.report.calibrated.Calibrated`.

    Parameters
    ----------
    d : heavecomp.diagnosis.GapDiagnoser
        Fitted on ``run``.
    out : str or Path
        The folder (created).
    params : CMCParams
        The nominal parameters it was diagnosed against.
    run : MeasuredRun
        The log (or its span) as the diagnosis read it.
    run_path, params_path : str
        The log and the parameter file as the user named them.
    span : heavecomp.diagnosis.span.Span, optional
        The stretch of the log analysed.
    columns, units : dict, optional
        The mapping the log was read with (``--columns``/``--units``): ``calibrated.toml`` records it, so its
        re-diagnosis needs no flags.
    shown_dir : str, optional
        The folder as the user named it (the printed commands name it; default ``out``).
    """
    from heavecomp.params.measurement import used
    from heavecomp.report.calibrated import write_calibrated  # calibrated.toml, its json block, "What next"
    from heavecomp.report.diagnosis import write_report
    from heavecomp.report.provenance import finish

    write_report(d, out, title=f"Sim-to-real gap diagnosis — {run.source}")
    _record_measurement(Path(out) / "diagnosis.json", run.measurement, span.to_json() if span is not None else None)
    cal = write_calibrated(used(params, columns, units), out, run_path=run_path, params_path=params_path, run=run,
                           policy=d.verdict_policy(), shown_dir=str(shown_dir or out), columns=columns, units=units,
                           span=span)
    finish(out, params=params, json_files=("diagnosis.json",), heave_used=False,
           measured_run=str(Path(run_path).resolve()))
    return cal


def _record_measurement(path: Path, measurement: dict, span: dict | None = None) -> None:
    """Add how the run was read (format, columns, units, conversions) and which span of it was analysed
    (:mod:`heavecomp.diagnosis.span`) to diagnosis.json."""
    import json

    if not (measurement or span) or not path.is_file():
        return
    d = json.loads(path.read_text(encoding="utf-8"))
    if measurement:
        d["measurement"] = measurement
    if span:
        d["span"] = span
    path.write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")
