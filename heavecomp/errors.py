"""Exceptions for input that a user can fix.

Every error raised for bad user input (parameter files, measured data, CLI
arguments) derives from :class:`InputError`.  The CLI turns it into a single
line on stderr and exit code 2; library users catch it like a ``ValueError``.
"""

from __future__ import annotations

import difflib


class InputError(ValueError):
    """Bad user input: the message is one line and names the offending key/column.

    Library messages never name a command-line flag (a library user has none).  Instead
    ``option`` names the argument, in the library's terms, that carries the bad value or would
    fix it (``"duration"``, ``"units"``, ``"columns"``; a tuple for several), and ``example`` a
    value for it (``"t=ms"``).  The command line turns them into its own flag, when the command
    has one: ``duration must be ...`` becomes ``--duration must be ...``, and a hint such as
    ``; use --units t=ms`` is added (:func:`heavecomp.cli.message`).

    Parameters
    ----------
    *args : str
        The message (one line), as for ``ValueError``.
    option : str or tuple of str or None
        The library argument(s) that carry the bad value or would fix it.
    example : str or None
        A value for ``option`` that the hint shows.
    """

    def __init__(self, *args, option: str | tuple[str, ...] | None = None, example: str | None = None):
        super().__init__(*args)
        self.option = option
        self.example = example


class ParameterError(InputError):
    """A parameter file or parameter value is invalid."""


class DataError(InputError):
    """Measured data (CSV) is invalid."""


def did_you_mean(word: str, choices) -> str:
    """Return ``" (did you mean 'x'?)"`` for the closest match, or ``""``.

    Parameters
    ----------
    word : str
        The unknown name as given (converted with ``str``).
    choices : iterable
        The known names.
    """
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""
