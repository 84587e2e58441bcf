"""The command line that produced this process's outputs.

Set once by the entry points (``heavecomp.cli.main`` and the scenarios' ``parse_args``) and read
by :func:`heavecomp.report.provenance.command_line`.  It lives in this import-free module so that
the command-line parser can record it without loading the library (``heavecomp --help`` stays fast).
"""

from __future__ import annotations

#: argv of the command as the user typed it (``None``: use ``sys.argv``)
COMMAND: list[str] | None = None
