"""What the commands share about their output folder (the staging itself is in :mod:`heavecomp.report.output`)."""

from __future__ import annotations


def final(args) -> str:
    """The output folder as the user named it (``args.out`` is the staging folder while the command runs)."""
    return str(getattr(args, "out_final", None) or args.out)
