"""Write a built-in parameter set as TOML, or check a parameter file."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp params`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("source", metavar="NAME|PARAMS.toml",
                   help="a built-in set (paper_a) or a parameter file to check")
    p.add_argument("--friction", default=None, metavar="MODEL", help="friction model for a built-in set")
    p.add_argument("-o", "--output", default=None, metavar="FILE", help="write here instead of stdout")


def run(args) -> int:
    """Run ``heavecomp params``: a built-in set or a checked copy of a parameter file, as TOML on stdout or
    written whole to ``-o``.

    Parameters
    ----------
    args : argparse.Namespace
        The arguments of :func:`add_arguments`.

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

    from heavecomp.errors import ParameterError, did_you_mean
    from heavecomp.params import SETS, dumps
    from heavecomp.effects.spec import load  # the file with its [[effects]] checked

    if args.source in SETS:
        factory = SETS[args.source]
        params = factory(args.friction) if args.friction else factory()
        header = f"heavecomp built-in parameter set '{args.source}'\n" + (factory.__doc__ or "").split("\n")[0]
    elif Path(args.source).suffix == ".toml" or Path(args.source).exists():
        params = load(args.source)
        if args.friction:
            params = params.replace(friction={"model": args.friction})
        header = f"checked copy of {args.source}"
        from heavecomp.params.budget import check_default_step
        from heavecomp.plants.cmc import eigen_rate
        from heavecomp.simulate.core import default_dt

        h = default_dt(params)
        check_default_step(params, h, eigen_rate)
        if getattr(args, "quiet", False) and not args.output:
            return 0  # a check asked quietly: the exit code is the answer (the TOML is written with -o)
        if not getattr(args, "quiet", False):
            print(f"{args.source}: valid (k_eff = {params.k_eff:.6g} N/m, p_0 = {params.p0:.6g} Pa, "
                  f"V_0 = {params.gas_volume:.4g} m^3, default step {h:.3g} s){_effects_line(params)}",
                  file=sys.stderr)
    else:
        raise ParameterError(f"{args.source}: not a built-in set nor a file{did_you_mean(args.source, SETS)}; "
                             f"built-in sets: {', '.join(SETS)}")
    params = _heave_path_for(params, args.output)
    text = dumps(params, header=header)
    if args.output:
        from heavecomp.report.output import write_text_atomic

        write_text_atomic(args.output, text)
    else:
        sys.stdout.write(text)
    return 0


def _effects_line(params) -> str:
    """``; [[effects]]: string_damping (plant), sensor_gain on wob (reading)`` for a file that has effects: what
    every command then simulates (the plant effects) and how a log is read (the reading effects)."""
    from heavecomp.effects.spec import check

    fx = check(params)
    if not fx:
        return ""
    words = [f"{e.name}{f' on {e.channel}' if getattr(e, 'channel', None) else ''} "
             f"({'plant' if e.kind == 'plant' else 'reading'})" for e in fx]
    return f"; {len(fx)} [[effects]]: {', '.join(words)}"


def _heave_path_for(params, output):
    """A relative ``heave.path`` re-pointed for the file being written: relative to the output's
    folder when writing a file, absolute on stdout (where the file lands is unknown)."""
    import os
    from pathlib import Path

    h = params.heave
    if h is None or h.kind != "file" or not h.path or Path(h.path).is_absolute() or params.base_dir is None:
        return params
    src = (Path(params.base_dir) / h.path).resolve()
    if output:
        new = os.path.relpath(src, Path(output).resolve().parent)
    else:
        new = str(src)
    return params.replace(heave={"path": Path(new).as_posix()})

