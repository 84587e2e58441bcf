"""Write a built-in parameter set as TOML, or check a parameter file."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("source", metavar="NAME|PARAMS.toml",
                   help="a built-in set (paper_a) or a parameter file to check")
    p.add_argument("--friction", default=None, metavar="MODEL", help="friction model for a built-in set")
    p.add_argument("-o", "--output", default=None, metavar="FILE", help="write here instead of stdout")


def run(args) -> int:
    import sys
    from pathlib import Path

    from heavecomp.errors import ParameterError, did_you_mean
    from heavecomp.params import SETS, dumps, load

    if args.output:
        _check_output(Path(args.output))
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
        from heavecomp.simulate.core import default_dt, plant_eigen_rate

        h = default_dt(params)
        check_default_step(params, h, plant_eigen_rate)
        print(f"{args.source}: valid (k_eff = {params.k_eff:.6g} N/m, p_0 = {params.p0:.6g} Pa, "
              f"V_0 = {params.gas_volume:.4g} m^3, default step {h:.3g} s)", file=sys.stderr)
    else:
        raise ParameterError(f"{args.source}: not a built-in set nor a file{did_you_mean(args.source, SETS)}; "
                             f"built-in sets: {', '.join(SETS)}")
    text = dumps(params, header=header)
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


def _check_output(path) -> None:
    """One-line :class:`ParameterError` for an output path that cannot be written (before any work)."""
    import os
    from pathlib import Path

    from heavecomp.errors import ParameterError

    if path.is_dir():
        raise ParameterError(f"-o {path}: is a folder; give a file name, e.g. {path / 'params.toml'}")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise ParameterError(f"-o {path}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise ParameterError(f"-o {path}: not writable")
