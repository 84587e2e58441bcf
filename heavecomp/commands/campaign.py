"""Run a sea-state campaign (scatter diagram x friction regimes x variants x seeds): WOB exceedance statistics and report."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp campaign`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("campaign", metavar="CAMPAIGN.toml",
                   help="campaign definition (docs/campaign.md); 'default' = the built-in illustrative campaign")
    p.add_argument("--out", required=True, metavar="DIR", help="results folder (rerun into it to resume)")
    p.add_argument("--format", choices=("netcdf",), default=None,
                   help="also write the results as a labelled array, DIR/campaign.nc (netCDF 3: xarray.Dataset with "
                        "coordinates and units; needs heavecomp[arrays])")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask distributed scheduler, e.g. tcp://10.0.0.5:8786 (needs heavecomp[cluster])")


def run(args) -> int:
    """Run ``heavecomp campaign``: simulate (or resume) the campaign into ``--out`` and write its report
    (:func:`heavecomp.report.campaign.run_and_report`); print the counts and the long-term
    statistics per regime.

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
    from pathlib import Path

    from heavecomp.commands._output import final
    import sys

    from heavecomp.campaign import spec
    from heavecomp.report.campaign import run_and_report
    from heavecomp.commands._progress import Progress
    from heavecomp.errors import InputError

    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be >= 1, got {args.workers}")
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    if args.format:  # the library first: one line before any run, not after the campaign
        from heavecomp.io.arrays import xarray

        xarray()
    camp = spec.default() if args.campaign == "default" else spec.load(args.campaign)
    bar = Progress(f"campaign {camp.settings.name}")
    info, st = run_and_report(camp, args.out, workers=args.workers, scheduler=args.scheduler,
                              progress=lambda done, total: bar(done / total if total else 1.0))
    from heavecomp.report.provenance import finish

    if args.format:
        from heavecomp.campaign.tables import to_xarray
        from heavecomp.io.arrays import write

        write(to_xarray(info.table_path, name=camp.settings.name), Path(info.out_dir) / "campaign.nc")
    finish(info.out_dir, json_files=("metrics.json", "statistics.json"), params_file="campaign.toml",
           csv_files=("runs.csv",))
    print(f"{info.n_simulated} runs simulated, {info.n_skipped} resumed, {info.wall_time:.1f} s "
          f"({info.executor}, {info.workers} workers) -> {Path(final(args)) / info.table_path.name}")
    if st is not None:
        b = st["band_half_width"] / 1e3
        for key, e in st["regime_effect"].items():
            print(f"  {key:28s} long-term time outside +-{b:.0f} kN: {100 * e['frac_outside_band']:6.2f} %   "
                  f"P(leave within {st['exposure']:g} s): {e['p_leave_exposure']:.3f}")
        print(f"report: {Path(final(args)) / 'report.md'}")
    sys.stdout.flush()
    return 0
