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
from heavecomp.report import output as _staging

#: name -> (module, one-line help).  Order is the order shown by --help.
COMMANDS: dict[str, tuple[str, str]] = {
    "simulate": ("heavecomp.commands.simulate", "simulate the CMC for a parameter file (exact stick-slip; --controller for active compensation)"),
    "params": ("heavecomp.commands.params", "write or check a parameter file (built-in sets: paper_a, ...)"),
    "analyse": ("heavecomp.commands.analyse", "linear analysis: k_eff_dc, natural frequencies, heave -> WOB frequency response"),
    "diagnose": ("heavecomp.commands.diagnose", "sim-to-real gap diagnosis of a measured run (which unmodelled effect)"),
    "replay": ("heavecomp.commands.replay", "replay a measured log under one or more parameter files as the diagnosis does: gap/noise per file, the log against each model"),
    "monitor": ("heavecomp.commands.monitor", "monitor a long log: when and where the sim-to-real gap appears or changes"),
    "fleet": ("heavecomp.commands.fleet", "monitor (and diagnose) a folder of logs: one summary of segments, components and verdicts per log"),
    "campaign": ("heavecomp.commands.campaign", "run a sea-state campaign: WOB exceedance over a scatter diagram"),
    "stickslip": ("heavecomp.commands.stickslip", "paper B pneumatic cylinder: stick-slip analysis, simulation, map"),
    "identify": ("heavecomp.commands.identify", "identify from measured data: EMPS axis (+ residual diagnosis) or seal friction vs pressure"),
    "export-fmu": ("heavecomp.commands.export_fmu", "write the CMC of a parameter file as a co-simulation FMU (FMI 3.0): heave in, WOB out"),
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
    which import the library, are not loaded: ``heavecomp --help`` stays fast).

    Parameters
    ----------
    only : str or None
        The command whose module is loaded (None: all of them).

    Returns
    -------
    (argparse.ArgumentParser, dict)
        The parser and command name -> its loaded module.
    """
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
    """Run the command line ``argv`` and return its exit code.

    Parameters
    ----------
    argv : list of str or None
        The arguments after ``heavecomp`` (None: ``sys.argv[1:]``).

    Returns
    -------
    int
        The command's code: 0 on success, 2 for bad input (one line on stderr), the no-space code of
        :mod:`heavecomp.report.output` for a disk that filled, 130 when interrupted.
    """
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
        with _staged(args):
            rc = _run(modules[args.command], args)
            if rc:
                raise _Failed(rc)
        return rc
    except _Failed as f:
        return f.code
    except InputError as exc:
        print(f"heavecomp {args.command}: error: {message(exc, _leaf_for(parser, args), args)}", file=sys.stderr)
        return 2
    except OSError as exc:
        if exc.errno not in _staging.NO_SPACE:
            raise
        where = (f"--out {args.out_final}" if getattr(args, "out_final", None)
                 else f"-o {args.output}" if getattr(args, "output", None) else "output")
        print(f"heavecomp {args.command}: error: {_staging.no_space_message(exc, where)}", file=sys.stderr)
        return _staging.EXIT_NO_SPACE
    except KeyboardInterrupt:
        print(f"heavecomp {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` & co.
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


#: library option names whose flag is not ``--<name>``
FLAG_OF = {"out": "--out", "out_dir": "--out", "output": "-o"}


def message(exc: InputError, leaf: argparse.ArgumentParser | None = None, args=None) -> str:
    """The one-line message of ``exc`` as the command line shows it.

    The library names no flag; its ``exc.option`` names the argument (see
    :class:`heavecomp.errors.InputError`).  When this command has that flag, a message starting with
    the option's name (``duration must be ...``) or with its value (``/data/run: holds ...``) starts
    with the flag instead, ``name = `` inside it becomes ``--name = ``, and ``exc.example`` is added
    as ``; use --units t=ms``.  A flag the command lacks is never suggested.  The staging folder
    (``.DIR.partial``) is shown as the ``--out`` the user gave.

    Parameters
    ----------
    exc : heavecomp.errors.InputError
        The library's error.
    leaf : argparse.ArgumentParser or None
        The parser of the command that ran (its flags are the ones that may be named); None: no flag.
    args : argparse.Namespace or None
        The parsed arguments (the values a message may start with, ``out_final``).

    Returns
    -------
    str
    """
    msg = str(exc).strip().replace("\n", " ")
    final = getattr(args, "out_final", None) if args is not None else None
    if final:
        msg = msg.replace(str(_staging.staging_path(final)), str(final))
    opt = getattr(exc, "option", None)
    if not opt:
        return msg
    known = leaf._option_string_actions if leaf is not None else {}  # noqa: SLF001
    pairs = [(n, FLAG_OF.get(n, "--" + n.replace("_", "-"))) for n in ((opt,) if isinstance(opt, str) else opt)]
    pairs = [(n, f) for n, f in pairs if f in known]
    if not pairs:
        return msg
    placed = False
    for n, f in pairs:
        value = final if f == "--out" and final else getattr(args, n, None) if args is not None else None
        spoken = n.replace("_", " ")  # controller_option: "controller option 'x': ..."
        if msg.startswith(f"{spoken} ") and not placed:
            msg, placed = f + msg[len(spoken):], True
        elif value is not None and str(value) and msg.startswith(str(value)) and not placed:
            msg, placed = f"{f} {msg}", True
        if f" {n} = " in msg:
            msg, placed = msg.replace(f" {n} = ", f" {f} = "), True
    example = getattr(exc, "example", None)
    if example:
        return f"{msg}; use {pairs[0][1]} {example}"
    if not placed:
        return f"{msg} ({', '.join(f for _, f in pairs)})"
    return msg


class _Failed(Exception):
    """A command returned a non-zero code: its staged output is dropped."""

    def __init__(self, code: int):
        super().__init__(code)
        self.code = code


def _run(module, args) -> int:
    if getattr(args, "quiet", False):
        return _run_quiet(module, args)
    return int(module.run(args) or 0)


def _staged(args):
    """The command writes into a staging folder beside ``--out``, moved into place when it has
    finished (:mod:`heavecomp.report.output`); ``args.out`` is the staging folder and
    ``args.out_final`` the folder the user named."""
    import contextlib

    if not getattr(args, "out", None):
        return contextlib.nullcontext()

    @contextlib.contextmanager
    def staged():
        st = _staging.Staged(args.out, "--out", resumable=args.command in ("campaign", "fleet"))
        args.out_final = args.out
        with st as work:
            args.out = str(work)
            try:
                yield work
            finally:
                args.out = args.out_final

    return staged()


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
