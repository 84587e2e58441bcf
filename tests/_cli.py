"""``heavecomp ARGS`` run in the test process (:func:`heavecomp.cli.main`), for tests about what a command
writes or refuses rather than about the process boundary.

A subprocess adds only an interpreter's start-up and imports (about 1 s of CPU a command, most of the CPU
of a short command). The boundary itself -- ``--version``, ``--quiet`` as a shell sees it, a killed run, a command started from
another folder -- keeps its subprocess tests (test_cli_messages, test_cli_conventions, test_campaign,
test_fuzz_inputs, test_output_whole). What a subprocess' stderr would show is kept: the package's
log records of WARNING and above go to the captured stderr (where Python's last-resort handler puts
them in a shell), and a Python warning is an error in the suite. An exception escaping ``main`` (a
traceback a user would see) fails the calling test.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import subprocess


def run(*args, cwd=None) -> subprocess.CompletedProcess:
    """``heavecomp *args`` from ``cwd`` (default: the current folder): exit code, stdout and stderr."""
    from heavecomp.cli import main

    out, err = io.StringIO(), io.StringIO()
    shell = logging.StreamHandler(err)
    shell.setLevel(logging.WARNING)
    log = logging.getLogger("heavecomp")
    log.addHandler(shell)
    try:
        with contextlib.chdir(cwd or os.getcwd()), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main([str(a) for a in args])
    finally:
        log.removeHandler(shell)
    return subprocess.CompletedProcess(["heavecomp", *map(str, args)], code, out.getvalue(), err.getvalue())
