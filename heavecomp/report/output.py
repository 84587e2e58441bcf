"""Output folders that are whole or absent (issue 21.3).

A command never writes into its ``--out DIR`` directly.  :class:`Staged`

1. takes a lock beside it, ``.DIR.lock`` (an ``flock`` on a file holding the owner's pid): a
   second process on the same ``DIR`` is refused in one line while the first runs; the lock of a
   process that died is free again (the kernel drops an ``flock`` with its owner), so a stale lock
   file is simply taken over;
2. hands the command a staging folder beside it, ``.DIR.partial``, on the same file system;
3. when the command has finished, moves the staging folder into place in one step: an absent
   ``DIR`` by ``rename``, an existing one by an atomic exchange (``renameat2(RENAME_EXCHANGE)``;
   where the kernel lacks it, two renames, so ``DIR`` is briefly absent but never mixed) after
   which the old folder is deleted.

A run that fails, is interrupted or killed leaves ``DIR`` as it was (absent, or the previous
complete result); its staging folder is hidden and named ``.partial``, and the next run on the
same ``DIR`` removes it -- except for a *resumable* command (``campaign``), which resumes from it.

An existing ``DIR`` is replaced whole only if it is empty or a result folder heavecomp moved into
place (it holds the marker :data:`MARKER`).  Any other folder (``--out .``, a folder of your files, a
result folder of an older heavecomp) is never deleted: the finished results are moved into it file by
file, each file whole (``os.replace``), and files already there that this run did not write stay.

An existing ``DIR`` whose parent takes no files (``--out .`` under a read-only folder) keeps its lock
and staging folder inside itself (``DIR/.heavecomp.lock``, ``DIR/.heavecomp.partial``) and gets the
results file by file.

Single files (``params -o FILE``) are written with :func:`write_text_atomic`: a temporary file in
the same folder, ``fsync``, then ``os.replace``.
"""

from __future__ import annotations

import errno
import logging
import os
import shutil
import tempfile
from pathlib import Path

from heavecomp.errors import InputError

log = logging.getLogger(__name__)

#: written into every result folder moved into place: such a folder is replaced whole by a re-run
MARKER = ".heavecomp-result"

#: files a resumable (campaign) run takes over from a previous complete folder
RESUME_FILES = ("manifest.json", "campaign.toml", "runs.csv")

#: errno values that mean "the disk is full" (one line, exit :data:`EXIT_NO_SPACE`)
NO_SPACE = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)

#: exit code of a run whose output could not be written (disk full, quota); bad input is 2
EXIT_NO_SPACE = 3


class OutputBusy(InputError):
    """Another live process writes the same output folder."""


def _inside(final: Path) -> bool:
    """Stage inside ``final``: an existing folder whose parent takes no files (``--out .`` in a
    read-only parent, ``--out /``); its results are then moved in file by file."""
    return final.is_dir() and (final.parent == final or not os.access(final.parent, os.W_OK))


def _side(final: Path, what: str) -> Path:
    if _inside(final):
        return final / f".heavecomp.{what}"
    return final.parent / f".{final.name}.{what}"


def lock_path(final) -> Path:
    """The lock file of the output folder ``final``: ``.NAME.lock`` beside it.

    Parameters
    ----------
    final : str or os.PathLike
        The output folder (made absolute; need not exist).

    Returns
    -------
    pathlib.Path
        ``.NAME.lock`` beside ``final``; inside it (``.heavecomp.lock``) when ``final`` is an existing folder
        whose parent takes no files.
    """
    return _side(Path(final).absolute(), "lock")


