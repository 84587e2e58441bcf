"""Monitor a long measured log: when and where the sim-to-real gap appears or changes, segment by segment."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The ``monitor`` subcommand's arguments.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The ``monitor`` subcommand's parser.
    """
    p.add_argument("run", metavar="LOG", help="measured log: columns t, heave, stroke, pressure, wob; CSV (any "
                   "delimiter, decimal comma, .gz/.bz2/.xz/.zip), Parquet or .mat (docs/contracts/measured-run.md)")
    p.add_argument("--columns", default=None, metavar="t=NAME,...",
                   help="map contract columns to the file's, e.g. t=Time,heave=MRU_heave,wob=WOB")
    p.add_argument("--units", default=None, metavar="t=ms,...",
                   help="declare units, e.g. t=ms,pressure=bar,wob=kN,stroke=mm (converted to SI and recorded)")
    p.add_argument("--params", required=True, metavar="NOMINAL.toml", help="nominal CMC parameter file")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (monitor.json, report.md/html, timeline.png)")
    p.add_argument("--block", type=float, default=None, metavar="S",
                   help="statistic block [s] (default 10 s, about one wave period)")
    p.add_argument("--diagnose", action="store_true",
                   help="diagnose each segment that starts at an effect change (the gap diagnosis on its first "
                        "600 s; segments[].verdict in monitor.json, segment_<i>/diagnosis.json)")
    p.add_argument("--jobs", type=int, default=1, metavar="N", help="candidates fitted concurrently by --diagnose")
    p.add_argument("--format", choices=("netcdf",), default=None,
                   help="also write the results as a labelled array, DIR/monitor.nc (netCDF 3: xarray.Dataset with "
                        "coordinates and units; needs heavecomp[arrays])")


def run(args) -> int:
    """Monitor the log (and with ``--diagnose`` diagnose its segments); returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of :func:`add_arguments`.
    """
    import sys
    import time
    from pathlib import Path

    from heavecomp.commands._output import final
    from heavecomp.diagnosis import monitor as M
    from heavecomp.diagnosis.data import load_run
    from heavecomp.errors import InputError
    from heavecomp.io.series import check_spec, parse_mapping
    from heavecomp.effects.spec import load  # the file with its [[effects]] checked
    from heavecomp.report.monitor import diagnosed_lines, write_report
    from heavecomp.report.provenance import finish

    columns, units = check_spec(parse_mapping(args.columns, "--columns"), parse_mapping(args.units, "--units"),
                                "cli")
    params = load(args.params, heave_file=False)  # the log carries the heave: an unused heave file may be absent
    block = M.BLOCK if args.block is None else args.block
    if not block > 0:
        raise InputError(f"--block must be > 0 s, got {args.block}")
    if args.jobs < 1:
        raise InputError(f"--jobs must be >= 1, got {args.jobs}")
    if args.format:  # the library first: one line before the log is read
        from heavecomp.io.arrays import xarray

        xarray()
    run_ = load_run(args.run, params, columns=columns, units=units)
    if run_.duration < M.MIN_DURATION:
        raise InputError(f"{run_.source}: column 't': the log spans {run_.duration:.3g} s; monitor needs at least "
                         f"{M.MIN_DURATION:g} s (a reference stretch and a few blocks to compare)")
    t0 = time.perf_counter()

    def progress(frac, msg):
        if not getattr(args, "quiet", False):
            print(f"[{time.perf_counter() - t0:6.1f} s {100 * frac:3.0f} %] {msg}", file=sys.stderr, flush=True)

    res = M.monitor(run_, params, block=block, progress=progress)
    spans = {}

    def write_segment(i, d, sub, ab):
        # what `heavecomp diagnose LOG --span A:B` writes: diagnosis.json, report, figures, calibrated.toml
        from heavecomp.commands.diagnose import write_outputs
        from heavecomp.diagnosis import span as SP

        spans[i] = ab
        write_outputs(d, Path(args.out) / f"segment_{i}", params=params, run=sub, run_path=args.run,
                      params_path=args.params, span=SP.segment(run_.duration, *ab, i, min_duration=M.DIAGNOSE_MIN),
                      columns=columns, units=units, shown_dir=str(Path(final(args)) / f"segment_{i}"))
        print(f"segment {i} ({ab[0]:.0f}-{ab[1]:.0f} s): {d.verdict_['effect']} (confidence "
              f"{d.verdict_.get('confidence')}) -> {Path(final(args)) / f'segment_{i}'}", file=sys.stderr, flush=True)

    diagnoses = (M.diagnose_segments(res, run_, params, n_jobs=args.jobs, progress=progress, each=write_segment)
                 if args.diagnose else {})
    for i, (a, b) in spans.items():  # where the segment's full diagnosis is
        res.segments[i]["verdict"]["folder"] = f"segment_{i}"
    write_report(res, args.out, source=run_.source, extra={"measurement": run_.measurement} if run_.measurement else None,
                 diagnosed=diagnosed_lines(spans, args.run, args.params, final(args), columns=columns,
                                           units=units))
    if args.format:  # from monitor.json as written (the segments' verdicts included)
        import json

        from heavecomp.io.arrays import monitor_dataset, write

        mon = json.loads((Path(args.out) / "monitor.json").read_text(encoding="utf-8"))
        write(monitor_dataset(mon, {"source": str(run_.source)}), Path(args.out) / "monitor.nc")
    finish(args.out, params=params, json_files=("monitor.json",), heave_used=False, measured_run=str(Path(args.run).resolve()))
    for e, chans in res.skipped.get("equations", {}).items():
        print(f"left out the {e} residual: the log has no {', '.join(chans)} channel", file=sys.stderr)
    for note in res.notes:
        print(f"note: {note}", file=sys.stderr)
    eff = [c for c in res.changes if c["kind"] == "effect"]
    ops = [c for c in res.changes if c["kind"] == "operating"]
    print(f"{len(eff)} effect change(s), {len(ops)} operating change(s), {len(res.segments)} segment(s)"
          + "".join(f"; {c['component']} at {c['t']:.0f} s" for c in eff[:5])
          + "".join(f"; segment {i}: {res.segments[i]['verdict']['effect']}" for i in diagnoses)
          + f" -> {Path(final(args)) / 'monitor.json'}")
    return 0
