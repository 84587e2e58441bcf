"""The ``heavecomp`` command line.

Each sub-command lives in ``heavecomp/commands/<name>.py`` and defines
``add_arguments(parser)`` and ``run(args) -> int``.  Command modules import
only ``argparse`` at module level so that ``heavecomp --help`` stays fast;
heavy imports happen inside ``run``.

Bad input (any :class:`heavecomp.errors.InputError`) is printed as one line,
``heavecomp <command>: error: <message>``, and the exit code is 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from heavecomp import __version__
from heavecomp.errors import InputError

#: name -> (module, one-line help).  Order is the order shown by --help.
COMMANDS: dict[str, tuple[str, str]] = {
    "simulate": ("heavecomp.commands.simulate", "simulate the CMC for a parameter file (exact stick-slip; --controller for active compensation)"),
    "params": ("heavecomp.commands.params", "write or check a parameter file (built-in sets: paper_a, ...)"),
    "analyse": ("heavecomp.commands.analyse", "linear analysis: k_eff_dc, natural frequencies, heave -> WOB frequency response"),
    "diagnose": ("heavecomp.commands.diagnose", "sim-to-real gap diagnosis of a measured run (which unmodelled effect)"),
    "campaign": ("heavecomp.commands.campaign", "run a sea-state campaign: WOB exceedance over a scatter diagram"),
    "stickslip": ("heavecomp.commands.stickslip", "paper B pneumatic cylinder: stick-slip analysis, simulation, map"),
    "identify": ("heavecomp.commands.identify", "identify from measured data: EMPS axis (+ residual diagnosis) or seal friction vs pressure"),
}


def build_parser(only: str | None = None) -> tuple[argparse.ArgumentParser, dict]:
    """The parser; with ``only`` the arguments of that command alone (the others' modules,
    which import the library, are not loaded: ``heavecomp --help`` stays fast)."""
    parser = argparse.ArgumentParser(
        prog="heavecomp",
        description="heavecomp: heave compensation of offshore drilling rigs "
        "(CMC plant, linear analysis, MPC, sim-to-real gap diagnosis).",
    )

    parser.add_argument("--version", action="version", version=f"heavecomp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    modules = {}
    for name, (modname, helptext) in COMMANDS.items():
        if only is not None and name != only:
            sub.add_parser(name, help=helptext, description=helptext)
            continue
        mod = importlib.import_module(modname)
        p = sub.add_parser(name, help=helptext, description=(mod.__doc__ or helptext).strip().splitlines()[0])
        mod.add_arguments(p)
        modules[name] = mod
    return parser, modules


def main(argv: list[str] | None = None) -> int:
    words = sys.argv[1:] if argv is None else argv
    parser, modules = build_parser(next((w for w in words if not w.startswith("-")), ""))
    args = parser.parse_args(argv)
    if not args.command:
        parser.print_help()
        return 2
    try:
        return int(modules[args.command].run(args) or 0)
    except InputError as exc:
        msg = str(exc).strip().replace("\n", " ")
        print(f"heavecomp {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"heavecomp {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` & co.
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
