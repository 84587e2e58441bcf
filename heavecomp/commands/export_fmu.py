"""Write the CMC of a parameter file as a co-simulation FMU (FMI 3.0, pythonfmu3): heave in, WOB out.

    heavecomp export-fmu PARAMS.toml --out cmc.fmu

The FMU runs heavecomp's own exact stick-slip stepper with the file's plant effects
(docs/fmu.md: its variables, what it needs where it runs, its validation in fmpy).
"""

from __future__ import annotations


def add_arguments(p) -> None:
    """Add the arguments of ``heavecomp export-fmu`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("params", metavar="PARAMS.toml", help="CMC parameter file ([[effects]] and [active] carried)")
    # dest fmu: --out names a file here, not an output folder (the CLI stages folders named by args.out)
    p.add_argument("--out", dest="fmu", required=True, metavar="FILE.fmu", help="the FMU written")


def run(args) -> int:
    """Run ``heavecomp export-fmu``: check the parameter file and ``--out``, write the FMU.

    Parameters
    ----------
    args : argparse.Namespace
        The arguments of :func:`add_arguments` (``args.fmu``: the FMU file named by ``--out``).
    """
    from pathlib import Path

    from heavecomp.report import paths as _output
    from heavecomp.errors import InputError
    from heavecomp.simulate.fmu import export_fmu

    out = Path(args.fmu)
    if out.suffix.lower() != ".fmu":
        raise InputError(f"--out {out}: an FMU file ends in .fmu")
    _output.out_file(out, "--out")
    export_fmu(args.params, out)
    print(f"FMU (FMI 3.0 co-simulation, heavecomp's stepper inside) -> {out}")
    return 0