def staging_path(final) -> Path:
    """The staging folder of the output folder ``final``: ``.NAME.partial`` beside it.

    Parameters
    ----------
    final : str or os.PathLike
        The output folder (made absolute; need not exist).

    Returns
    -------
    pathlib.Path
        ``.NAME.partial`` beside ``final``; inside it (``.heavecomp.partial``) when ``final`` is an existing folder
        whose parent takes no files.
    """
    return _side(Path(final).absolute(), "partial")


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap the two existing paths ``a`` and ``b``; False where the OS cannot."""
    if not hasattr(os, "uname") or os.uname().sysname != "Linux":
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    AT_FDCWD, RENAME_EXCHANGE = -100, 2
    rc = fn(AT_FDCWD, os.fsencode(str(a)), AT_FDCWD, os.fsencode(str(b)), RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(a))


def _fsync(path: Path, *, strict: bool = True) -> None:
    """Flush ``path`` (a file or a folder's entries) to disk; ``strict=False`` ignores failures
    (a folder's fsync is not supported everywhere), ``strict=True`` raises them (a delayed
    ENOSPC or EIO of a file must fail the run, not the next reader)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        if strict:
            raise
        return
    try:
        os.fsync(fd)
    except OSError:
        if strict:
            raise
    finally:
        os.close(fd)


def is_result_folder(path) -> bool:
    """True if ``path`` is a result folder heavecomp moved into place (holds :data:`MARKER`).

    Parameters
    ----------
    path : str or os.PathLike
        The folder to test (need not exist).

    Returns
    -------
    bool
    """
    p = Path(path)
    return p.is_dir() and (p / MARKER).is_file()


class Staged:
    """Lock and staging folder of one output folder (see the module docstring).

    Use as a context manager: ``with Staged(out) as work: ...`` writes into ``work``; a normal exit
    moves it into place (:meth:`commit`), an exception leaves ``final`` untouched (:meth:`abort`).

    Parameters
    ----------
    final : str or os.PathLike
        The output folder as the user named it.
    flag : str
        The option that named it, for messages (``--out``).
    resumable : bool
        Keep a staging folder left by a killed run and resume from it; seed a new one from the
        :data:`RESUME_FILES` of an existing ``final`` (campaigns).
    """

    def __init__(self, final, flag: str = "--out", *, resumable: bool = False):
        self.shown = str(final)
        self.final = Path(final).absolute()
        self.flag = flag
        self.resumable = resumable
        self.lock = lock_path(self.final)
        self.work = staging_path(self.final)
        self._fd: int | None = None
        self._made: list[Path] = []
        self._seeded: dict[str, int] = {}  # files copied from a previous result -> size

    # -- lock ------------------------------------------------------------------------------------
    def _make_parent(self) -> None:
        missing = []
        q = self.final.parent
        while not q.exists():
            missing.append(q)
            q = q.parent
        for d in reversed(missing):
            d.mkdir()
            self._made.append(d)

    def acquire(self) -> None:
        """Take the lock (one line naming the flag and the owner's pid if another process holds it)."""
        import fcntl

        self._make_parent()
        while True:
            fd = os.open(self.lock, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno not in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                    raise
                try:
                    owner = self.lock.read_text().strip() or "?"
                except OSError:
                    owner = "?"
                self._remove_made()  # nothing of ours in them: the other process made its own
                raise OutputBusy(f"{self.flag} {self.shown}: another heavecomp process (pid {owner}) is writing "
                                 f"this folder; wait for it or choose another {self.flag}") from None
            try:  # the file we locked may have been removed by its previous owner meanwhile
                same = os.fstat(fd).st_ino == os.stat(self.lock).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        self._fd = fd

    def release(self) -> None:
        """Drop the lock and remove its file."""
        if self._fd is None:
            return
        try:
            self.lock.unlink()
        except FileNotFoundError:
            pass
        os.close(self._fd)  # closing drops the flock
        self._fd = None

    def _remove_made(self) -> None:
        for d in reversed(self._made):
            try:
                d.rmdir()
            except OSError:
                break
        self._made = []

    # -- staging ---------------------------------------------------------------------------------
    def check_final(self) -> None:
        """Refuse (before any work) an output path that is an existing file."""
        f = self.final
        if f.exists() and not f.is_dir():
            raise InputError(f"{self.flag} {self.shown}: is an existing file, not a folder")

    def open(self) -> Path:
        """Lock, check and prepare the staging folder; returns it."""
        self.acquire()
        try:
            self.check_final()
            old = _side(self.final, "old")
            if old.exists():
                shutil.rmtree(old, ignore_errors=True)
            if self.work.exists() and not (self.resumable and self.work.is_dir()):
                log.info("removing %s, left by an interrupted run", self.work)
                _remove(self.work)
            if not self.work.exists():
                self.work.mkdir()
                if self.resumable and self.final.is_dir():
                    for name in RESUME_FILES:
                        if (self.final / name).is_file():
                            shutil.copy2(self.final / name, self.work / name)
                            self._seeded[name] = (self.work / name).stat().st_size
        except BaseException:
            self.release()
            if not self.work.exists():
                self._remove_made()
            raise
        return self.work

    def commit(self) -> Path:
        """Move the staging folder into place (replacing an older result whole) and unlock.

        A staging folder with nothing in it is dropped: ``final`` stays as it was."""
        empty = False
        try:
            if not any(self.work.iterdir()):
                self.work.rmdir()
                empty = not self.final.exists()
                return self.final
            (self.work / MARKER).write_text("heavecomp result folder: a re-run with the same output folder "
                                            "replaces it whole\n")
            _fsync_tree(self.work)
            if not self.final.exists():
                os.rename(self.work, self.final)
            elif self.work.parent == self.final or (any(self.final.iterdir()) and not is_result_folder(self.final)):
                _merge(self.work, self.final)
            elif _exchange(self.work, self.final):
                _remove(self.work)  # now the old result
            else:
                old = _side(self.final, "old")
                os.rename(self.final, old)
                os.rename(self.work, self.final)
                _remove(old)
            _fsync(self.final.parent, strict=False)
            self._made = []
            return self.final
        finally:
            self.release()
            if empty:
                self._remove_made()

    def abort(self) -> None:
        """Leave ``final`` as it was; drop the staging folder (kept when resumable) and unlock."""
        try:
            if self.work.exists() and (not self.resumable or self._nothing_new()):
                _remove(self.work)
        finally:
            self.release()
            if not self.final.exists() and not self.work.exists():
                self._remove_made()

    def _nothing_new(self) -> bool:
        """The staging folder holds nothing but unchanged copies of the previous result's files."""
        try:
            return all(self._seeded.get(p.name) == p.stat().st_size for p in self.work.iterdir())
        except OSError:
            return False

    def __enter__(self) -> Path:
        return self.open()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.abort()


def _merge(work: Path, final: Path) -> None:
    """Move the finished files of ``work`` into the existing folder ``final`` one by one (each whole)."""
    for p in sorted(work.iterdir()):
        if p.name == MARKER:
            continue  # not a folder heavecomp may replace whole: it holds other files
        target = final / p.name
        if p.is_dir() and target.is_dir():
            _remove(target)
        os.replace(p, target)
    _remove(work)


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        try:
            path.unlink()
        except FileNotFoundError:
            pass


def _fsync_tree(folder: Path) -> None:
    """Flush the staged files to disk before they become visible under the final name."""
    for p in folder.rglob("*"):
        if p.is_file():
            _fsync(p)
    _fsync(folder, strict=False)


def need_space(folder, nbytes: float, flag: str = "--out", shown=None) -> None:
    """Refuse before any work when the file system of ``folder`` has less than ``nbytes`` free.

    ``nbytes`` is a low estimate of what the run will write (a check, not a reservation: a disk
    that fills during the run still ends in one line, :data:`EXIT_NO_SPACE`).

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder; its nearest existing ancestor gives the file system.
    nbytes : float [bytes]
        What the run will write at least.
    flag : str
        The option that named ``folder``, first word of the message.
    shown : str or None
        ``folder`` as the user spelled it, for the message (None: ``folder``).

    Raises
    ------
    heavecomp.errors.InputError
        Less than ``nbytes`` free.
    """
    q = Path(folder).absolute()
    while not q.exists():
        q = q.parent
    free = shutil.disk_usage(q).free
    if free < nbytes:
        raise InputError(f"{flag} {shown if shown is not None else folder}: about {_size(nbytes)} to write, "
                         f"only {_size(free)} free on its file system")


def _size(n: float) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{int(n)} bytes"


def write_text_atomic(path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` whole or not at all (temporary file beside it, fsync, rename).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (its folder must exist); an existing file keeps its mode.
    text : str
        The whole content.
    encoding : str
        Text encoding.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.parent if str(path.parent) else ".")
    try:
        try:  # mkstemp makes 0600: take the mode a plain open() would give (or the old file's)
            mode = path.stat().st_mode & 0o7777
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        with os.fdopen(fd, "w", encoding=encoding) as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def no_space_message(exc: OSError, where: str) -> str:
    """One line for a disk that filled during the run.

    Parameters
    ----------
    exc : OSError
        The error of the full disk (its ``errno`` gives the text).
    where : str
        What was being written, as the user named it (``--out DIR``).

    Returns
    -------
    str
    """
    return (f"{where}: {os.strerror(exc.errno)} while writing the results; nothing was written "
            "(the previous result, if any, is unchanged)")
