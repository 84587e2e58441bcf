"""Commands the outputs print for the user to copy: shell-quoted, naming the final folders, carrying the log's
column mapping and units (issue 31 item 3)."""

from __future__ import annotations

import shlex


def mapping_text(mapping) -> str:
    """``{"t": "TIME_MS", "wob": "WOB"}`` -> ``"t=TIME_MS,wob=WOB"`` (the inverse of
    :func:`heavecomp.io.series.parse_mapping`).

    Parameters
    ----------
    mapping : dict or None
        Contract name -> column or unit.
    """
    return ",".join(f"{k}={v}" for k, v in (mapping or {}).items())


def command(*words, columns=None, units=None) -> str:
    """One shell command line: ``words`` quoted where needed, then ``--columns``/``--units`` when given.

    Parameters
    ----------
    *words : str or os.PathLike
        The command and its arguments (``"heavecomp", "diagnose", LOG, ...``).
    columns, units : dict or None
        The log's mapping as the user gave it on the command line (empty: no flag).
    """
    argv = [str(w) for w in words]
    if columns:
        argv += ["--columns", mapping_text(columns)]
    if units:
        argv += ["--units", mapping_text(units)]
    return shlex.join(argv)


def span_text(start: float, end: float) -> str:
    """``--span``'s value for the stretch ``start``-``end`` [s from the log's first sample], exact enough that the
    command acts on the same samples (``1200.25:1800``; :func:`heavecomp.diagnosis.span.parse` reads it).

    Parameters
    ----------
    start, end : float [s]
        The stretch.
    """
    return f"{start:.10g}:{end:.10g}"


__all__ = ["command", "mapping_text", "span_text"]
