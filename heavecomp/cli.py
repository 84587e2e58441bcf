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
from heavecomp.errors import InputError, did_you_mean
from heavecomp.report import invocation
from heavecomp.commands import _progress
from heavecomp.report import paths as _output

#: name -> (module, one-line help).  Order is the order shown by --help.
COMMANDS: dict[str, tuple[str, str]] = {
    "simulate": ("heavecomp.commands.simulate", "simulate the CMC for a parameter file (exact stick-slip; --controller for active compensation)"),
    "params": ("heavecomp.commands.params", "write or check a parameter file (built-in sets: paper_a, ...)"),
    "analyse": ("heavecomp.commands.analyse", "linear analysis: k_eff_dc, natural frequencies, heave -> WOB frequency response"),
    "diagnose": ("heavecomp.commands.diagnose", "sim-to-real gap diagnosis of a measured run (which unmodelled effect)"),
    "monitor": ("heavecomp.commands.monitor", "monitor a long log: when and where the sim-to-real gap appears or changes"),
    "campaign": ("heavecomp.commands.campaign", "run a sea-state campaign: WOB exceedance over a scatter diagram"),
    "stickslip": ("heavecomp.commands.stickslip", "paper B pneumatic cylinder: stick-slip analysis, simulation, map"),
    "identify": ("heavecomp.commands.identify", "identify from measured data: EMPS axis (+ residual diagnosis) or seal friction vs pressure"),
}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors that suggest the closest option for a mistyped flag."""

    argv: list[str] = []

    def error(self, message):  # noqa: D102 - argparse API
        known = [o for o in self._option_string_actions if o.startswith("--")]  # noqa: SLF001
        for tok in self.argv:
            flag = tok.split("=", 1)[0]
            if flag.startswith("--") and flag not in known and not any(k.startswith(flag) for k in known):
                hint = did_you_mean(flag, known)
                if hint:
                    message += f"; unrecognized argument {flag}{hint}"
                    break
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _leaf_parsers(parser: argparse.ArgumentParser):
    """The parsers that take options: ``parser`` itself, or its sub-commands' leaves."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]  # noqa: SLF001
    if not subs:
        yield parser
        return
    for a in subs:
        for p in dict.fromkeys(a.choices.values()):
            yield from _leaf_parsers(p)


def _add_quiet(parser: argparse.ArgumentParser) -> None:
    """``--quiet`` on every command (a command may define its own, e.g. diagnose)."""
    for p in _leaf_parsers(parser):
        if "--quiet" not in p._option_string_actions:  # noqa: SLF001
            p.add_argument("-q", "--quiet", action="store_true",
                           help="no progress and no summary on stdout/stderr (errors still print)")


def _leaf_for(parser: argparse.ArgumentParser, args) -> argparse.ArgumentParser:
    """The (sub-)sub-parser that parsed ``args`` (e.g. ``identify emps``)."""
    for a in parser._actions:  # noqa: SLF001
        if isinstance(a, argparse._SubParsersAction):  # noqa: SLF001
            name = getattr(args, a.dest, None)
            if name in a.choices:
                return _leaf_for(a.choices[name], args)
    return parser


def _unknown_arguments(parser, args, extra) -> str:
    """One line for unrecognised arguments, with the closest option of the command."""
    leaf = _leaf_for(parser, args)
    flags = [o for o in leaf._option_string_actions if o.startswith("--")]  # noqa: SLF001
    first = next((e for e in extra if e.startswith("-")), extra[0])
    hint = did_you_mean(first.split("=", 1)[0], flags) if first.startswith("-") else ""
    return f"unrecognized argument{'s' if len(extra) > 1 else ''}: {' '.join(extra)}{hint}"


def build_parser(only: str | None = None) -> tuple[argparse.ArgumentParser, dict]:
    """The parser; with ``only`` the arguments of that command alone (the others' modules,
    which import the library, are not loaded: ``heavecomp --help`` stays fast)."""
    parser = _Parser(
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
        _add_quiet(p)
        modules[name] = mod
    return parser, modules


def main(argv: list[str] | None = None) -> int:
    words = list(sys.argv[1:] if argv is None else argv)
    parser, modules = build_parser(next((w for w in words if not w.startswith("-")), ""))
    _Parser.argv = words
    invocation.COMMAND = ["heavecomp", *_Parser.argv]
    args, extra = parser.parse_known_args(argv)
    if not args.command:
        parser.print_help()
        return 2
    if extra:
        print(f"heavecomp {args.command}: error: {_unknown_arguments(parser, args, extra)}", file=sys.stderr)
        return 2
    try:
        _check_outputs(args)
        if getattr(args, "quiet", False):
            return _run_quiet(modules[args.command], args)
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


def _check_outputs(args) -> None:
    """``--out DIR`` and ``params -o FILE`` checked before any work (one line, exit 2)."""

    if getattr(args, "out", None):
        _output.out_dir(args.out, "--out")
    if args.command == "params" and getattr(args, "output", None):
        _output.out_file(args.output, "-o")


def _run_quiet(module, args) -> int:
    """Run a command with progress bars off, summaries dropped and INFO logging off.

    ``params`` without ``-o`` writes its TOML to stdout: that is the output, not a
    summary, so it is kept.
    """
    import contextlib
    import io
    import logging


    _progress.QUIET = True
    logging.getLogger("heavecomp").setLevel(logging.WARNING)
    if args.command == "params" and not getattr(args, "output", None):
        return int(module.run(args) or 0)
    with contextlib.redirect_stdout(io.StringIO()):
        return int(module.run(args) or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
