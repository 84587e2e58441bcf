"""Output paths checked before any work starts (issue 13.3): one line naming the flag, exit 2.

Used by the commands (`heavecomp.cli`) and the scenario scripts (:mod:`heavecomp.report.scenario`)."""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

from heavecomp.errors import InputError


def _why(exc: OSError) -> str:
    return {errno.EACCES: "permission denied", errno.EPERM: "permission denied", errno.EROFS: "read-only file system",
            errno.ENOSPC: "no space left", errno.ENOTDIR: "a path component is a file",
            errno.ENAMETOOLONG: "name too long", errno.ENOENT: "cannot create files there"}.get(exc.errno,
                                                                                    exc.strerror or type(exc).__name__)


def _probe(folder: Path, flag: str, shown) -> None:
    try:
        fd, name = tempfile.mkstemp(prefix=".heavecomp-probe-", dir=folder)
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise InputError(f"{flag} {shown}: folder not writable ({_why(exc)})") from None


def out_dir(path, flag: str = "--out") -> Path:
    """Check that the output folder ``path`` exists and takes files, or can be created.

    Nothing is created: the nearest existing ancestor is probed with a temporary file.
    Raises :class:`InputError` (one line, naming ``flag``) when ``path`` or an ancestor
    is an existing file, or the folder is not writable.

    Parameters
    ----------
    path : str or os.PathLike
        The output folder.
    flag : str
        The option that named it, first word of a message.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    p = Path(path)
    if len(str(p)) > 4000:
        raise InputError(f"{flag}: path of {len(str(p))} characters is too long")
    if p.exists() and not p.is_dir():
        raise InputError(f"{flag} {path}: is an existing file, not a folder")
    q = p.absolute()
    while not q.exists():
        q = q.parent
    if not q.is_dir():
        raise InputError(f"{flag} {path}: {q} is a file, not a folder")
    _probe(q, flag, path)
    return p


def out_file(path, flag: str = "-o") -> Path:
    """Check that the file ``path`` can be written (its folder exists and is writable).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    flag : str
        The option that named it, first word of a message.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    heavecomp.errors.InputError
        ``path`` is a folder, its folder does not exist, or it cannot be written.
    """
    p = Path(path)
    if p.is_dir():
        raise InputError(f"{flag} {path}: is a folder, not a file")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{flag} {path}: folder {parent} does not exist")
    if p.exists() and not os.access(p, os.W_OK):
        raise InputError(f"{flag} {path}: file not writable")
    _probe(parent, flag, path)
    return p
