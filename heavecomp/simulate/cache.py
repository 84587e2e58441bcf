"""Where numba keeps the compiled kernels: one folder per kernel, keyed to the files it is built from.

numba checks a cached function against *its own* file only, but the compiled steppers inline
physics from other files (``friction/laws.py``, ``plants/cmc.py``, the effects' methods, ...): after
an edit or an upgrade a stale cache would run old physics.  So each kernel is compiled into a folder
whose name is a hash of exactly the files it is built from (:func:`source_key`):

- the nominal stepper (:mod:`heavecomp.simulate._kernel`): :data:`layout.KERNEL_SOURCES`;
- the stepper of an effect composition: those plus the composition's generated source and the
  compiled hook methods of its effects (:func:`composition_key`);
- a driver that calls the stepper from compiled code (the campaign's parallel batch, the pneumatic
  stepper): its own files plus the kernel sources.

An edit anywhere else (a report, a command, the diagnosis' decisions) changes no key and
recompiles nothing; an edit of an effect's hook methods recompiles the compositions holding it only.

The folders live in :func:`base_dir`: ``heavecomp/_numba_cache`` beside the sources when that is
writable (an editable install or a clone: ``setup.py`` fills it at install, so the first run
compiles nothing; see ``benchmarks/coldstart``), else ``$XDG_CACHE_HOME/heavecomp`` (default
``~/.cache/heavecomp``).  ``HEAVECOMP_CACHE_DIR`` overrides the place; ``NUMBA_CACHE_DIR`` set by
the user wins over all of this (numba's own single folder, no keys).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
from pathlib import Path

from heavecomp.simulate.layout import KERNEL_SOURCES

#: the package folder (paths in the keys are relative to it)
ROOT = Path(__file__).resolve().parents[1]
#: folder name of the cache beside the sources
IN_PACKAGE = "_numba_cache"


def _writable(path: Path) -> bool:
    probe = path if path.exists() else path.parent
    return os.access(probe, os.W_OK | os.X_OK)


@functools.cache
def base_dir() -> Path:
    """The folder holding the keyed cache folders (see the module docstring)."""
    env = os.environ.get("HEAVECOMP_CACHE_DIR")
    if env:
        return Path(env)
    here = ROOT / IN_PACKAGE
    if _writable(here):
        return here
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "heavecomp"


def where() -> Path:
    """Where compiled kernels are kept now: ``NUMBA_CACHE_DIR`` when the user set it, else :func:`base_dir`."""
    return Path(os.environ.get("NUMBA_CACHE_DIR") or base_dir())


def _file_digest(rel: str) -> bytes:
    return hashlib.sha256((ROOT / rel).read_bytes()).digest()


def source_key(files=(), extra: str = "") -> str:
    """16-hex-digit key of :data:`KERNEL_SOURCES`, the package-relative ``files`` and ``extra`` text.

    The relative path of every file goes into the hash with its contents, so a renamed file
    changes the key too.

    Parameters
    ----------
    files : iterable of str
        Package-relative paths (``effects/flow_loss.py``) hashed with :data:`KERNEL_SOURCES`.
    extra : str
        Further text hashed after the files (a generated source, compiled method texts).
    """
    h = hashlib.sha256()
    for rel in sorted(set(KERNEL_SOURCES) | set(files)):
        h.update(rel.encode())
        h.update(_file_digest(rel))
    h.update(extra.encode())
    return h.hexdigest()[:16]


def module_file(module: str) -> str | None:
    """Package-relative file of a ``heavecomp`` module (``heavecomp.effects.flow_loss`` ->
    ``effects/flow_loss.py``), None for a module outside the package.

    Parameters
    ----------
    module : str
        Dotted module name (``func.__module__``).
    """
    parts = module.split(".")
    if parts[0] != "heavecomp" or len(parts) < 2:
        return None
    rel = "/".join(parts[1:])
    return f"{rel}/__init__.py" if (ROOT / rel).is_dir() else f"{rel}.py"


def function_text(func) -> str:
    """The source of ``func`` with what it reads from its module: the value of each constant, the
    source of each function it calls (modules by name).  What numba compiles of it, in short.

    Parameters
    ----------
    func : callable
        A Python function or a numba dispatcher's ``py_func``.
    """
    import inspect
    import types

    parts = [inspect.getsource(func)]
    g = func.__globals__
    for name in func.__code__.co_names:
        if name not in g:
            continue
        v = g[name]
        if isinstance(v, types.ModuleType):
            parts.append(f"{name} = module {v.__name__}")
        elif callable(v):
            try:
                parts.append(inspect.getsource(getattr(v, "py_func", v)))
            except (OSError, TypeError):
                parts.append(f"{name} = {v!r}")
        else:
            parts.append(f"{name} = {v!r}")
    return "\n".join(parts)


def composition_key(comp) -> str:
    """Key of the stepper of an effect composition (:class:`heavecomp.effects.compose.Composition`):
    the kernel sources, the composition's generated source and the compiled hook methods of its
    effects (:func:`function_text`).  An edit of an effect's other parts (its diagnosis metadata,
    its docs, its casadi-only code) recompiles nothing.

    Parameters
    ----------
    comp : Composition
        The effect composition (:func:`heavecomp.effects.compose.composition`).
    """
    extra = [comp.source]
    for c in comp.classes:
        for m in c.methods():
            extra.append(f"{c.__module__}.{c.__qualname__}.{m}")
            extra.append(function_text(getattr(c, m)))
    return source_key((), "\n".join(extra))


def cache_dir(key: str) -> Path:
    """The numba cache folder of ``key``.

    Parameters
    ----------
    key : str
        A key of :func:`source_key` or :func:`composition_key`.
    """
    return base_dir() / f"numba-{key}"


def source_file(key: str, name: str, text: str) -> Path | None:
    """``text`` written to the file ``name`` in :func:`cache_dir` ``(key)`` (unless it already holds exactly
    that): generated source that numba can then cache like any module's, since its cache needs a file
    whose time stamp stays put.  Written to a temporary name and renamed, so processes compiling at once
    (the install's, pytest's workers) never read half a file.  None when no cache folder is writable.

    Parameters
    ----------
    key : str
        A key of :func:`source_key` or :func:`composition_key` (the text is part of what it hashes).
    name : str
        File name (``hooks_<hash>.py``).
    text : str
        The source.
    """
    path = cache_dir(key) / name
    try:
        if path.exists() and path.read_text() == text:
            return path
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{name}.{os.getpid()}.tmp")
        tmp.write_text(text)
        os.replace(tmp, path)
    except OSError:
        return None
    return path


@contextlib.contextmanager
def keyed(key: str):
    """numba's cache folder is :func:`cache_dir` ``(key)`` for the functions decorated inside.

    numba fixes a function's cache folder when it is decorated, so the folder of every
    ``njit(cache=True)`` inside this block is the keyed one.  Without a writable place (or with
    ``NUMBA_CACHE_DIR`` set by the user) numba's own choice stands.

    Parameters
    ----------
    key : str
        A key of :func:`source_key` or :func:`composition_key`.
    """
    from numba.core import config

    if os.environ.get("NUMBA_CACHE_DIR"):
        yield
        return
    d = cache_dir(key)
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError:  # read-only everywhere: numba's default (__pycache__ beside the sources)
        yield
        return
    old = config.CACHE_DIR
    config.CACHE_DIR = str(d)
    try:
        yield
    finally:
        config.CACHE_DIR = old


@contextlib.contextmanager
def one_compiler(name: str):
    """Hold the cache's lock ``name`` (an exclusive ``flock`` on ``<where()>/<name>.lock``) for a compile: a
    second process that needs the same kernel at the same moment (pytest's workers, a fleet's or a
    campaign's processes) waits, then loads what the first one wrote, instead of compiling it again.

    Where no lock can be taken (no ``fcntl``, a read-only cache) it does nothing: each process compiles
    on its own, as numba would.

    Parameters
    ----------
    name : str
        A file name for the one compiled thing (the stepper's: ``stepper-<its composition's key>``).
    """
    try:
        import fcntl
    except ImportError:  # Windows: no flock
        yield
        return
    try:
        d = where()
        d.mkdir(parents=True, exist_ok=True)
        fd = os.open(d / f"{name}.lock", os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing the descriptor releases the lock


def jit(files=(), **options):
    """``numba.njit(cache=True, **options)`` cached under :func:`source_key` ``(files)``: for a
    compiled driver that calls the stepper (``files``: its own module, package-relative).

    Parameters
    ----------
    files : iterable of str
        Package-relative paths of the driver's own sources (hashed with the kernel sources).
    **options : dict
        Further ``numba.njit`` options (``parallel=True``, ...).
    """
    import numba as nb

    def decorate(func):
        with keyed(source_key(files)):
            return nb.njit(cache=True, **options)(func)

    return decorate
