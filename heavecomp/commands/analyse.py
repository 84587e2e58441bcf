"""Linear analysis of the CMC: k_eff_dc, natural frequencies, damping ratios and the heave -> WOB frequency response.

Writes DIR/analysis.json, DIR/frequency_response.csv, DIR/bode.png and DIR/report.md.
"""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp analyse`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("params", metavar="PARAMS.toml", help="CMC parameter file (contract: docs/contracts/parameter-file.md)")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--points", type=int, default=1000, metavar="N",
                   help="number of log-spaced frequencies (default 1000)")
    p.add_argument("--omega-min", type=float, default=1e-3, metavar="RAD_S",
                   help="lowest angular frequency [rad/s] (default 1e-3)")
    p.add_argument("--omega-max", type=float, default=None, metavar="RAD_S",
                   help="highest angular frequency [rad/s] (default 10x the fastest pole)")
    p.add_argument("--sliding-velocity", type=float, default=None, metavar="M_S",
                   help="also linearise the file's friction law about this constant stroke velocity [m/s]")


def _check(args):
    import math

    from heavecomp.errors import InputError

    if not (2 <= args.points <= 1_000_000):
        raise InputError(f"--points must be between 2 and 1000000, got {args.points}")
    if not (args.omega_min > 0 and math.isfinite(args.omega_min)):
        raise InputError(f"--omega-min must be a positive number of rad/s, got {args.omega_min}")
    if args.omega_max is not None and not (math.isfinite(args.omega_max) and args.omega_max > args.omega_min):
        raise InputError(f"--omega-max must be a finite number of rad/s above --omega-min, got {args.omega_max}")
    v = args.sliding_velocity
    if v is not None and not (math.isfinite(v) and v != 0.0):
        raise InputError(f"--sliding-velocity must be a non-zero number of m/s, got {v}")


def run(args) -> int:
    """Run ``heavecomp analyse``: the linear analysis of the parameter file written to ``--out``
    (:func:`heavecomp.report.analysis.write_analysis`), its summary printed on one line.

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

    from heavecomp.report.analysis import write_analysis
    from heavecomp.effects.spec import load  # the file with its [[effects]] checked

    _check(args)
    params = load(args.params, heave_file=False)  # the analysis takes no heave from the file
    s = write_analysis(params, args.out, source=f"({Path(args.params).name})", n_points=args.points,
                       omega_min=args.omega_min, omega_max=args.omega_max, sliding_velocity=args.sliding_velocity)
    from heavecomp.report.provenance import finish

    finish(args.out, params=params, json_files=("analysis.json",), heave_used=False, csv_files=("frequency_response.csv",))
    from heavecomp.report.analysis import mode_rows
    from heavecomp.commands._output import final

    modes = "; ".join(f"{n} {w:.3f} rad/s (zeta {z:.4f})"
                      for n, w, f, T, z in mode_rows(s["natural_frequencies"], s["damping_ratios"]))
    from heavecomp.analysis.summary import accounting_line

    said = accounting_line(s.get("effects"))
    if said:
        print(said)
    print(f"k_eff_dc {s['k_eff_dc'] / 1e3:.3f} kN/m (eq. 14: {s['k_eff_eq14'] / 1e3:.3f}), natural frequencies: "
          f"{modes} -> {final(args)}")
    return 0
