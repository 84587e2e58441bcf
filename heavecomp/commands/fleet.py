"""Monitor (and diagnose) a folder of logs, a fleet or a month of one rig, one task per log: local processes or Dask, with resume."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The ``fleet`` subcommand's arguments.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The ``fleet`` subcommand's parser.
    """
    p.add_argument("logs", metavar="DIR", help="folder of logs (files ending in .csv, .txt, .tsv, .dat, .parquet, "
                   ".mat, compressed or not) or a glob pattern in quotes ('logs/**/*.csv.gz')")
    p.add_argument("--params", default=None, metavar="NOMINAL.toml",
                   help="nominal CMC parameter file of every log (unless --manifest gives one per log)")
    p.add_argument("--manifest", default=None, metavar="FLEET.toml",
                   help="parameter file, columns and units for every log or per log (docs/fleet.md)")
    p.add_argument("--columns", default=None, metavar="t=NAME,...",
                   help="map contract columns to the files', e.g. t=Time,heave=MRU_heave,wob=WOB")
    p.add_argument("--units", default=None, metavar="t=ms,...",
                   help="declare units, e.g. t=ms,pressure=bar,wob=kN,stroke=mm")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (fleet.csv, changes.csv, segments.csv, report.md/html, logs/<log>/)")
    p.add_argument("--diagnose", action="store_true",
                   help="diagnose each segment that starts at an effect change (as monitor --diagnose)")
    p.add_argument("--block", type=float, default=None, metavar="S",
                   help="the monitor's statistic block [s] (default 10 s)")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes, one log each at a time (default: all cores)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask distributed scheduler, e.g. tcp://10.0.0.5:8786 (needs heavecomp[cluster])")
    p.add_argument("--format", choices=("netcdf",), default=None,
                   help="also write the results as a labelled array, DIR/fleet.nc (netCDF 3: xarray.Dataset with "
                        "coordinates and units; needs heavecomp[arrays])")
    p.add_argument("--resume", action="store_true",
                   help="keep the logs already finished in --out (by an interrupted run, or a complete one) "
                        "with the same log, parameters and settings; compute the rest")


def run(args) -> int:
    """Run ``heavecomp fleet``: check every log, run (or resume) them, write the summary and report.

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
    import logging
    import shutil
    from pathlib import Path

    from heavecomp.campaign import fleet as F
    from heavecomp.commands._output import final
    from heavecomp.commands._progress import Progress
    from heavecomp.errors import InputError
    from heavecomp.io.series import check_spec, parse_mapping
    from heavecomp.report.fleet import run_and_report
    from heavecomp.report.provenance import finish

    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be >= 1, got {args.workers}")
    if args.block is not None and not args.block > 0:
        raise InputError(f"--block must be > 0 s, got {args.block}")
    if args.workers is not None and args.scheduler:
        raise InputError("--workers and --scheduler: give one (the Dask scheduler has its own workers)")
    if args.format:  # the library first: one line before any log is read
        from heavecomp.io.arrays import xarray

        xarray()
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    columns, units = check_spec(parse_mapping(args.columns, "--columns"), parse_mapping(args.units, "--units"), "cli")
    tasks = F.plan(args.logs, args.params, manifest=args.manifest, columns=columns, units=units)
    settings = F.Settings(diagnose=args.diagnose, block=args.block)
    old = Path(final(args)) / F.RESULTS
    work = Path(args.out) / F.RESULTS
    staged = Path(args.out) != Path(final(args))  # the CLI's staging folder (kept by an interrupted fleet)
    if staged and not args.resume:  # a fresh fleet: nothing an interrupted run left is taken over
        for p in Path(args.out).iterdir():
            if p.is_dir():
                shutil.rmtree(p)
            else:
                p.unlink()
    if args.resume and old.is_dir() and not work.exists():  # resume from a complete earlier result
        shutil.copytree(old, work)
    bar = Progress(f"fleet of {len(tasks)} logs")
    info, summary = run_and_report(tasks, args.out, settings, source=str(args.logs), final_out=final(args),
                                   workers=args.workers,
                                   scheduler=args.scheduler,
                                   progress=lambda done, total: bar(done / total if total else 1.0))
    keep = {t.key for t in tasks}
    for p in work.iterdir():  # results of logs no longer in the fleet, or interrupted writes
        if p.name not in keep:
            shutil.rmtree(p, ignore_errors=True)
    if args.format:
        from heavecomp.io.arrays import write
        from heavecomp.report.fleet import to_xarray

        write(to_xarray(summary, source=str(args.logs)), Path(args.out) / "fleet.nc")
    finish(args.out, json_files=("fleet.json",), params_file=None)
    failed = [r for r in summary["fleet"] if r["status"] != "done"]
    n_eff = sum(c["kind"] == "effect" for c in summary["changes"])
    print(f"{len(tasks)} logs: {info.n_computed} computed, {info.n_skipped} resumed, {len(failed)} failed; "
          f"{n_eff} effect change(s), {len(summary['changes']) - n_eff} operating change(s); {info.wall_time:.1f} s "
          f"({info.executor}, {info.workers} workers) -> {Path(final(args)) / 'fleet.csv'}")
    for r in failed[:5]:
        print(f"  failed: {r['log']}: {r['reason']}")
    ranked = [r for r in summary["fleet"] if r.get("gap rank [-]") not in ("", "-", None)]
    if ranked:
        top = min(ranked, key=lambda r: r["gap rank [-]"])
        print(f"farthest from the model: {top['log']}, gap/noise {top['gap level [-]']:.2f} in {top['gap component']} "
              f"(ranking: {Path(final(args)) / 'report.md'})")
    for c in summary.get("what_next", []):
        print(f"  {c}")
    return 0
