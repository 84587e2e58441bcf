"""Replay a measured log under one or more parameter files, exactly as the diagnosis replays it: gap over the noise floor per channel and file, the whole log against each model, the files ranked."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp replay`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("run", metavar="LOG", help="measured log: columns t, heave, stroke, pressure, wob; CSV (any "
                   "delimiter, decimal comma, .gz/.bz2/.xz/.zip), Parquet or .mat (docs/contracts/measured-run.md)")
    p.add_argument("--params", required=True, action="append", metavar="FILE.toml",
                   help="a parameter file to replay the log under; repeat it for several (e.g. the nominal and "
                        "a diagnosis' calibrated.toml): the first is the reference of the shrink")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (replay.json, overlay.png, report.md/html)")
    p.add_argument("--columns", default=None, metavar="t=NAME,...",
                   help="map contract columns to the file's, e.g. t=Time,heave=MRU_heave,wob=WOB "
                        "(overrides each file's [measurement] columns)")
    p.add_argument("--units", default=None, metavar="t=ms,...",
                   help="declare units, e.g. t=ms,pressure=bar,wob=kN,stroke=mm (overrides [measurement] units)")
    p.add_argument("--window", default=None, metavar="START:END",
                   help="zoom of overlay.png, in s of the replayed span (default: the whole span)")
    p.add_argument("--span", default=None, metavar="START:END",
                   help="the stretch of the log replayed, in s from its first sample (default as diagnose: a log up "
                        "to 1200 s whole, a longer one its last 600 s)")
    p.add_argument("--split", type=float, default=0.67, metavar="F",
                   help="fraction of the span in the fit part; the rest is held out (default 0.67, as diagnose)")
    p.add_argument("--settle", type=float, default=None, metavar="S",
                   help="start-up window left out [s] (default as diagnose: min(30 s, 10 %% of the span))")


def run(args) -> int:
    """Run ``heavecomp replay`` (:func:`heavecomp.diagnosis.replay_files`): ``replay.json``, ``overlay.png``
    and ``report.md``/``report.html`` in ``--out``, the ranking on one line.

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
    from pathlib import Path

    from heavecomp.commands._output import final
    from heavecomp.diagnosis import span as SP
    from heavecomp.diagnosis.compare import replay_files
    from heavecomp.effects.spec import load
    from heavecomp.errors import InputError
    from heavecomp.io.series import check_spec, parse_mapping
    from heavecomp.report.commands import command
    from heavecomp.report.provenance import finish
    from heavecomp.report.replay import write_report

    columns, units = check_spec(parse_mapping(args.columns, "--columns"), parse_mapping(args.units, "--units"),
                                "cli")
    if not 0.2 <= args.split <= 0.9:
        raise InputError(f"--split must be between 0.2 and 0.9, got {args.split}")
    if args.settle is not None and not args.settle >= 0:
        raise InputError(f"--settle must be >= 0 s, got {args.settle}")
    window = _window(args.window)
    span = SP.parse(args.span)
    files = [load(p, heave_file=False) for p in args.params]  # every file checked before the log is read
    cmp = replay_files(args.run, files, names=args.params, columns=columns, units=units, split=args.split,
                       settle=args.settle, span=span, window=window,
                       progress=None if args.quiet else lambda f, m: print(f"replay: {m}", file=sys.stderr, flush=True))
    out = Path(final(args))
    best = cmp.ranking()[0]
    cmds = [command("heavecomp", "diagnose", args.run, "--params", best, "--out", out / "diagnosis_best",
                    columns=columns, units=units)]
    d = write_report(cmp, args.out, window=cmp.window, commands=cmds)
    finish(args.out, json_files=("replay.json",), params_file=None, measured_run=str(Path(args.run).resolve()),
           params_files=[str(Path(p).resolve()) for p in args.params])
    _contract_units(Path(args.out) / "replay.json", d["units"])
    pc = d["channel"]
    by = {m["params"]: m for m in d["models"]}
    print("; ".join(f"{n}: {pc} gap/noise held-out {by[n]['gap_to_noise_validate'][pc]:.2f}, shrink "
                    f"{by[n]['shrink_validate']:+.2f}" for n in d["ranking"])
          + f" -> {out / 'replay.json'}")
    return 0


def _contract_units(path, units: dict) -> None:
    """Put the contract's ``units`` blocks (``units.rms`` ...) back beside the provenance's unit of every key."""
    import json

    d = json.loads(path.read_text(encoding="utf-8"))
    d["units"] = {**d.get("units", {}), **units}
    path.write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")


def _window(text):
    """``--window START:END`` -> (start, end) [s] (either None), one-line errors."""
    from heavecomp.diagnosis import span as SP
    from heavecomp.errors import InputError

    try:
        return SP.parse(text)
    except InputError as exc:
        raise InputError("--window" + str(exc)[len("span"):]) from None
